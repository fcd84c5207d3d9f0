// The forces that bodies exert on their anchors and the tensions of their links (reactions.h), against
// statics and a closed-form pendulum: a hanging rope's weight, the discrete catenary's horizontal tension,
// and the 3 m g at the bottom of a pendulum's swing.
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "catenary.h"
#include "soft_body_sim/core/bodies/jelly.h"
#include "soft_body_sim/core/bodies/rope.h"
#include "soft_body_sim/core/integrators/integrator_groups.h"
#include "test_util.h"

namespace soft_body_sim::test
{
namespace
{
/// A scene of one rope of 21 nodes, 1 m and 0.1 kg, laid at rest along `path`, springs of 200 N/m with
/// dashpots, under gravity with air drag so that it comes to rest; `pinned` nodes are anchors named "end0",
/// "end1", ...
SceneDef ropeScene(const std::vector<Vec3>& path, const std::vector<int>& pinned)
{
  SceneDef scene = oneBodyScene(IntegratorType::Xpbd, 2e-3);
  scene.physics.gravity = Vec3(0, 0, -kGravity);
  scene.physics.drag = 2.0;
  RopeDef rope;
  rope.nodes = 21;
  rope.path = path;
  rope.mass = 0.1;
  rope.stiffness = 200.0;
  rope.damping = 0.05;
  rope.pinned = pinned;
  scene.bodies[0] = buildRope("rope", rope);
  for (std::size_t k = 0; k < pinned.size(); ++k)
    scene.bodies[0].anchors.emplace_back("end" + std::to_string(k), pinned[k]);
  return scene;
}

TEST(AnchorForce, AHangingRopesAnchorCarriesItsWeightWithEveryIntegrator)
{
  // At rest, the anchor holds the rope: the springs pull its node down with the weight of the nodes
  // below, and its own node's weight adds the rest, whatever the integrator.
  const double weight = 0.1 * kGravity;
  const SceneDef base = ropeScene({ Vec3(0, 0, 0), Vec3(0, 0, -1.0) }, { 0 });
  const std::vector<IntegratorType> stable = stableIntegrators(base);
  ASSERT_GE(stable.size(), 6u) << "the scene's step should suit all but explicit Euler";
  for (const IntegratorType integrator : stable)
  {
    SceneDef scene = base;
    scene.physics.integrator = integrator;
    World world = buildWorld(scene);
    ASSERT_TRUE(settle(world, 1e-7, 200000)) << integratorName(integrator);
    const std::vector<Wrench> wrenches = world.anchorWrenches();
    ASSERT_EQ(wrenches.size(), 1u);
    EXPECT_TRUE(expectNear(wrenches[0].force, Vec3(0, 0, -weight), 1e-3 * weight)) << integratorName(integrator);
    EXPECT_TRUE(expectNear(wrenches[0].torque, Vec3::Zero(), 1e-12)) << integratorName(integrator);
    // The top spring carries the 20 nodes below it.
    EXPECT_NEAR(world.linkTensions()[0], weight * 20.0 / 21.0, 1e-3 * weight) << integratorName(integrator);
  }
}

TEST(AnchorForce, AChainsAnchorsTakeTheCatenarysHorizontalTensionAndItsWeight)
{
  // A chain pinned at both ends 0.8 m apart: each anchor is pulled inward by the discrete catenary's
  // horizontal tension H, and the two carry the chain's weight between them, half each by symmetry.
  const int nodes = 21;
  const double node_mass = 0.1 / nodes, span = 0.8;
  const double horizontal = catenaryHorizontalTension(nodes, node_mass, 200.0, 1.0 / (nodes - 1), span);
  const double weight = 0.1 * kGravity;
  // Released from a V of its rest length.
  const SceneDef base = ropeScene({ Vec3(0, 0, 0), Vec3(span / 2, 0, -0.3), Vec3(span, 0, 0) }, { 0, 20 });
  for (const IntegratorType integrator : stableIntegrators(base))
  {
    SceneDef scene = base;
    scene.physics.integrator = integrator;
    // xpbd sweeps an even chain by Gauss-Seidel, whose rest shape with one sweep per sub-step sags
    // g h^2 N^2 / (pi^2 sweeps) too far (docs/RESULTS.md), here 4.5 mm and 1.7 % of H: the readout is
    // its state's, so the sweeps are converged here.
    if (integrator == IntegratorType::Xpbd)
      scene.physics.step.iterations = 100;
    World world = buildWorld(scene);
    ASSERT_TRUE(settle(world, 1e-7, 200000)) << integratorName(integrator);
    const std::vector<Wrench> wrenches = world.anchorWrenches();
    ASSERT_EQ(wrenches.size(), 2u);
    EXPECT_TRUE(expectNear(wrenches[0].force, Vec3(horizontal, 0, -weight / 2), 1e-3 * horizontal))
        << integratorName(integrator);
    EXPECT_TRUE(expectNear(wrenches[1].force, Vec3(-horizontal, 0, -weight / 2), 1e-3 * horizontal))
        << integratorName(integrator);
    EXPECT_NEAR(wrenches[0].force.z() + wrenches[1].force.z(), -weight, 1e-3 * weight) << integratorName(integrator);
  }
}

TEST(AnchorForce, AJellyHangingFromItsTopCornersHasThemCarryItsWeight)
{
  // A 3 x 3 jelly of 1 kg hangs from its top corners: its springs and the gas in its cells (which pushes
  // on the corners too) hold them, and at rest the two carry its whole weight, half each by symmetry.
  JellyDef jelly;
  jelly.nx = jelly.ny = 3;
  SceneDef scene = oneBodyScene(IntegratorType::Xpbd, 2e-3);
  scene.physics.gravity = Vec3(0, 0, -kGravity);
  scene.physics.drag = 2.0;
  scene.bodies[0] = buildJelly("jelly", jelly);
  for (NodeDef& node : scene.bodies[0].nodes)
    node.mass = 1.0 / 16.0;
  scene.bodies[0].nodes[0].pinned = scene.bodies[0].nodes[3].pinned = true;
  scene.bodies[0].anchors = { AnchorDef("left", 0), AnchorDef("right", 3) };
  const double weight = kGravity;
  for (const IntegratorType integrator : stableIntegrators(scene))
  {
    scene.physics.integrator = integrator;
    World world = buildWorld(scene);
    ASSERT_TRUE(settle(world, 1e-7, 200000)) << integratorName(integrator);
    const std::vector<Wrench> wrenches = world.anchorWrenches();
    ASSERT_EQ(wrenches.size(), 2u);
    EXPECT_NEAR(wrenches[0].force.z() + wrenches[1].force.z(), -weight, 1e-3 * weight) << integratorName(integrator);
    EXPECT_NEAR(wrenches[0].force.z(), -weight / 2, 1e-3 * weight) << integratorName(integrator);
    // The cells do push on the corners: without them the springs alone would not balance the weight.
    EXPECT_GT(world.internalForces().pressure.cwiseAbs().maxCoeff(), 1.0) << integratorName(integrator);
  }
}

TEST(LinkTension, APendulumsLinkCarriesThreeTimesItsWeightAtTheBottom)
{
  // A mass m on an inextensible link of length L, released from rest with the link horizontal: at the
  // bottom v^2 = 2 g L (energy), and the link pulls up with the weight plus the centripetal force,
  // T = m g + m v^2 / L = 3 m g. The step whose end is nearest the bottom is within v dt / L = 1.4e-3 rad
  // of it, where T differs from 3 m g by a factor cos(1.4e-3), 1e-6.
  const double mass = 0.2, length = 1.0, dt = 1e-4;
  for (const std::string& name : integratorNames())
  {
    IntegratorType integrator;
    integratorFromName(name, integrator);
    SceneDef scene = oneBodyScene(integrator, dt);
    scene.physics.gravity = Vec3(0, 0, -kGravity);
    scene.physics.step.iterations = 2;
    BodyDef& body = scene.bodies[0];
    body.nodes.push_back(NodeDef{ Vec3::Zero(), 0.1, Vec3::Zero(), true });
    body.nodes.push_back(NodeDef{ Vec3(length, 0, 0), mass, Vec3::Zero(), false });
    body.constraints.push_back(ConstraintDef{ 0, 1, 0.0, length });
    body.anchors.emplace_back("pivot", 0);
    World world = buildWorld(scene);
    double tension = 0.0;
    double lowest_x = length;
    for (int n = 0; n < 10000; ++n)
    {
      world.step();
      const Vec3 x = world.state().position.col(1);
      if (std::abs(x.x()) < lowest_x && x.z() < 0.0)
      {
        lowest_x = std::abs(x.x());
        tension = world.linkTensions()[0];
      }
      if (x.x() < -0.1)
        break;  // past the bottom
    }
    ASSERT_LT(lowest_x, 4.5 * dt * length) << name << ": the pendulum never reached the bottom";
    EXPECT_NEAR(tension, 3.0 * mass * kGravity, 0.01 * 3.0 * mass * kGravity) << name;
  }
}

TEST(LinkTension, EachBodysLinksTakeTheirTensionsFromTheIntegratorSteppingIt)
{
  // Two bodies hanging at rest: a 0.3 kg mass on a spring (stretched by its weight), and a 0.2 kg mass on
  // an inextensible link. With the second body moved to xpbd (as the guard does), the groups' tensions
  // come back in the model's order: 0.3 g for the spring, 0.2 g for the link.
  SceneDef scene = oneBodyScene(IntegratorType::SemiImplicitEuler, 1e-3);
  scene.physics.gravity = Vec3(0, 0, -kGravity);
  BodyDef& spring = scene.bodies[0];
  spring.nodes = { NodeDef{ Vec3::Zero(), 0.1, Vec3::Zero(), true },
                   NodeDef{ Vec3(0, 0, -1.0 - 0.3 * kGravity / 100.0), 0.3, Vec3::Zero(), false } };
  spring.springs.push_back(SpringDef{ 0, 1, 100.0, 0.0, 1.0 });
  BodyDef link;
  link.name = "link";
  link.nodes = { NodeDef{ Vec3(1, 0, 0), 0.1, Vec3::Zero(), true },
                 NodeDef{ Vec3(1, 0, -0.5), 0.2, Vec3::Zero(), false } };
  link.constraints.push_back(ConstraintDef{ 0, 1, 0.0, 0.5 });
  scene.bodies.push_back(link);
  const World world = buildWorld(scene);
  State state = world.state();
  IntegratorGroups groups(IntegratorType::SemiImplicitEuler, 2);
  groups.switchBody(1, IntegratorType::Xpbd);
  groups.prepare(world.model());
  groups.step(world.model(), state, 1e-3, 1, nullptr);
  InternalForces forces;
  groups.internalForces(world.model(), state, forces);
  ASSERT_EQ(forces.tension.size(), 2);
  EXPECT_NEAR(forces.tension[0], 0.3 * kGravity, 1e-9);
  EXPECT_NEAR(forces.tension[1], 0.2 * kGravity, 1e-9);
}

}  // namespace
}  // namespace soft_body_sim::test
