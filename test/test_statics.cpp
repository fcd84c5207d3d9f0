// Static equilibria against closed forms: a vertical elastic chain's stretch and the elastic discrete
// catenary of a chain pinned at both ends. The damped dynamics must come to rest exactly there.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "catenary.h"
#include "test_util.h"

namespace soft_body_sim::test
{
namespace
{
// A chain of N nodes hangs from a pinned top node. Spring j (between nodes j-1 and j) carries the weight
// of the N - j nodes below it, so it is stretched by (N - j) m g / k and node j sits at
//   z_j = -sum_{i=1..j} (L + (N - i) m g / k).
struct VerticalChain
{
  int nodes = 11;
  double node_mass = 0.01;   // [kg]
  double stiffness = 50.0;   // [N/m]
  double rest = 0.1;         // [m]

  SceneDef scene(IntegratorType integrator, double dt, int iterations) const
  {
    SceneDef s = oneBodyScene(integrator, dt);
    s.physics.gravity = Vec3(0, 0, -kGravity);
    s.physics.drag = 2.0;
    s.physics.step.iterations = iterations;
    BodyDef& body = s.bodies[0];
    for (int j = 0; j < nodes; ++j)
      body.nodes.push_back(NodeDef{ Vec3(0, 0, -rest * j), node_mass, Vec3::Zero(), j == 0 });
    for (int j = 1; j < nodes; ++j)
      body.springs.push_back(SpringDef{ j - 1, j, stiffness, 0.05, rest });
    return s;
  }

  Eigen::Matrix3Xd exact() const
  {
    Eigen::Matrix3Xd x = Eigen::Matrix3Xd::Zero(3, nodes);
    for (int j = 1; j < nodes; ++j)
      x(2, j) = x(2, j - 1) - (rest + (nodes - j) * node_mass * kGravity / stiffness);
    return x;
  }
};

TEST(VerticalChain, ImplicitEulerSettlesOnTheClosedFormStretch)
{
  // Backward Euler's fixed point (v = 0) is exactly f(x) = 0, so only the settling residual remains:
  // it is bounded by the stop speed times the slowest decay time (~1 s), hence 1e-9 m.
  const VerticalChain chain;
  World world = buildWorld(chain.scene(IntegratorType::ImplicitEuler, 0.01, 3));
  settle(world, 1e-11, 100000);
  EXPECT_TRUE(expectNear(world.state().position, chain.exact(), 1e-9));
  // The total stretch, (N - 1) N m g / (2 k), as a single figure.
  const double length = -world.state().position(2, chain.nodes - 1);
  const double stretch = chain.nodes * (chain.nodes - 1) * chain.node_mass * kGravity / (2.0 * chain.stiffness);
  EXPECT_NEAR(length, (chain.nodes - 1) * chain.rest + stretch, 1e-9);
}

TEST(VerticalChain, ExplicitSchemesComeToRestOnTheSameStretch)
{
  // Every force-based scheme has f(x) = 0 as its rest state; settling with drag at a stable step.
  const VerticalChain chain;
  for (IntegratorType integrator : { IntegratorType::SemiImplicitEuler, IntegratorType::Verlet,
                                     IntegratorType::VelocityVerlet, IntegratorType::Rk4 })
  {
    World world = buildWorld(chain.scene(integrator, 2e-3, 1));
    settle(world, 1e-11, 200000);
    EXPECT_TRUE(expectNear(world.state().position, chain.exact(), 1e-9)) << integratorName(integrator);
  }
}

TEST(VerticalChain, XpbdWithConvergedIterationsMatchesTheClosedForm)
{
  // XPBD's rest state solves C + alpha~ lambda = 0 with x - x~ = M^-1 grad C^T lambda, which is
  // the static equilibrium once the Gauss-Seidel sweeps have converged (Macklin et al. 2016, sec. 4).
  // 400 sweeps over 10 constraints reduce the sweep error far below the 1e-9 m asked.
  const VerticalChain chain;
  World world = buildWorld(chain.scene(IntegratorType::Xpbd, 0.01, 400));
  settle(world, 1e-11, 100000);
  EXPECT_TRUE(expectNear(world.state().position, chain.exact(), 1e-9));
}

TEST(HangingChain, SettlesOnTheElasticDiscreteCatenary)
{
  // 1 m, 0.1 kg, 21 nodes, pinned at both ends 0.8 m apart; released from a V of the rest length.
  const int nodes = 21;
  const double mass = 0.1 / nodes, stiffness = 200.0, rest = 1.0 / (nodes - 1), span = 0.8;
  SceneDef scene = oneBodyScene(IntegratorType::ImplicitEuler, 0.01);
  scene.physics.gravity = Vec3(0, 0, -kGravity);
  scene.physics.drag = 1.0;
  scene.physics.step.iterations = 2;
  BodyDef& body = scene.bodies[0];
  const int middle = (nodes - 1) / 2;
  for (int j = 0; j < nodes; ++j)
  {
    const double along = std::abs(j - middle) * rest;  // distance from the V's tip along one arm
    const Vec3 position(span / 2 + (j < middle ? -1 : 1) * along * 0.8, 0.0, -0.3 + along * 0.6);
    body.nodes.push_back(NodeDef{ position, mass, Vec3::Zero(), j == 0 || j == nodes - 1 });
  }
  for (int j = 1; j < nodes; ++j)
    body.springs.push_back(SpringDef{ j - 1, j, stiffness, 0.01, rest });
  World world = buildWorld(scene);
  const Eigen::Matrix3Xd start = world.state().position;

  settle(world, 1e-11, 100000);
  const Eigen::Matrix3Xd truth = discreteCatenary(nodes, mass, stiffness, rest, span);
  ASSERT_NEAR(truth(2, nodes - 1), 0.0, 1e-12) << "the reference is not symmetric";
  EXPECT_TRUE(expectNear(world.state().position, truth, 1e-9));
  // Pinned ends exactly where they were.
  EXPECT_EQ(world.state().position.col(0), start.col(0));
  EXPECT_EQ(world.state().position.col(nodes - 1), start.col(nodes - 1));
}

}  // namespace
}  // namespace soft_body_sim::test
