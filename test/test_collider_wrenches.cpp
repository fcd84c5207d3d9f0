// The wrench the bodies exert on each named collider (World::colliderWrenches) against statics: a body at
// rest on its colliders presses on them with its weight m g, through its centre of mass.
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "soft_body_sim/core/bodies/cloth.h"
#include "soft_body_sim/core/bodies/rope.h"
#include "soft_body_sim/core/bodies/volume.h"
#include "test_util.h"

namespace soft_body_sim::test
{
namespace
{
constexpr double kGravity = 9.81;  ///< [m/s^2], along -z
constexpr double kPi = 3.14159265358979323846;

/// The wrench of collider `name`; fails the test if there is none.
Wrench wrenchOf(const World& world, const std::string& name)
{
  for (const ColliderWrench& c : world.colliderWrenches())
    if (c.name == name)
      return c.wrench;
  ADD_FAILURE() << "no wrench for collider '" << name << "'";
  return {};
}

/// The total mass [kg] of the world's free nodes and their centre of mass [m].
std::pair<double, Vec3> massAndCentre(const World& world)
{
  double mass = 0.0;
  Vec3 moment = Vec3::Zero();
  for (int i = 0; i < world.model().nodeCount(); ++i)
  {
    mass += world.model().mass[i];
    moment += world.model().mass[i] * world.state().position.col(i);
  }
  return { mass, moment / mass };
}

/// Steps `seconds` [s] (the landing), then until every node is slower than 0.1 mm/s; false if that takes
/// over 2 s more.
bool comeToRest(World& world, double seconds)
{
  while (world.time() < seconds)
    world.step();
  return settle(world, 1e-4, static_cast<long>(2.0 / world.settings().dt));
}

/// A body at rest whose weight only `collider` carries (at `origin`): the collider feels F = (0, 0, -m g)
/// and, about its origin, r x F for the centre of mass at r from it. 2 %: what is left of the settling
/// (the body still moves by less than 0.1 mm/s) in one step's impulses.
void expectCarriesTheWeight(const World& world, const std::string& collider, const Vec3& origin)
{
  const auto [mass, centre] = massAndCentre(world);
  const Vec3 weight(0.0, 0.0, -mass * kGravity);
  const Wrench wrench = wrenchOf(world, collider);
  EXPECT_TRUE(expectNear(wrench.force, weight, 0.02 * weight.norm()));
  const Vec3 arm = centre - origin;
  EXPECT_TRUE(expectNear(wrench.torque, arm.cross(weight), 0.02 * arm.norm() * weight.norm()));
}

/// The soft_box scene's 8 cm foam cube (E = 50 kPa, 200 kg/m^3, 102 g) 1 mm above the soft_box table
/// (top at z = 0.4 m), off its centre by (0.1, -0.05) m.
SceneDef boxOnTable()
{
  SceneDef scene;
  scene.physics.integrator = IntegratorType::ImplicitEuler;
  scene.physics.step = StepSettings{ 0.004, 1, 1 };
  scene.physics.gravity = Vec3(0.0, 0.0, -kGravity);
  scene.physics.drag = 5.0;  // settles the landing in well under a second
  Box table;
  table.at.name = "table";
  table.size = Vec3(0.4, 0.4, 0.04);
  table.at.position = Vec3(0.0, 0.0, 0.38);
  table.at.friction = 0.5;
  scene.colliders.boxes.push_back(table);
  VolumeDef box = boxVolume(Vec3::Constant(0.08), 0.016, Vec3(0.1, -0.05, 0.441), 5.0e4, 0.3, 200.0);
  scene.bodies.push_back(buildVolume("box", box));
  return scene;
}

/// A rope of 42 g and 31 nodes, 5 mm thick, laid over the horizontal capsule `bar` (along y at z = 1 m),
/// its two halves hanging 0.4 m down either side.
RopeDef ropeOver(const Capsule& bar)
{
  RopeDef rope;
  rope.nodes = 31;
  const double r = bar.radius + 0.005;  // its axis on the capsule
  rope.path = { Vec3(-r, 0.0, 0.6), Vec3(-r, 0.0, 1.0), Vec3(-0.7 * r, 0.0, 1.0 + 0.7 * r), Vec3(0.0, 0.0, 1.0 + r),
                Vec3(0.7 * r, 0.0, 1.0 + 0.7 * r), Vec3(r, 0.0, 1.0), Vec3(r, 0.0, 0.6) };
  rope.mass = 0.042;
  rope.stiffness = 2000.0;
  rope.damping = 0.5;
  rope.radius = 0.005;
  return rope;
}

/// ropeOver a horizontal capsule "bar" of radius 3 cm and length 0.3 m along y at height 1 m (friction
/// 0.5), damped to come to rest: 1/240 s in 4 sub-steps of 4 iterations, drag 5.
SceneDef ropeOverBar(IntegratorType integrator)
{
  SceneDef scene;
  scene.physics.integrator = integrator;
  scene.physics.step = StepSettings{ 1.0 / 240.0, 4, 4 };
  scene.physics.gravity = Vec3(0.0, 0.0, -kGravity);
  scene.physics.drag = 5.0;
  Capsule bar;
  bar.at.name = "bar";
  bar.radius = 0.03;
  bar.length = 0.3;
  bar.at.position = Vec3(0.0, 0.0, 1.0);
  bar.at.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * kPi, Vec3::UnitX()));  // along y
  bar.at.friction = 0.5;
  scene.colliders.capsules.push_back(bar);
  scene.bodies.push_back(buildRope("rope", ropeOver(bar)));
  return scene;
}
}  // namespace

