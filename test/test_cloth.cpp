// The cloth body type (tum-mass-spring-tutorial.txt: a grid of mass points joined by springs) against
// independent truth: its grid and springs, the stretch of a hanging curtain between two closed-form
// bounds, the example scene's pinned corners and its strain, and every bad value of its scene keys.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "soft_body_sim/core/bodies/cloth.h"
#include "soft_body_sim/scene/scene_loader.h"
#include "test_util.h"
#include "scene_error.h"

namespace soft_body_sim::test
{
namespace
{
constexpr double kGravity = 9.81;  ///< [m/s^2]

/// A measured figure for the test report (--gtest_output=xml), to 4 significant digits.
std::string figure(double value)
{
  std::ostringstream out;
  out.precision(4);
  out << value;
  return out.str();
}

// --- the builder ------------------------------------------------------------------------------------

TEST(ClothBuilder, GridOfEqualMassesBetweenTheNamedCorners)
{
  ClothDef cloth;
  cloth.nx = 4;
  cloth.ny = 3;
  cloth.corners = GridCorners{ Vec3(0, 0, 2), Vec3(0.6, 0, 2), Vec3(0, 0.4, 1.7) };
  cloth.mass = 1.2;
  const BodyDef body = buildCloth("c", cloth);
  ASSERT_EQ(body.nodes.size(), 12u);
  for (const NodeDef& node : body.nodes)
    EXPECT_NEAR(node.mass, 0.1, 1e-15);
  // Node (i, j) = j nx + i at top_left + i/(nx-1) (top_right - top_left) + j/(ny-1) (bottom_left - top_left).
  EXPECT_TRUE(expectNear(body.nodes[5].position, Vec3(0.2, 0.2, 1.85), 1e-15));
  // The named corners, and bottom_right = top_right + bottom_left - top_left.
  const Vec3 expected[4] = { Vec3(0, 0, 2), Vec3(0.6, 0, 2), Vec3(0, 0.4, 1.7), Vec3(0.6, 0.4, 1.7) };
  for (int k = 0; k < 4; ++k)
  {
    const std::optional<int> corner = gridCornerNode(gridCornerNames()[k], 4, 3);
    ASSERT_TRUE(corner) << gridCornerNames()[k];
    EXPECT_TRUE(expectNear(body.nodes[*corner].position, expected[k], 1e-15)) << gridCornerNames()[k];
  }
  EXPECT_EQ(*gridCornerNode("top_left", 4, 3), 0);
  EXPECT_EQ(*gridCornerNode("top_right", 4, 3), 3);
  EXPECT_EQ(*gridCornerNode("bottom_left", 4, 3), 8);
  EXPECT_EQ(*gridCornerNode("bottom_right", 4, 3), 11);
  EXPECT_FALSE(gridCornerNode("top", 4, 3));
}

TEST(ClothBuilder, StructuralShearAndOnlyRequestedBendingSprings)
{
  ClothDef cloth;
  cloth.nx = 5;
  cloth.ny = 4;
  cloth.corners = GridCorners{ Vec3(0, 0, 1), Vec3(0.4, 0, 1), Vec3(0, 0, 0.7) };  // 0.1 m squares
  cloth.structural = { 100.0, 0.1 };
  cloth.shear = { 20.0, 0.2 };
  SceneDef scene = oneBodyScene(IntegratorType::SemiImplicitEuler, 1e-3);
  scene.bodies[0] = buildCloth("c", cloth);
  const int structural = 2 * 5 * 4 - 5 - 4;  // (nx - 1) ny + nx (ny - 1)
  const int shear = 2 * 4 * 3;               // 2 (nx - 1)(ny - 1)
  {
    const World world = buildWorld(scene);
    ASSERT_EQ(world.model().springs.size(), static_cast<std::size_t>(structural + shear));
    for (const Spring& s : world.model().springs)
    {
      const double rest = s.stiffness == 100.0 ? 0.1 : 0.1 * std::sqrt(2.0);
      EXPECT_NEAR(s.rest_length, rest, 1e-15);
    }
    EXPECT_EQ(strains(world, 100.0).size(), static_cast<std::size_t>(structural));
  }
  cloth.bending = SpringParameters{ 5.0, 0.0 };
  scene.bodies[0] = buildCloth("c", cloth);
  const World world = buildWorld(scene);
  const int bending = (5 - 2) * 4 + 5 * (4 - 2);
  ASSERT_EQ(world.model().springs.size(), static_cast<std::size_t>(structural + shear + bending));
  for (const Spring& s : world.model().springs)
  {
    if (s.stiffness == 5.0)
    {
      EXPECT_NEAR(s.rest_length, 0.2, 1e-15);
    }
  }
}

TEST(ClothBuilder, RejectsBadDefinitions)
{
  ClothDef cloth;
  cloth.nx = 1;
  EXPECT_THROW(buildCloth("c", cloth), std::invalid_argument);
  cloth.nx = 3;
  cloth.corners.bottom_left = cloth.corners.top_left + 2.0 * (cloth.corners.top_right - cloth.corners.top_left);
  EXPECT_THROW(buildCloth("c", cloth), std::invalid_argument);  // collinear corners
  cloth.corners = GridCorners{};
  cloth.pinned = { 100 };
  EXPECT_THROW(buildCloth("c", cloth), std::out_of_range);
}

// --- statics: a curtain's stretch ----------------------------------------------------------------------

// A curtain: nx x ny nodes of mass m, squares of side L, the whole top row pinned. Across the row of
// vertical springs below the top row the cloth carries the weight of the (ny - 1) rows below it, per
// column (ny - 1) m g. Two closed forms bound the stretch of those springs:
//  - if the structural springs carried it alone, each column would be the vertical chain of
//    test_statics: strain eps_chain = (ny - 1) m g / (k L), the largest any structural spring can have
//    while the shear springs pull along (in tension);
//  - under a uniform vertical strain eps with no horizontal strain, a column's structural spring
//    carries k eps L and its two shear springs (length sqrt(2) L, strain eps / 2) add k_s eps L
//    vertically, so eps_uniform = (ny - 1) m g / ((k + k_s) L): the interior columns, far from the
//    free side edges, where the strain is uniform.
// The settled curtain must lie between them: interior columns within 3 % of eps_uniform (the small
// geometric nonlinearity and the sides' influence), the edge columns (one shear spring fewer) above
// it, every structural spring at most eps_chain.
TEST(Cloth, HangingCurtainStretchesBetweenTheUniformAndTheChainBounds)
{
  const int nx = 8, ny = 8;
  const double side = 0.1, node_mass = 0.01, k = 200.0, k_shear = 50.0;
  ClothDef cloth;
  cloth.nx = nx;
  cloth.ny = ny;
  cloth.corners = GridCorners{ Vec3(0, 0, 1), Vec3((nx - 1) * side, 0, 1), Vec3(0, 0, 1 - (ny - 1) * side) };
  cloth.mass = node_mass * nx * ny;
  cloth.structural = { k, 0.05 };
  cloth.shear = { k_shear, 0.02 };
  for (int i = 0; i < nx; ++i)
    cloth.pinned.push_back(i);
  SceneDef scene = oneBodyScene(IntegratorType::ImplicitEuler, 0.005);
  scene.physics.gravity = Vec3(0, 0, -kGravity);
  scene.physics.drag = 1.0;
  scene.physics.step.iterations = 2;
  scene.bodies[0] = buildCloth("curtain", cloth);
  World world = buildWorld(scene);
  const Eigen::Matrix3Xd start = world.state().position;
  long steps = 0;
  while (world.state().velocity.colwise().norm().maxCoeff() > 1e-10 || steps == 0)
  {
    world.step();
    ASSERT_LT(++steps, 100000);
  }
  EXPECT_EQ(world.state().position.leftCols(nx), start.leftCols(nx));  // the pinned top row, exactly

  const double load = (ny - 1) * node_mass * kGravity;  // [N] per column
  const double eps_chain = load / (k * side);
  const double eps_uniform = load / ((k + k_shear) * side);
  const NodeArray& x = world.state().position;
  for (int i = 0; i < nx; ++i)
  {
    const double top_strain = (x.col(i + nx) - x.col(i)).norm() / side - 1.0;
    if (i > 0 && i < nx - 1)
      EXPECT_NEAR(top_strain, eps_uniform, 0.03 * eps_uniform) << "column " << i;
    else
      EXPECT_GT(top_strain, eps_uniform) << "edge column " << i;
  }
  const double max_structural = maxOf(strains(world, k));
  EXPECT_LE(max_structural, eps_chain);
  EXPECT_GE(max_structural, eps_uniform);
  EXPECT_LE(maxOf(strains(world, k_shear)), eps_chain);
  RecordProperty("max_structural_strain", figure(max_structural));
}

// --- the example scene -----------------------------------------------------------------------------

// config/scenes/cloth.yaml: 15 x 15 nodes, 1 m, 0.3 kg, held at its two top corners, falls from
// horizontal and swings down. The corners must stay exactly where they are at every step. Settled, no
// spring may stretch more than if one structural spring carried the whole weight W: W / (k L), about
// 4.1 %; each corner holds W / 2 vertically plus the top edge's pull, shared by its springs.
TEST(ClothScene, CornersStayExactlyAndTheSettledStrainStaysBelowTheWeightOverOneSpring)
{
  World world = buildWorld(loadSceneFile(std::string(SOURCE_DIR) + "/config/scenes/cloth.yaml"));
  const int top_left = 0, top_right = 14;
  ASSERT_FALSE(world.model().isFree(top_left));
  ASSERT_FALSE(world.model().isFree(top_right));
  int pinned = 0;
  for (int i = 0; i < world.model().nodeCount(); ++i)
    pinned += world.model().isFree(i) ? 0 : 1;
  EXPECT_EQ(pinned, 2);
  const Vec3 left = world.state().position.col(top_left), right = world.state().position.col(top_right);
  const double duration = 30.0;  // drag 0.5 1/s: the swing has decayed by e^-7.5 by then
  for (long n = 1; n <= std::lround(duration / world.settings().dt); ++n)
  {
    world.step();
    ASSERT_EQ(Vec3(world.state().position.col(top_left)), left) << "step " << n;
    ASSERT_EQ(Vec3(world.state().position.col(top_right)), right) << "step " << n;
  }
  EXPECT_LT(world.state().velocity.colwise().norm().maxCoeff(), 0.01);
  // It hangs below its corners.
  EXPECT_LT(world.state().position.row(2).maxCoeff(), left.z() + 1e-12);
  EXPECT_LT(world.state().position(2, 224), left.z() - 0.8);

  const double weight = 0.3 * kGravity, k = 1000.0, side = 1.0 / 14;
  const double max_strain = maxOf(strains(world, k));
  EXPECT_LT(max_strain, weight / (k * side));
  EXPECT_GT(max_strain, 0.0);
  RecordProperty("max_strain", figure(max_strain));
}

// --- scene keys ---------------------------------------------------------------------------------------

SceneDef clothScene(const std::string& keys)
{
  return parseBodyKeys("cloth", "c", keys);
}

// Valid keys from line 4 on; the bad cases below replace or append lines.
const char* const kClothKeys = R"(    nx: 3
    ny: 4
    top_left: [0, 0, 1]
    top_right: [0.2, 0, 1]
    bottom_left: [0, 0, 0.7]
    mass: 0.12
    structural: {stiffness: 100, damping: 0.1}
    shear: {stiffness: 20}
)";

TEST(ClothKeys, EveryKeyIsReadAndCornersNameNodes)
{
  const SceneDef scene = clothScene(std::string(kClothKeys) +
                                    "    bending: {stiffness: 5, damping: 0.01}\n"
                                    "    pinned: [top_left, top_right, bottom_left, bottom_right, 4, -2]\n");
  const BodyDef& body = scene.bodies[0];
  EXPECT_EQ(body.type, "cloth");
  ASSERT_EQ(body.nodes.size(), 12u);
  EXPECT_NEAR(body.nodes[0].mass, 0.01, 1e-15);
  EXPECT_TRUE(expectNear(body.nodes[11].position, Vec3(0.2, 0, 0.7), 1e-15));
  for (int i = 0; i < 12; ++i)
  {
    const bool expected = i == 0 || i == 2 || i == 9 || i == 11 || i == 4 || i == 10;
    EXPECT_EQ(body.nodes[i].pinned, expected) << "node " << i;
  }
  const int structural = 2 * 3 * 4 - 3 - 4, shear = 2 * 2 * 3, bending = 1 * 4 + 3 * 2;
  ASSERT_EQ(body.springs.size(), static_cast<std::size_t>(structural + shear + bending));
  EXPECT_EQ(body.springs[0].stiffness, 100.0);
  EXPECT_EQ(body.springs[0].damping, 0.1);
  EXPECT_EQ(body.springs[structural].stiffness, 20.0);
  EXPECT_EQ(body.springs[structural].damping, 0.0);
  EXPECT_EQ(body.springs.back().stiffness, 5.0);
  EXPECT_EQ(body.springs.back().damping, 0.01);
}

TEST(ClothKeys, NoBendingKeyNoBendingSprings)
{
  const SceneDef scene = clothScene(kClothKeys);
  const BodyDef& body = scene.bodies[0];
  EXPECT_EQ(body.springs.size(), static_cast<std::size_t>(2 * 3 * 4 - 3 - 4 + 2 * 2 * 3));
  for (const NodeDef& node : body.nodes)
    EXPECT_FALSE(node.pinned);
}

class ClothKeysReject : public ::testing::TestWithParam<BadKeys>
{
};

TEST_P(ClothKeysReject, WithOneLineNamingFileLineKeyAndReason)
{
  const auto& bad = GetParam();
  expectSceneError([&] { clothScene(bad.keys); }, bad.keys, bad.location, bad.reason_words);
}

const BadKeys kBadCloths[] = {
  { "NxIsOne", replaceKeyLine(kClothKeys, 4, "    nx: 1"), "cloth.yaml:4: bodies[0].nx", { "[2, 1000000]", "got 1" } },
  { "NxIsAList", replaceKeyLine(kClothKeys, 4, "    nx: [3]"), "cloth.yaml:4: bodies[0].nx", { "expected an integer", "a list" } },
  { "NyIsNegative", replaceKeyLine(kClothKeys, 5, "    ny: -4"), "cloth.yaml:5: bodies[0].ny", { "[2, 1000000]", "-4" } },
  { "GridTooLarge", replaceKeyLine(kClothKeys, 4, "    nx: 1000000"), "cloth.yaml:5: bodies[0].ny", { "more than 1000000" } },
  { "NyMissing", replaceKeyLine(kClothKeys, 5, ""), "cloth.yaml:2: bodies[0].ny", { "missing required key" } },
  { "TopLeftIsAWord", replaceKeyLine(kClothKeys, 6, "    top_left: origin"), "cloth.yaml:6: bodies[0].top_left",
    { "expected a list of 3 numbers" } },
  { "CollinearCorners", replaceKeyLine(kClothKeys, 8, "    bottom_left: [0.4, 0, 1]"), "cloth.yaml:8: bodies[0].bottom_left",
    { "must span a parallelogram", "collinear" } },
  { "ZeroMass", replaceKeyLine(kClothKeys, 9, "    mass: 0"), "cloth.yaml:9: bodies[0].mass", { "must be > 0" } },
  { "StructuralIsANumber", replaceKeyLine(kClothKeys, 10, "    structural: 100"), "cloth.yaml:10: bodies[0].structural",
    { "expected a mapping", "'100'" } },
  { "StructuralWithoutStiffness", replaceKeyLine(kClothKeys, 10, "    structural: {damping: 0.1}"),
    "cloth.yaml:10: bodies[0].structural.stiffness", { "missing required key" } },
  { "NegativeStructuralStiffness", replaceKeyLine(kClothKeys, 10, "    structural: {stiffness: -100}"),
    "cloth.yaml:10: bodies[0].structural.stiffness", { "must be > 0", "-100" } },
  { "UnknownSpringKey", replaceKeyLine(kClothKeys, 11, "    shear: {stiffness: 20, k: 3}"), "cloth.yaml:11: bodies[0].shear.k",
    { "unknown key 'k'", "stiffness, damping" } },
  { "NegativeShearDamping", replaceKeyLine(kClothKeys, 11, "    shear: {stiffness: 20, damping: -1}"),
    "cloth.yaml:11: bodies[0].shear.damping", { "must be >= 0" } },
  { "ShearMissing", replaceKeyLine(kClothKeys, 11, ""), "cloth.yaml:2: bodies[0].shear", { "missing required key" } },
  { "BendingWithZeroStiffness", std::string(kClothKeys) + "    bending: {stiffness: 0}\n",
    "cloth.yaml:12: bodies[0].bending.stiffness", { "must be > 0" } },
  { "UnknownCornerName", std::string(kClothKeys) + "    pinned: [top_left, top_middle]\n",
    "cloth.yaml:12: bodies[0].pinned[1]",
    { "unknown corner 'top_middle'", "top_left, top_right, bottom_left, bottom_right" } },
  { "PinnedIndexOutOfRange", std::string(kClothKeys) + "    pinned: [12]\n", "cloth.yaml:12: bodies[0].pinned[0]",
    { "node index 12 out of range", "12 nodes (-12..11)" } },
  { "PinnedIndexNotAnInteger", std::string(kClothKeys) + "    pinned: [1.5]\n", "cloth.yaml:12: bodies[0].pinned[0]",
    { "must be an integer" } },
  { "PinnedItemIsAList", std::string(kClothKeys) + "    pinned: [[0, 1]]\n", "cloth.yaml:12: bodies[0].pinned[0]",
    { "expected a node index or a corner name", "a list" } },
  { "UnknownKey", std::string(kClothKeys) + "    size: [1, 1]\n", "cloth.yaml:12: bodies[0].size",
    { "unknown key 'size'", "nx, ny, top_left, top_right, bottom_left, mass, structural, shear, bending, pinned" } },
};

INSTANTIATE_TEST_SUITE_P(BadCloths, ClothKeysReject, ::testing::ValuesIn(kBadCloths),
                         [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace soft_body_sim::test
