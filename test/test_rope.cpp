// The rope body type (spring-string-tutorial.txt) against independent truth: its layout, the elastic
// discrete catenary it settles on (test/catenary.h), the tutorial's string with its anchored middle
// node, and every bad value of its scene keys.
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "catenary.h"
#include "soft_body_sim/core/bodies/rope.h"
#include "soft_body_sim/core/elements/forces.h"
#include "soft_body_sim/scene/scene_loader.h"
#include "test_util.h"
#include "scene_error.h"

namespace soft_body_sim::test
{
namespace
{
std::string scenePath(const std::string& name) { return std::string(SOURCE_DIR) + "/config/scenes/" + name; }

// --- the builder --------------------------------------------------------------------------------

TEST(RopeBuilder, EqualMassNodesOnTheSegmentAndSpringsAtRest)
{
  RopeDef rope;
  rope.nodes = 5;
  rope.from = Vec3(1, 2, 3);
  rope.to = Vec3(3, 2, 3);
  rope.mass = 0.5;
  rope.stiffness = 100.0;
  rope.damping = 0.2;
  const BodyDef body = buildRope("r", rope);
  ASSERT_EQ(body.nodes.size(), 5u);
  for (int i = 0; i < 5; ++i)
  {
    EXPECT_TRUE(expectNear(body.nodes[i].position, Vec3(1 + 0.5 * i, 2, 3), 1e-15)) << "node " << i;
    EXPECT_EQ(body.nodes[i].mass, 0.1);
    EXPECT_FALSE(body.nodes[i].pinned);
  }
  SceneDef scene = oneBodyScene(IntegratorType::SemiImplicitEuler, 1e-3);
  scene.bodies[0] = body;
  const World world = buildWorld(scene);
  ASSERT_EQ(world.model().springs.size(), 4u);
  for (int i = 0; i < 4; ++i)
  {
    const Spring& s = world.model().springs[i];
    EXPECT_EQ(s.a, i);
    EXPECT_EQ(s.b, i + 1);
    EXPECT_NEAR(s.rest_length, 0.5, 1e-15);
    EXPECT_EQ(s.stiffness, 100.0);
    EXPECT_EQ(s.damping, 0.2);
  }
}

TEST(RopeBuilder, BendingSpringsToSecondNeighboursOnlyWhenAsked)
{
  RopeDef rope;
  rope.nodes = 6;
  EXPECT_EQ(buildRope("r", rope).springs.size(), 5u);
  rope.bending = 30.0;
  rope.bending_damping = 0.1;
  const BodyDef body = buildRope("r", rope);
  ASSERT_EQ(body.springs.size(), 5u + 4u);
  for (int i = 0; i < 4; ++i)
  {
    const SpringDef& s = body.springs[5 + i];
    EXPECT_EQ(s.a, i);
    EXPECT_EQ(s.b, i + 2);
    EXPECT_EQ(s.stiffness, 30.0);
    EXPECT_EQ(s.damping, 0.1);
  }
}

TEST(RopeBuilder, PinnedIndicesCountFromTheEndAndAreChecked)
{
  RopeDef rope;
  rope.nodes = 4;
  rope.pinned = { 0, -1 };
  const BodyDef body = buildRope("r", rope);
  EXPECT_TRUE(body.nodes[0].pinned);
  EXPECT_FALSE(body.nodes[1].pinned);
  EXPECT_FALSE(body.nodes[2].pinned);
  EXPECT_TRUE(body.nodes[3].pinned);
  rope.pinned = { 4 };
  EXPECT_THROW(buildRope("r", rope), std::out_of_range);
  rope.pinned = { -5 };
  EXPECT_THROW(buildRope("r", rope), std::out_of_range);
  rope.pinned = {};
  rope.nodes = 1;
  EXPECT_THROW(buildRope("r", rope), std::invalid_argument);
  rope.nodes = 4;
  rope.to = rope.from;
  EXPECT_THROW(buildRope("r", rope), std::invalid_argument);
}

// --- statics: the elastic discrete catenary ------------------------------------------------------

// A rope pinned at both ends starts straight and taut, every spring at rest, and sags by stretching.
// Its rest shape is the elastic discrete catenary of its nodes (equal masses M / N) with span = its rest
// length. The damped dynamics must stop exactly there: a force-based scheme's rest state is f(x) = 0,
// so only the settling residual remains, bounded by the stop speed times the slowest decay time
// (1e-11 m/s x ~1 s), hence 1e-9 m.
TEST(Rope, BuiltRopeSettlesOnTheElasticDiscreteCatenary)
{
  RopeDef rope;
  rope.nodes = 15;
  rope.from = Vec3::Zero();
  rope.to = Vec3(0.7, 0, 0);
  rope.mass = 0.15;
  rope.stiffness = 150.0;
  rope.damping = 0.02;
  rope.pinned = { 0, -1 };
  SceneDef scene = oneBodyScene(IntegratorType::ImplicitEuler, 0.01);
  scene.physics.gravity = Vec3(0, 0, -kGravity);
  scene.physics.drag = 1.0;
  scene.physics.step.iterations = 2;
  scene.bodies[0] = buildRope("rope", rope);
  World world = buildWorld(scene);
  const Eigen::Matrix3Xd start = world.state().position;
  ASSERT_TRUE(settle(world, 1e-11, 100000));

  const double rest = 0.7 / 14;
  const Eigen::Matrix3Xd truth = discreteCatenary(15, 0.15 / 15, 150.0, rest, 0.7);
  EXPECT_TRUE(expectNear(world.state().position, truth, 1e-9));
  // The sag of the middle node, as one figure: some 9 cm for this stretchy rope.
  EXPECT_NEAR(world.state().position(2, 7), truth(2, 7), 1e-9);
  EXPECT_LT(truth(2, 7), -0.05);
  EXPECT_EQ(world.state().position.col(0), start.col(0));
  EXPECT_EQ(world.state().position.col(14), start.col(14));
}

TEST(RopeScene, SettlesOnTheElasticDiscreteCatenaryWithItsEndsExactlyInPlace)
{
  World world = buildWorld(loadSceneFile(scenePath("rope.yaml")));
  ASSERT_EQ(world.model().nodeCount(), 21);
  ASSERT_TRUE(world.findAnchor("rope", "left"));
  ASSERT_TRUE(world.findAnchor("rope", "right"));
  const Eigen::Matrix3Xd start = world.state().position;
  // semi_implicit_euler at dt = 2 ms; the swing decays at about drag / 2 = 0.25 1/s, so the stop speed
  // 1e-11 m/s leaves at most ~4e-11 m to go: 1e-9 m.
  ASSERT_TRUE(settle(world, 1e-11, 200000));
  EXPECT_EQ(world.state().position.col(0), start.col(0));
  EXPECT_EQ(world.state().position.col(20), start.col(20));

  // The scene's rope: 1 m from (-0.5, 0, 1.5) to (0.5, 0, 1.5), 0.2 kg on 21 nodes, k = 200 N/m.
  Eigen::Matrix3Xd truth = discreteCatenary(21, 0.2 / 21, 200.0, 0.05, 1.0);
  truth.colwise() += start.col(0);
  EXPECT_TRUE(expectNear(world.state().position, truth, 1e-9));
  const double sag = start(2, 10) - world.state().position(2, 10);
  EXPECT_NEAR(sag, start(2, 10) - truth(2, 10), 1e-9);
  EXPECT_GT(sag, 0.15);  // the scene's comment promises about 0.2 m
  EXPECT_LT(sag, 0.25);
}

// --- the tutorial's string -----------------------------------------------------------------------

TEST(StringScene, IsTheTutorialsString)
{
  const SceneDef scene = loadSceneFile(scenePath("string.yaml"));
  const World world = buildWorld(scene);
  const Model& model = world.model();
  ASSERT_EQ(model.nodeCount(), 80);
  for (int i = 0; i < 80; ++i)
    EXPECT_NEAR(model.mass[i], 0.05, 1e-15);
  ASSERT_EQ(model.springs.size(), 79u);  // no bending springs: the tutorial has none
  for (const Spring& s : model.springs)
  {
    EXPECT_EQ(s.stiffness, 8000.0);
    EXPECT_NEAR(s.rest_length, 0.05, 1e-12);
  }
  const std::optional<int> anchor = world.findAnchor("string", "middle");
  ASSERT_TRUE(anchor);
  EXPECT_EQ(model.anchors[*anchor].node, 39);  // (80 - 1) / 2
  for (int i = 0; i < 80; ++i)
    EXPECT_EQ(model.isFree(i), i != 39) << "node " << i;
  EXPECT_NEAR(world.state().position(0, 39), 0.0, 1e-12);  // where the tutorial put its anchor
  EXPECT_TRUE(expectNear(model.gravity, Vec3(0, 0, -9.81), 0.0));
}

TEST(StringScene, TheAnchoredMiddleStaysExactlyWhileBothHalvesFallAndSwingBelowIt)
{
  World world = buildWorld(loadSceneFile(scenePath("string.yaml")));
  const Vec3 anchor = world.state().position.col(39);
  const double energy = world.energy();
  const double dt = world.settings().dt;
  bool left_tip_passed_under = false, right_tip_passed_under = false;
  double left_side = world.state().position(0, 0) - anchor.x();    // < 0
  double right_side = world.state().position(0, 79) - anchor.x();  // > 0
  for (long n = 1; n <= std::lround(3.0 / dt); ++n)
  {
    world.step();
    const NodeArray& x = world.state().position;
    ASSERT_EQ(Vec3(x.col(39)), anchor) << "step " << n;
    ASSERT_TRUE(x.allFinite()) << "step " << n;
    // Released level with the anchor, nothing rises above it during the first fall and swing through.
    if (n * dt <= 1.0)
    {
      for (int i = 0; i < 80; ++i)
      {
        if (i != 39)
        {
          ASSERT_LT(x(2, i), anchor.z()) << "node " << i << " at t = " << n * dt;
        }
      }
    }
    // Each tip swings through under the anchor: its side of the anchor changes while below it.
    const double left = x(0, 0) - anchor.x(), right = x(0, 79) - anchor.x();
    left_tip_passed_under |= left * left_side < 0.0 && x(2, 0) < anchor.z();
    right_tip_passed_under |= right * right_side < 0.0 && x(2, 79) < anchor.z();
    left_side = left;
    right_side = right;
    // A passive system (springs, dashpots, drag) never gains energy; symplectic Euler's energy error
    // stays bounded by O(h) of the motion's energy, far below 1e-3 of M g times the string's length.
    ASSERT_LE(world.energy(), energy + 1e-3 * 4.0 * 9.81 * 3.95) << "t = " << n * dt;
  }
  EXPECT_TRUE(left_tip_passed_under);
  EXPECT_TRUE(right_tip_passed_under);
}

// --- scene keys ------------------------------------------------------------------------------------

/// The rope of a scene, from a body mapping's keys.
SceneDef ropeScene(const std::string& keys)
{
  return parseBodyKeys("rope", "r", keys);
}

TEST(RopeKeys, EveryKeyIsRead)
{
  const SceneDef scene = ropeScene(R"(    nodes: 4
    from: [0, 0, 1]
    to: [0.3, 0, 1]
    mass: 0.4
    stiffness: 50
    damping: 0.5
    bending: 7
    bending_damping: 0.25
    pinned: [1, -1]
)");
  const BodyDef& body = scene.bodies[0];
  EXPECT_EQ(body.type, "rope");
  EXPECT_EQ(body.name, "r");
  ASSERT_EQ(body.nodes.size(), 4u);
  EXPECT_TRUE(expectNear(body.nodes[3].position, Vec3(0.3, 0, 1), 1e-15));
  EXPECT_EQ(body.nodes[0].mass, 0.1);
  EXPECT_FALSE(body.nodes[0].pinned);
  EXPECT_TRUE(body.nodes[1].pinned);
  EXPECT_TRUE(body.nodes[3].pinned);
  ASSERT_EQ(body.springs.size(), 3u + 2u);
  EXPECT_EQ(body.springs[0].stiffness, 50.0);
  EXPECT_EQ(body.springs[0].damping, 0.5);
  EXPECT_EQ(body.springs[3].stiffness, 7.0);
  EXPECT_EQ(body.springs[3].damping, 0.25);
}

TEST(RopeKeys, OptionalKeysDefaultToNoDampingNoBendingNothingPinned)
{
  const SceneDef scene = ropeScene("    nodes: 3\n    from: [0, 0, 0]\n    to: [1, 0, 0]\n    mass: 1\n    stiffness: 5\n");
  const BodyDef& body = scene.bodies[0];
  ASSERT_EQ(body.springs.size(), 2u);
  EXPECT_EQ(body.springs[0].damping, 0.0);
  for (const NodeDef& node : body.nodes)
    EXPECT_FALSE(node.pinned);
}

class RopeKeysReject : public ::testing::TestWithParam<BadKeys>
{
};

TEST_P(RopeKeysReject, WithOneLineNamingFileLineKeyAndReason)
{
  const auto& bad = GetParam();
  expectSceneError([&] { ropeScene(bad.keys); }, bad.keys, bad.location, bad.reason_words);
}

// Valid keys, line by line from line 4: nodes, from, to, mass, stiffness.
#define ROPE_FROM_LINE_5 "    from: [0, 0, 0]\n    to: [1, 0, 0]\n    mass: 1\n    stiffness: 5\n"

const BadKeys kBadRopes[] = {
  { "NodesMissing", "    from: [0, 0, 0]\n    to: [1, 0, 0]\n    mass: 1\n    stiffness: 5\n",
    "rope.yaml:2: bodies[0].nodes", { "missing required key" } },
  { "NodesIsAWord", "    nodes: many\n" ROPE_FROM_LINE_5, "rope.yaml:4: bodies[0].nodes", { "expected an integer", "'many'" } },
  { "NodesIsNotAnInteger", "    nodes: 2.5\n" ROPE_FROM_LINE_5, "rope.yaml:4: bodies[0].nodes", { "must be an integer" } },
  { "OneNode", "    nodes: 1\n" ROPE_FROM_LINE_5, "rope.yaml:4: bodies[0].nodes", { "[2, 1000000]", "got 1" } },
  { "TooManyNodes", "    nodes: 2000000\n" ROPE_FROM_LINE_5, "rope.yaml:4: bodies[0].nodes", { "[2, 1000000]" } },
  { "FromIsAScalar", "    nodes: 3\n    from: 0\n    to: [1, 0, 0]\n    mass: 1\n    stiffness: 5\n",
    "rope.yaml:5: bodies[0].from", { "expected a list of 3 numbers" } },
  { "ToHasTwoNumbers", "    nodes: 3\n    from: [0, 0, 0]\n    to: [1, 0]\n    mass: 1\n    stiffness: 5\n",
    "rope.yaml:6: bodies[0].to", { "expected a list of 3 numbers", "2 item(s)" } },
  { "ToEqualsFrom", "    nodes: 3\n    from: [1, 2, 3]\n    to: [1, 2, 3]\n    mass: 1\n    stiffness: 5\n",
    "rope.yaml:6: bodies[0].to", { "must differ from 'from'" } },
  { "NegativeMass", "    nodes: 3\n    from: [0, 0, 0]\n    to: [1, 0, 0]\n    mass: -1\n    stiffness: 5\n",
    "rope.yaml:7: bodies[0].mass", { "must be > 0", "-1" } },
  { "ZeroStiffness", "    nodes: 3\n    from: [0, 0, 0]\n    to: [1, 0, 0]\n    mass: 1\n    stiffness: 0\n",
    "rope.yaml:8: bodies[0].stiffness", { "must be > 0" } },
  { "NegativeDamping", "    nodes: 3\n" ROPE_FROM_LINE_5 "    damping: -0.1\n", "rope.yaml:9: bodies[0].damping",
    { "must be >= 0" } },
  { "BendingIsQuoted", "    nodes: 3\n" ROPE_FROM_LINE_5 "    bending: \"5\"\n", "rope.yaml:9: bodies[0].bending",
    { "expected a number", "quoted string" } },
  { "BendingDampingWithoutBending", "    nodes: 3\n" ROPE_FROM_LINE_5 "    bending_damping: 0.1\n",
    "rope.yaml:9: bodies[0].bending_damping", { "no effect without bending > 0" } },
  { "PinnedIsAScalar", "    nodes: 3\n" ROPE_FROM_LINE_5 "    pinned: 0\n", "rope.yaml:9: bodies[0].pinned",
    { "expected a list" } },
  { "PinnedIndexTooLarge", "    nodes: 3\n" ROPE_FROM_LINE_5 "    pinned: [0, 3]\n",
    "rope.yaml:9: bodies[0].pinned[1]", { "node index 3 out of range", "3 nodes (-3..2)" } },
  { "PinnedIndexTooNegative", "    nodes: 3\n" ROPE_FROM_LINE_5 "    pinned: [-4]\n",
    "rope.yaml:9: bodies[0].pinned[0]", { "node index -4 out of range" } },
  { "PinnedCornerNameOnARope", "    nodes: 3\n" ROPE_FROM_LINE_5 "    pinned: [top_left]\n",
    "rope.yaml:9: bodies[0].pinned[0]", { "expected an integer", "'top_left'" } },
  { "UnknownKey", "    nodes: 3\n" ROPE_FROM_LINE_5 "    length: 2\n", "rope.yaml:9: bodies[0].length",
    { "unknown key 'length'", "nodes, from, to, path, mass, stiffness, damping, bending, bending_damping, pinned" } },
  { "AnchorOutOfRange", "    nodes: 3\n" ROPE_FROM_LINE_5 "    anchors: [{name: end, node: 3}]\n",
    "rope.yaml:9: bodies[0].anchors[0].node", { "node index 3 out of range" } },
};
#undef ROPE_FROM_LINE_5

INSTANTIATE_TEST_SUITE_P(BadRopes, RopeKeysReject, ::testing::ValuesIn(kBadRopes),
                         [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace soft_body_sim::test
