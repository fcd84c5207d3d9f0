// The world's stages against independent truth: kinematic anchors and plane contacts.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "soft_body_sim/core/bodies/rope.h"
#include "soft_body_sim/core/elements/forces.h"
#include "test_util.h"

namespace soft_body_sim::test
{
namespace
{
TEST(Anchors, AnAnchoredNodeArrivesExactlyWhereItWasSentWithinOneStep)
{
  RopeDef rope;
  rope.nodes = 5;
  SceneDef scene = oneBodyScene(IntegratorType::SemiImplicitEuler, 1e-3);
  scene.bodies[0] = buildRope("rope", rope);
  scene.bodies[0].anchors = { AnchorDef{ "end", 4 } };
  scene.physics.step.substeps = 3;
  World world = buildWorld(scene);
  const std::optional<int> anchor = world.findAnchor("rope", "end");
  ASSERT_TRUE(anchor);
  EXPECT_FALSE(world.findAnchor("rope", "start"));
  const Vec3 goal(1.5, 0.2, -0.1);
  world.moveAnchor(*anchor, goal);
  world.step();
  EXPECT_EQ(Vec3(world.state().position.col(4)), goal);
  // It moved at constant velocity over the step: (goal - start) / dt.
  EXPECT_TRUE(expectNear(Vec3(world.state().velocity.col(4)), Vec3((goal - Vec3(1, 0, 0)) / 1e-3), 1e-9));
  world.step();
  EXPECT_EQ(Vec3(world.state().position.col(4)), goal);
  EXPECT_TRUE(world.state().velocity.col(4).isZero(0.0));
}

/// One free node of mass 1 kg above a floor z = 0 (the plane's normal given unnormalised on purpose).
World nodeAboveFloor(IntegratorType integrator, double dt, const Vec3& position, const Vec3& velocity,
                     double restitution, double friction)
{
  SceneDef scene = oneBodyScene(integrator, dt);
  scene.physics.gravity = Vec3(0, 0, -9.81);
  scene.colliders.planes = { Plane{ Vec3::Zero(), Vec3(0, 0, 3), restitution, friction } };
  scene.bodies[0].nodes = { NodeDef{ position, 1.0, velocity, false } };
  return buildWorld(scene);
}

TEST(Planes, ABounceKeepsTheRestitutionFractionOfTheImpactSpeed)
{
  // Dropped from H = 1 m: impact speed sqrt(2 g H); the first rebound leaves at e times that and rises
  // to e^2 H. The contact is found at a step boundary, so the impact speed is off by at most g h and
  // the apex by about v h: with h = 1e-4 s, 1e-3 m/s and 1e-3 m are generous.
  const double restitution = 0.6, height = 1.0, g = 9.81, dt = 1e-4;
  for (IntegratorType integrator : { IntegratorType::SemiImplicitEuler, IntegratorType::Verlet, IntegratorType::Xpbd })
  {
    World world = nodeAboveFloor(integrator, dt, Vec3(0, 0, height), Vec3::Zero(), restitution, 0.0);
    double rebound_speed = 0.0, apex = 0.0;
    bool bounced = false;
    for (int n = 0; n < 20000; ++n)
    {
      const double vz_before = world.state().velocity(2, 0);
      world.step();
      const double vz = world.state().velocity(2, 0);
      if (!bounced && vz_before < 0.0 && vz > 0.0)
      {
        bounced = true;
        rebound_speed = vz;
      }
      if (bounced)
      {
        apex = std::max(apex, world.state().position(2, 0));
        if (vz < 0.0)
          break;
      }
    }
    ASSERT_TRUE(bounced) << integratorName(integrator);
    EXPECT_NEAR(rebound_speed, restitution * std::sqrt(2.0 * g * height), 2e-3) << integratorName(integrator);
    EXPECT_NEAR(apex, restitution * restitution * height, 2e-3) << integratorName(integrator);
  }
}

TEST(Planes, AFastNodeDoesNotTunnel)
{
  // 100 m/s at the default step moves 0.1 m per step: the half-space test still catches it.
  for (IntegratorType integrator : { IntegratorType::SemiImplicitEuler, IntegratorType::Rk4, IntegratorType::Xpbd,
                                     IntegratorType::ImplicitEuler })
  {
    World world = nodeAboveFloor(integrator, 1e-3, Vec3(0, 0, 0.25), Vec3(0, 0, -100), 0.0, 0.0);
    for (int n = 0; n < 100; ++n)
    {
      world.step();
      ASSERT_GE(world.state().position(2, 0), 0.0) << integratorName(integrator) << " step " << n;
    }
  }
}

TEST(Planes, CoulombFrictionStopsASlidingNodeAfterVSquaredOverTwoMuG)
{
  // A node sliding at v0 decelerates at mu g: it stops after v0^2 / (2 mu g) = 0.5097 m. Each step's
  // contact removes exactly mu g h of tangential speed; the stop falls within one step, v0 h = 2e-3 m.
  const double v0 = 2.0, mu = 0.4, g = 9.81, dt = 1e-3;
  World world = nodeAboveFloor(IntegratorType::SemiImplicitEuler, dt, Vec3::Zero(), Vec3(v0, 0, 0), 0.0, mu);
  for (int n = 0; n < 2000; ++n)
    world.step();
  EXPECT_NEAR(world.state().position(0, 0), v0 * v0 / (2.0 * mu * g), v0 * dt);
  EXPECT_EQ(world.state().velocity(0, 0), 0.0);  // friction never reverses the sliding direction
}

TEST(Planes, ARestingNodeDoesNotJitter)
{
  // On the floor, each step gravity adds g h of approach speed, which is below the resting speed and is
  // removed: the node stays on the plane and its kinetic energy stays below m (g h)^2 / 2.
  const double dt = 1e-3, g = 9.81;
  World world = nodeAboveFloor(IntegratorType::SemiImplicitEuler, dt, Vec3::Zero(), Vec3::Zero(), 0.9, 0.0);
  for (int n = 0; n < 10000; ++n)
  {
    world.step();
    ASSERT_LE(0.5 * world.state().velocity.col(0).squaredNorm(), 0.5 * (g * dt) * (g * dt)) << "step " << n;
    ASSERT_NEAR(world.state().position(2, 0), 0.0, g * dt * dt) << "step " << n;
  }
}

TEST(Planes, ALoadedNodeOnABouncyFloorComesToRest)
{
  // A node carrying another on a spring presses into the floor harder than its own weight, faster
  // than the resting speed 2 g h; being in contact since the last sub-step, it must still not bounce.
  // With spring damping the column settles: its kinetic energy falls far below one bounce's
  // m (e 2 g h)^2 / 2 ~ 7e-4 J and stays there.
  SceneDef scene = oneBodyScene(IntegratorType::SemiImplicitEuler, 1e-3);
  scene.physics.gravity = Vec3(0, 0, -9.81);
  scene.colliders.planes = { Plane{ Vec3::Zero(), Vec3::UnitZ(), 0.9, 0.0 } };
  scene.bodies[0].nodes = { NodeDef{ Vec3(0, 0, 0), 1.0 }, NodeDef{ Vec3(0, 0, 0.1), 10.0 } };
  scene.bodies[0].springs = { SpringDef{ 0, 1, 1e4, 400.0, 0.1 } };  // damping ratio 0.6
  World world = buildWorld(scene);
  for (int n = 0; n < 5000; ++n)
    world.step();
  double largest = 0.0;
  for (int n = 0; n < 1000; ++n)
  {
    world.step();
    largest = std::max(largest, kineticEnergy(world.model(), world.state()));
  }
  EXPECT_LT(largest, 1e-9);
}

TEST(Planes, PinnedNodesAreLeftWhereTheyAre)
{
  SceneDef scene = oneBodyScene(IntegratorType::SemiImplicitEuler, 1e-3);
  scene.colliders.planes = { Plane{ Vec3::Zero(), Vec3::UnitZ(), 0.0, 0.0 } };
  scene.bodies[0].nodes = { NodeDef{ Vec3(0, 0, -1), 1.0, Vec3::Zero(), true } };
  World world = buildWorld(scene);
  world.step();
  EXPECT_EQ(Vec3(world.state().position.col(0)), Vec3(0, 0, -1));
}

TEST(Strain, TheLargestRelativeStretchOfAnySpringOrConstraint)
{
  // Springs of rest 1 m at 1.5 m (strain 0.5) and 0.8 m (0.2), a constraint of rest 2 m at 2.2 m (0.1),
  // a zero-rest-length spring (no strain defined: skipped).
  Model model;
  model.mass = Eigen::VectorXd::Ones(4);
  model.inverse_mass = Eigen::VectorXd::Ones(4);
  model.springs = { Spring{ 0, 1, 1.0, 10.0, 0.0 }, Spring{ 1, 2, 1.0, 10.0, 0.0 }, Spring{ 2, 3, 0.0, 10.0, 0.0 } };
  model.constraints = { DistanceConstraint{ 0, 3, 2.0, 0.0 } };
  State state;
  state.position.resize(3, 4);
  state.position << 0.0, 1.5, 2.3, 2.2,  //
      0.0, 0.0, 0.0, 0.0,                 //
      0.0, 0.0, 0.0, 0.0;
  state.velocity = NodeArray::Zero(3, 4);
  EXPECT_DOUBLE_EQ(maxStrain(model, state), 0.5);
  model.springs[0].rest_length = 1.5;  // now at rest: the 0.8 m spring's 0.2 is the largest
  EXPECT_NEAR(maxStrain(model, state), 0.2, 1e-15);
  state.position(0, 2) = std::nan("");
  EXPECT_EQ(maxStrain(model, state), std::numeric_limits<double>::infinity());
}

}  // namespace
}  // namespace soft_body_sim::test
