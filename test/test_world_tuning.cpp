// Live tuning and grasping (the ROS node's dynamic_reconfigure, tf-following anchors and ~attach) against
// independent truth: constant-acceleration kinematics, a hanging spring's static stretch, a circle.
#include <cmath>

#include <gtest/gtest.h>

#include "soft_body_sim/core/bodies/rope.h"
#include "test_util.h"

namespace soft_body_sim::test
{
namespace
{
constexpr double kG = 9.81;  // [m/s^2]

/// One free node of 1 kg at the origin, falling under gravity g = (0, 0, -kG).
World fallingNode(IntegratorType integrator, double dt)
{
  SceneDef scene = oneBodyScene(integrator, dt);
  scene.physics.gravity = Vec3(0, 0, -kG);
  scene.bodies[0].nodes = { NodeDef{ Vec3::Zero(), 1.0, Vec3::Zero(), false } };
  return buildWorld(scene);
}

TEST(StepSettings, ANewDtContinuesTheTimeAndTheMotionWithoutAJump)
{
  // Under constant gravity semi-implicit Euler's velocity is exact, v = g t, whatever the step: the
  // velocity after 10 steps of 1 ms and 5 of 2 ms is g * 20 ms if neither time nor state jumped.
  World world = fallingNode(IntegratorType::SemiImplicitEuler, 1e-3);
  for (int n = 0; n < 10; ++n)
    world.step();
  const Vec3 x_before = world.state().position.col(0);
  world.setStepSettings(StepSettings{ 2e-3, 2, 3 });
  EXPECT_DOUBLE_EQ(world.time(), 0.010);
  EXPECT_EQ(Vec3(world.state().position.col(0)), x_before);
  for (int n = 0; n < 5; ++n)
    world.step();
  EXPECT_NEAR(world.time(), 0.020, 1e-15);
  EXPECT_EQ(world.stepCount(), 15);
  EXPECT_NEAR(world.state().velocity(2, 0), -kG * 0.020, 1e-12);
  EXPECT_EQ(world.settings().substeps, 2);
  EXPECT_EQ(world.settings().iterations, 3);
  // Bad values are refused and change nothing.
  EXPECT_THROW(world.setStepSettings(StepSettings{ 0.0, 1, 1 }), std::invalid_argument);
  EXPECT_THROW(world.setStepSettings(StepSettings{ 1e-3, 0, 1 }), std::invalid_argument);
  EXPECT_THROW(world.setStepSettings(StepSettings{ 1e-3, 1, 0 }), std::invalid_argument);
  EXPECT_DOUBLE_EQ(world.settings().dt, 2e-3);
}

TEST(Integrator, ASwitchedIntegratorStartsFromTheCurrentPositionAndVelocity)
{
  // Every scheme integrates a constant acceleration's velocity exactly, so after a tour through all
  // seven the velocity is still g t; the position is first order in h for the Euler schemes, so it
  // stays within g t h of -g t^2 / 2.
  const double dt = 1e-3;
  World world = fallingNode(IntegratorType::ExplicitEuler, dt);
  for (const std::string& name : integratorNames())
  {
    IntegratorType type;
    ASSERT_TRUE(integratorFromName(name, type));
    world.setIntegrator(type);
    EXPECT_EQ(world.integrator(), type);
    for (int n = 0; n < 20; ++n)
      world.step();
    const double t = world.time();
    EXPECT_NEAR(world.state().velocity(2, 0), -kG * t, 1e-9) << name;
    EXPECT_NEAR(world.state().position(2, 0), -0.5 * kG * t * t, kG * t * dt) << name;
  }
}

TEST(GravityAndDrag, NewValuesActFromTheNextStep)
{
  World world = fallingNode(IntegratorType::SemiImplicitEuler, 1e-3);
  for (int n = 0; n < 10; ++n)
    world.step();
  const Vec3 v = world.state().velocity.col(0);
  world.setGravity(Vec3::Zero());
  for (int n = 0; n < 10; ++n)
    world.step();
  EXPECT_EQ(Vec3(world.state().velocity.col(0)), v);  // no force: uniform motion
  // Drag alone: semi-implicit Euler multiplies v by (1 - h drag) per step.
  world.setDrag(2.0);
  world.step();
  EXPECT_TRUE(expectNear(Vec3(world.state().velocity.col(0)), Vec3(v * (1.0 - 1e-3 * 2.0)), 1e-15));
  EXPECT_THROW(world.setDrag(-1.0), std::invalid_argument);
  EXPECT_THROW(world.setGravity(Vec3(0, 0, NAN)), std::invalid_argument);
  EXPECT_EQ(world.model().drag, 2.0);
}

/// A 1 kg node hanging from a pinned node by a spring k = 100 N/m, critically damped (c = 2 sqrt(k m)).
World hangingSpring()
{
  SceneDef scene = oneBodyScene(IntegratorType::SemiImplicitEuler, 1e-3);
  scene.physics.gravity = Vec3(0, 0, -kG);
  scene.bodies[0].nodes = { NodeDef{ Vec3::Zero(), 1.0, Vec3::Zero(), true },
                            NodeDef{ Vec3(0, 0, -1), 1.0, Vec3::Zero(), false } };
  scene.bodies[0].springs = { SpringDef{ 0, 1, 100.0, 20.0, 1.0 } };
  return buildWorld(scene);
}

TEST(BodyScaling, AStifferSpringSettlesAtTheStretchOfItsNewStiffness)
{
  // Static equilibrium: stretch = m g / (s k). Settled after 5 s (decay time m / c... 0.1 s at
  // critical damping), the remaining error is far below 1e-9 m.
  World world = hangingSpring();
  ASSERT_TRUE(world.setBodyScaling("body", BodyScaling{ 4.0, 1.0, 1.0 }));
  for (int n = 0; n < 5000; ++n)
    world.step();
  EXPECT_NEAR(-1.0 - world.state().position(2, 1), kG / (4.0 * 100.0), 1e-9);
  EXPECT_EQ(world.bodyScaling("body").stiffness, 4.0);
}

TEST(BodyScaling, FactorsApplyToTheBuiltValuesAndDoNotCompound)
{
  World world = hangingSpring();
  world.setBodyScaling("body", BodyScaling{ 2.0, 3.0, 1.0 });
  world.setBodyScaling("body", BodyScaling{ 0.5, 0.25, 1.0 });
  EXPECT_EQ(world.model().springs[0].stiffness, 50.0);
  EXPECT_EQ(world.model().springs[0].damping, 5.0);
  world.setBodyScaling("body", BodyScaling{});
  EXPECT_EQ(world.model().springs[0].stiffness, 100.0);
  EXPECT_EQ(world.model().springs[0].damping, 20.0);
  EXPECT_FALSE(world.setBodyScaling("no_such_body", BodyScaling{}));
  EXPECT_THROW(world.setBodyScaling("body", BodyScaling{ 0.0, 1.0, 1.0 }), std::invalid_argument);
  EXPECT_THROW(world.setBodyScaling("body", BodyScaling{ 1.0, -1.0, 1.0 }), std::invalid_argument);
  EXPECT_THROW(world.setBodyScaling("body", BodyScaling{ 1.0, 1.0, INFINITY }), std::invalid_argument);
  EXPECT_TRUE(world.setBodyScaling("body", BodyScaling{ 1.0, 0.0, 1.0 }));  // undamped is fine
  EXPECT_EQ(world.model().springs[0].damping, 0.0);
}

TEST(BodyScaling, ConstraintsAndCellsScaleOnlyInTheirOwnBody)
{
  // Two bodies: a constraint (stiffness 1 / compliance) and a cell in each.
  SceneDef scene = oneBodyScene(IntegratorType::Xpbd, 1e-3);
  BodyDef square;
  square.nodes = { NodeDef{ Vec3(0, 0, 0) }, NodeDef{ Vec3(1, 0, 0) }, NodeDef{ Vec3(1, 1, 0) }, NodeDef{ Vec3(0, 1, 0) } };
  square.constraints = { ConstraintDef{ 0, 2, 0.01, {} } };
  square.cells = { CellDef{ { 0, 1, 2, 3 }, Vec3::UnitZ(), 10.0, {} } };
  square.name = "a";
  scene.bodies[0] = square;
  square.name = "b";
  scene.bodies.push_back(square);
  World world = buildWorld(scene);
  ASSERT_TRUE(world.setBodyScaling("b", BodyScaling{ 4.0, 1.0, 3.0 }));
  EXPECT_EQ(world.model().constraints[0].compliance, 0.01);
  EXPECT_EQ(world.model().constraints[1].compliance, 0.0025);
  EXPECT_EQ(world.model().cells[0].pressure, 10.0);
  EXPECT_EQ(world.model().cells[1].pressure, 30.0);
}

TEST(BodyScaling, AVolumesModuliAndGasScaleOnlyInItsOwnBody)
{
  // Two 2 cm cubes of E = 1e4 Pa, nu = 0.25 (mu = lambda = 4000 Pa), gas 1000 Pa; only b is scaled.
  SceneDef scene = oneBodyScene(IntegratorType::ImplicitEuler, 1e-3);
  VolumeDef cube = boxVolume(Vec3(0.02, 0.02, 0.02), 0.02, Vec3::Zero(), 1.0e4, 0.25, 100.0);
  cube.pressure = 1000.0;
  scene.bodies[0] = buildVolume("a", cube);
  cube.position = Vec3(0.1, 0.0, 0.0);
  scene.bodies.push_back(buildVolume("b", cube));
  World world = buildWorld(scene);
  ASSERT_TRUE(world.setBodyScaling("b", BodyScaling{ 2.0, 1.0, 3.0 }));
  int in_b = 0;
  for (const Tetrahedron& tet : world.model().tetrahedra)
  {
    const bool scaled = world.model().bodyOf(tet.nodes[0]) == 1;
    in_b += scaled;
    EXPECT_NEAR(tet.mu, scaled ? 8000.0 : 4000.0, 1e-9);
    EXPECT_NEAR(tet.lambda, scaled ? 8000.0 : 4000.0, 1e-9);
    EXPECT_EQ(tet.pressure, scaled ? 3000.0 : 1000.0);
  }
  EXPECT_GT(in_b, 0);
  EXPECT_LT(in_b, static_cast<int>(world.model().tetrahedra.size()));
}

TEST(AnchorPath, AnAnchorFollowingACircleIsOnItAtTheEndOfEveryStep)
{
  RopeDef rope;
  rope.nodes = 5;
  rope.pinned = { 0 };
  SceneDef scene = oneBodyScene(IntegratorType::SemiImplicitEuler, 1e-3);
  scene.bodies[0] = buildRope("rope", rope);
  scene.bodies[0].anchors = { AnchorDef{ "start", 0 } };
  World world = buildWorld(scene);
  const double radius = 0.3, omega = 2.0;  // [m], [rad/s]
  const auto circle = [&](double t) { return Vec3(radius * std::cos(omega * t), radius * std::sin(omega * t), 0.0); };
  world.followPath(0, [&](double t) { return std::optional<Vec3>(circle(t)); });
  for (int n = 0; n < 100; ++n)
  {
    world.step();
    ASSERT_TRUE(expectNear(Vec3(world.state().position.col(0)), circle(world.time()), 1e-15)) << "step " << n;
  }
  // A moveAnchor overrides the path for one step.
  world.moveAnchor(0, Vec3(5, 5, 5));
  world.step();
  EXPECT_EQ(Vec3(world.state().position.col(0)), Vec3(5, 5, 5));
  world.step();
  EXPECT_TRUE(expectNear(Vec3(world.state().position.col(0)), circle(world.time()), 1e-15));
  world.followPath(0, {});  // stops following: it stays
  const Vec3 held = world.state().position.col(0);
  world.step();
  EXPECT_EQ(Vec3(world.state().position.col(0)), held);
}

TEST(Attach, AGraspedNodeIsHeldMovedAndReleasedWithItsVelocity)
{
  // A free rope falling: grasp node 2, hold it, carry it along x, let go.
  RopeDef rope;
  rope.nodes = 5;
  rope.mass = 0.5;
  rope.stiffness = 10.0;  // soft: the springs' pull during the release step is ~2e-3 m/s
  SceneDef scene = oneBodyScene(IntegratorType::SemiImplicitEuler, 1e-3);
  scene.physics.gravity = Vec3(0, 0, -kG);
  scene.bodies[0] = buildRope("rope", rope);
  scene.bodies[0].nodes[0].pinned = true;
  scene.bodies[0].anchors = { AnchorDef{ "start", 0 } };
  World world = buildWorld(scene);
  for (int n = 0; n < 10; ++n)
    world.step();

  EXPECT_FALSE(world.nearestFreeNode(Vec3(0.5, 0, 0.01), "rope", 1e-3));  // nothing that close
  EXPECT_FALSE(world.nearestFreeNode(Vec3(0.0, 0, 0), "rope", 0.1));   // node 0 is pinned
  const std::optional<int> node = world.nearestFreeNode(Vec3(0.5, 0, 0.01), "", 0.1);
  ASSERT_TRUE(node);
  EXPECT_EQ(*node, 2);
  const int anchor = world.attach(*node, "gripper");
  EXPECT_EQ(anchor, 1);
  EXPECT_TRUE(world.isAttached(anchor));
  EXPECT_FALSE(world.isAttached(0));
  EXPECT_EQ(world.findAnchor("rope", "gripper"), std::optional<int>(1));
  EXPECT_THROW(world.attach(*node, "again"), std::invalid_argument);  // pinned now
  EXPECT_THROW(world.attach(3, "gripper"), std::invalid_argument);    // name taken

  // Held: it does not move while the rest falls.
  const Vec3 grasped = world.state().position.col(2);
  for (int n = 0; n < 10; ++n)
    world.step();
  EXPECT_EQ(Vec3(world.state().position.col(2)), grasped);
  EXPECT_LT(world.state().position(2, 3), grasped.z());

  // Carried at 1 m/s along x, then released: it leaves with that velocity, plus one step of gravity
  // and the springs' pull (semi-implicit Euler: v += h a).
  const double t0 = world.time();
  world.followPath(anchor, [&](double t) { return std::optional<Vec3>(grasped + Vec3(t - t0, 0, 0)); });
  for (int n = 0; n < 10; ++n)
    world.step();
  EXPECT_TRUE(expectNear(Vec3(world.state().position.col(2)), Vec3(grasped + Vec3(0.01, 0, 0)), 1e-12));
  EXPECT_TRUE(expectNear(Vec3(world.state().velocity.col(2)), Vec3(1, 0, 0), 1e-9));
  EXPECT_FALSE(world.detach(0));  // a scene anchor stays
  ASSERT_TRUE(world.detach(anchor));
  EXPECT_FALSE(world.findAnchor("rope", "gripper"));
  EXPECT_EQ(world.model().anchors.size(), 1u);
  EXPECT_TRUE(world.model().isFree(2));
  world.step();
  EXPECT_NEAR(world.state().velocity(0, 2), 1.0, 0.01);
  EXPECT_GT(world.state().position(0, 2), grasped.x() + 0.01);
}

}  // namespace
}  // namespace soft_body_sim::test