TEST(ColliderWrenches, ASoftSolidRestingOffCentreOnATablePressesWithItsWeightThroughItsCentreOfMass)
{
  // implicit_euler: the solid's nodes are held on the table inside the Newton solve (collider_holds.h),
  // the contact stage after it takes the rest.
  World world = buildWorld(boxOnTable());
  ASSERT_TRUE(comeToRest(world, 0.5));
  world.step();
  expectCarriesTheWeight(world, "table", Vec3(0.0, 0.0, 0.38));
}

TEST(ColliderWrenches, ACloth_RestingOffCentreOnATableUnderXpbd_PressesWithItsWeightThroughItsCentreOfMass)
{
  // A volume runs under implicit_euler only: under xpbd a 0.3 m cloth of 11 x 11 nodes lies on the table
  // instead, off its centre, with the contact stage alone.
  SceneDef scene = boxOnTable();
  scene.physics.integrator = IntegratorType::Xpbd;
  scene.physics.step = StepSettings{ 1.0 / 120.0, 2, 4 };
  scene.bodies.clear();
  ClothDef cloth;
  cloth.nx = cloth.ny = 11;
  cloth.corners = GridCorners{ Vec3(-0.1, 0.05, 0.405), Vec3(0.15, 0.05, 0.405), Vec3(-0.1, -0.15, 0.405) };
  cloth.mass = 0.2;
  cloth.structural = { 2000.0, 0.5 };
  cloth.shear = { 500.0, 0.5 };
  scene.bodies.push_back(buildCloth("cloth", cloth));
  scene.bodies[0].contact_radius = 0.005;
  World world = buildWorld(scene);
  ASSERT_TRUE(comeToRest(world, 0.5));
  world.step();
  expectCarriesTheWeight(world, "table", Vec3(0.0, 0.0, 0.38));
}

TEST(ColliderWrenches, ARopeHangingOverACapsuleLoadsItWithTheRopesWeight)
{
  // A rope of 42 g laid over a horizontal capsule, its two halves hanging 0.4 m down either side, comes
  // to rest there, the capsule carrying all of it. Under xpbd the nodes on the capsule are held inside the
  // chains' solve (chain_contacts.h); under implicit_euler by the contact stage, nodes and segments.
  for (const IntegratorType integrator : { IntegratorType::Xpbd, IntegratorType::ImplicitEuler })
  {
    SCOPED_TRACE(integratorName(integrator));
    World world = buildWorld(ropeOverBar(integrator));
    ASSERT_TRUE(comeToRest(world, 0.5));
    world.step();
    const double weight = 0.042 * kGravity;
    EXPECT_TRUE(expectNear(wrenchOf(world, "bar").force, Vec3(0.0, 0.0, -weight), 0.02 * weight));
  }
}

TEST(ColliderWrenches, ARopeCarryingTwoLoadsOverACapsuleUnderXpbdLoadsItWithItsAndTheirWeight)
{
  // As above with 0.2 kg at both ends: xpbd solves the loaded rope as a chain, its nodes on the capsule held
  // inside that solve (chain_contacts.h), which then tells the capsule the contact forces it applied.
  SceneDef scene = ropeOverBar(IntegratorType::Xpbd);
  scene.bodies[0].nodes.front().mass = 0.2;
  scene.bodies[0].nodes.back().mass = 0.2;
  World world = buildWorld(scene);
  ASSERT_TRUE(comeToRest(world, 0.5));
  world.step();
  const double weight = massAndCentre(world).first * kGravity;
  EXPECT_TRUE(expectNear(wrenchOf(world, "bar").force, Vec3(0.0, 0.0, -weight), 0.02 * weight));
}

TEST(ColliderWrenches, AClothLyingOnANamedPlaneLoadsItWithItsWeight_AndAnUnnamedPlaneReportsNothing)
{
  SceneDef scene;
  scene.physics.integrator = IntegratorType::Xpbd;
  scene.physics.step = StepSettings{ 1.0 / 120.0, 2, 4 };
  scene.physics.gravity = Vec3(0.0, 0.0, -kGravity);
  scene.physics.drag = 5.0;
  Plane floor{ Vec3(0.0, 0.0, 0.1), Vec3::UnitZ(), 0.0, 0.5, "floor" };
  scene.colliders.planes = { floor, Plane{ Vec3(5.0, 0.0, 0.0), -Vec3::UnitX(), 0.0, 0.0, "" } };
  ClothDef cloth;
  cloth.nx = cloth.ny = 11;
  cloth.corners = GridCorners{ Vec3(0.0, 0.2, 0.11), Vec3(0.2, 0.2, 0.11), Vec3(0.0, 0.0, 0.11) };
  cloth.mass = 0.1;
  cloth.structural = { 2000.0, 0.5 };
  cloth.shear = { 500.0, 0.5 };
  scene.bodies.push_back(buildCloth("cloth", cloth));
  scene.bodies[0].contact_radius = 0.005;
  World world = buildWorld(scene);
  ASSERT_EQ(world.colliderWrenches().size(), 1u);
  ASSERT_TRUE(comeToRest(world, 0.5));
  world.step();
  expectCarriesTheWeight(world, "floor", floor.point);
}

}  // namespace soft_body_sim::test
