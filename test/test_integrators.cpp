// Each integrator against independent truth: the TUM tutorial's worked exercises, the damped harmonic
// oscillator's closed form, measured orders of convergence, and the stability theory of each scheme.
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "core/elements/wide_columns.h"
#include "soft_body_sim/core/bodies/cloth.h"
#include "soft_body_sim/core/bodies/rope.h"
#include "soft_body_sim/core/elements/forces.h"
#include "test_util.h"

namespace soft_body_sim::test
{
namespace
{
const std::vector<IntegratorType> kAllIntegrators = {
  IntegratorType::ExplicitEuler, IntegratorType::SemiImplicitEuler, IntegratorType::Verlet,
  IntegratorType::VelocityVerlet, IntegratorType::Rk4,   IntegratorType::ImplicitEuler,
  IntegratorType::Xpbd,
};

Vec3 nodePosition(const World& world, int node) { return world.state().position.col(node); }

// --- TUM tutorial (tum-mass-spring-tutorial.txt), explicit Euler, h = 0.5, two steps ---------------

TEST(TumTutorial, Exercise1TwoStepsOfExplicitEuler)
{
  SceneDef scene = oneBodyScene(IntegratorType::ExplicitEuler, 0.5);
  scene.bodies[0].nodes = { NodeDef{ Vec3(2, 4, 0), 1.0 }, NodeDef{ Vec3(1, -3, 0), 1.0 } };
  scene.bodies[0].springs = { SpringDef{ 0, 1, 2.0, 0.0, 4.0 } };
  World world = buildWorld(scene);
  world.step();
  world.step();

  // Step 1 leaves positions alone (v0 = 0); the spring force -2 (5 sqrt2 - 4) u, u = (1, 7) / (5 sqrt2),
  // gives v1 = 0.5 f; step 2 moves x by 0.5 v1.
  const double f = -2.0 * (5.0 * std::sqrt(2.0) - 4.0);
  const Vec3 u = Vec3(1, 7, 0) / (5.0 * std::sqrt(2.0));
  EXPECT_TRUE(expectNear(nodePosition(world, 0), Vec3(Vec3(2, 4, 0) + 0.25 * f * u), 1e-14));
  EXPECT_TRUE(expectNear(nodePosition(world, 1), Vec3(Vec3(1, -3, 0) - 0.25 * f * u), 1e-14));
  // The tutorial's rounded answer: P1 = (1.783, 2.48), P2 = (1.217, -1.48).
  EXPECT_TRUE(expectNear(nodePosition(world, 0), Vec3(1.783, 2.48, 0), 5e-3));
  EXPECT_TRUE(expectNear(nodePosition(world, 1), Vec3(1.217, -1.48, 0), 5e-3));
}

TEST(TumTutorial, Exercise2WithGravityAndUnequalMasses)
{
  SceneDef scene = oneBodyScene(IntegratorType::ExplicitEuler, 0.5);
  scene.physics.gravity = Vec3(0, -10, 0);
  scene.bodies[0].nodes = { NodeDef{ Vec3(-2, 2, 0), 2.0, Vec3(-1, -1.5, 0) },
                            NodeDef{ Vec3(3, 2, 0), 3.0, Vec3(1, -1.5, 0) } };
  scene.bodies[0].springs = { SpringDef{ 0, 1, 4.0, 0.0, 6.0 } };
  World world = buildWorld(scene);
  world.step();
  world.step();
  EXPECT_TRUE(expectNear(nodePosition(world, 0), Vec3(-3.5, -2, 0), 1e-14));
  EXPECT_TRUE(expectNear(nodePosition(world, 1), Vec3(13.0 / 3.0, -2, 0), 1e-14));
}

// --- Damped harmonic oscillator against its closed form ---------------------------------------------

Oscillator dampedOscillator()
{
  Oscillator osc;
  osc.damping = 0.3;  // with drag: zeta = (0.3 + 0.2) / (2 * 2 pi) = 0.04
  osc.drag = 0.2;
  osc.v0 = 0.3;
  return osc;
}

double finalError(const Oscillator& osc, IntegratorType integrator, double dt, double duration)
{
  World world = osc.world(integrator, dt);
  const long steps = std::lround(duration / dt);
  for (long n = 0; n < steps; ++n)
    world.step();
  return std::abs(Oscillator::displacement(world) - osc.exact(world.time()));
}

struct OrderCase
{
  IntegratorType integrator;
  double order;
  double dt;  ///< coarsest step [s], in the asymptotic range yet far above round-off
  double error_bound;  ///< at the coarsest step [m]: the leading term (w h)^p w T x_max, doubled
};

class ConvergenceOrder : public ::testing::TestWithParam<OrderCase>
{
};

// Error at T = 2 s with h, h/2, h/4, h/8: the least-squares slope of log(error) against log(h) is the
// measured order; the tolerance 0.1 covers the O(h) correction to the asymptotic ratio at these steps.
TEST_P(ConvergenceOrder, MatchesTheSchemeOrderOnTheDampedOscillator)
{
  const OrderCase c = GetParam();
  const Oscillator osc = dampedOscillator();
  const double duration = 2.0;
  std::vector<double> log_h, log_error;
  for (int level = 0; level < 4; ++level)
  {
    const double dt = c.dt / std::pow(2.0, level);
    const double error = finalError(osc, c.integrator, dt, duration);
    if (level == 0)
    {
      EXPECT_LT(error, c.error_bound) << integratorName(c.integrator);
    }
    log_h.push_back(std::log(dt));
    log_error.push_back(std::log(error));
  }
  const double mean_h = (log_h[0] + log_h[1] + log_h[2] + log_h[3]) / 4.0;
  const double mean_e = (log_error[0] + log_error[1] + log_error[2] + log_error[3]) / 4.0;
  double num = 0.0, den = 0.0;
  for (int k = 0; k < 4; ++k)
  {
    num += (log_h[k] - mean_h) * (log_error[k] - mean_e);
    den += (log_h[k] - mean_h) * (log_h[k] - mean_h);
  }
  RecordProperty("measured_order", std::to_string(num / den));
  EXPECT_NEAR(num / den, c.order, 0.1) << integratorName(c.integrator);
}

// w = 2 pi, T = 2 s, amplitude ~0.1 m: bound = 2 (w h)^p (w T) 0.1.
double leadingBound(double order, double dt)
{
  const double w = 2.0 * M_PI;
  return 2.0 * std::pow(w * dt, order) * (w * 2.0) * 0.1;
}

INSTANTIATE_TEST_SUITE_P(
    Integrators, ConvergenceOrder,
    ::testing::Values(OrderCase{ IntegratorType::ExplicitEuler, 1.0, 1e-3, leadingBound(1, 1e-3) },
                      OrderCase{ IntegratorType::SemiImplicitEuler, 1.0, 1e-3, leadingBound(1, 1e-3) },
                      OrderCase{ IntegratorType::Verlet, 2.0, 4e-3, leadingBound(2, 4e-3) },
                      OrderCase{ IntegratorType::VelocityVerlet, 2.0, 4e-3, leadingBound(2, 4e-3) },
                      OrderCase{ IntegratorType::Rk4, 4.0, 1e-2, leadingBound(4, 1e-2) },
                      OrderCase{ IntegratorType::ImplicitEuler, 1.0, 1e-3, leadingBound(1, 1e-3) }),
    [](const ::testing::TestParamInfo<OrderCase>& info) { return integratorName(info.param.integrator); });

TEST(HarmonicOscillator, EveryIntegratorFollowsTheAnalyticSolutionAtAFineStep)
{
  // Undamped, h = 1e-4 s over 1 s: first-order schemes err by ~w^2 h T x0 / 2 = 2e-4 m; xpbd with one
  // iteration per sub-step equals implicit Euler on a single spring, so the same bound holds for all.
  Oscillator osc;
  for (IntegratorType integrator : kAllIntegrators)
    EXPECT_LT(finalError(osc, integrator, 1e-4, 1.0), 4e-4) << integratorName(integrator);
}

// --- Stability ---------------------------------------------------------------------------------------

TEST(ExplicitEuler, UndampedEnergyGrowsByOnePlusOmegaSquaredHSquaredEachStep)
{
  // The one-step map x' = x + h v, v' = v - h w^2 x multiplies w^2 x^2 + v^2 by exactly 1 + w^2 h^2.
  // Steps are few enough that the amplitude (growing like (1 + w^2 h^2)^(n/2)) stays far below the
  // rest length, where the spring is linear.
  for (const auto& [omega_h, steps] : { std::pair{ 0.1, 50 }, std::pair{ 1.0, 16 } })
  {
    Oscillator osc;
    osc.x0 = 1e-3;
    const double dt = omega_h / osc.omega0();
    World world = osc.world(IntegratorType::ExplicitEuler, dt);
    for (int n = 0; n < steps; ++n)
    {
      const double before = world.energy();
      world.step();
      EXPECT_NEAR(world.energy() / before, 1.0 + omega_h * omega_h, 1e-9) << "w h = " << omega_h << ", step " << n;
    }
  }
}

double maxDisplacement(World& world, long steps)
{
  double largest = 0.0;
  for (long n = 0; n < steps; ++n)
  {
    world.step();
    largest = std::max(largest, std::abs(Oscillator::displacement(world)));
  }
  return largest;
}

// Started at rest from x0, each symplectic scheme keeps a quadratic invariant (its modified energy):
//   symplectic Euler  w^2 x^2 + v^2 - h w^2 x v   =>  |x| <= x0 / sqrt(1 - (w h)^2 / 4)
//   (velocity) Verlet w^2 x^2 + v^2 / (1 - (w h)^2 / 4)  =>  |x| <= x0
// so the motion stays bounded for w h < 2, here w h = 1.9 over 10^5 steps.
TEST(SymplecticSchemes, StayBoundedJustBelowTheStabilityLimit)
{
  Oscillator osc;
  const double omega_h = 1.9;
  const double dt = omega_h / osc.omega0();
  const double slack = 1e-9;
  World euler = osc.world(IntegratorType::SemiImplicitEuler, dt);
  EXPECT_LE(maxDisplacement(euler, 100000), osc.x0 / std::sqrt(1.0 - omega_h * omega_h / 4.0) + slack);
  for (IntegratorType verlet : { IntegratorType::Verlet, IntegratorType::VelocityVerlet })
  {
    World world = osc.world(verlet, dt);
    EXPECT_LE(maxDisplacement(world, 100000), osc.x0 + slack) << integratorName(verlet);
  }
}

TEST(SymplecticSchemes, DivergeJustAboveTheStabilityLimit)
{
  expectGuardEvents();  // about divergence: the guard catches it
  // w h = 2.1: the one-step map has an eigenvalue below -1, so the same bound must break quickly.
  Oscillator osc;
  osc.x0 = 1e-6;  // stays far from the nonlinear range for the first steps
  const double dt = 2.1 / osc.omega0();
  for (IntegratorType integrator : { IntegratorType::SemiImplicitEuler, IntegratorType::VelocityVerlet })
  {
    World world = osc.world(integrator, dt);
    EXPECT_GT(maxDisplacement(world, 200), 100.0 * osc.x0) << integratorName(integrator);
  }
}

// Backward Euler is dissipative on a linear oscillator; xpbd with one iteration on a single spring is the
// same map (x_{n+1} = (x_n + h v_n) / (1 + w^2 h^2)). At w h = 50 the energy must never rise.
TEST(StiffSchemes, BoundedAndDissipativeFarAboveTheExplicitLimit)
{
  for (IntegratorType integrator : { IntegratorType::ImplicitEuler, IntegratorType::Xpbd })
  {
    Oscillator osc;
    const double dt = 50.0 / osc.omega0();
    World world = osc.world(integrator, dt);
    double energy = world.energy();
    for (int n = 0; n < 1000; ++n)
    {
      world.step();
      ASSERT_TRUE(allFinite(world.state())) << integratorName(integrator);
      EXPECT_LE(world.energy(), energy * (1.0 + 1e-12)) << integratorName(integrator) << " step " << n;
      EXPECT_LE(std::abs(Oscillator::displacement(world)), osc.x0) << integratorName(integrator);
      energy = world.energy();
    }
  }
}

// --- Degenerate geometry -----------------------------------------------------------------------------

TEST(DegenerateGeometry, CoincidentNodesNeverProduceNaN)
{
  for (IntegratorType integrator : kAllIntegrators)
  {
    SceneDef scene = oneBodyScene(integrator, 1e-3);
    scene.physics.gravity = Vec3(0, 0, -9.81);
    scene.physics.drag = 0.1;
    BodyDef& body = scene.bodies[0];
    const Vec3 p(0.5, 0.5, 0.5);
    body.nodes = { NodeDef{ p, 1.0, Vec3::Zero(), true }, NodeDef{ p, 1.0 }, NodeDef{ p, 0.5 },
                   NodeDef{ Vec3(0.5, 0.5, 0.4), 1.0 } };
    body.springs = { SpringDef{ 0, 1, 100.0, 1.0, 0.1 }, SpringDef{ 1, 2, 100.0, 1.0, 0.0 },
                     SpringDef{ 2, 3, 100.0, 1.0, std::nullopt } };
    body.constraints = { ConstraintDef{ 0, 2, 0.0, 0.2 }, ConstraintDef{ 1, 2, 1e-3, std::nullopt } };
    World world = buildWorld(scene);
    for (int n = 0; n < 200; ++n)
    {
      world.step();
      ASSERT_TRUE(allFinite(world.state())) << integratorName(integrator) << " step " << n;
    }
    EXPECT_TRUE(expectNear(nodePosition(world, 0), p, 0.0)) << "pinned node moved, " << integratorName(integrator);
  }
}

TEST(SpringForces, RunsAndColoursGiveEverySpringsTensionOnceWithFourLanesOrTwo)
{
  // The kernel (accumulateSpringForces: runs of consecutive nodes four or two at a time, the other springs
  // by colours) against each spring's tension along its axis (springAxis, springTension), summed spring by
  // spring in model order, on randomly moved nodes: a cloth with bending springs and a rope with them
  // (runs of distance 1, 2, the row's length and more, cut at kMostRun), and springs of every distance
  // from 1 to 9 between random nodes, repeated pairs and coincident ends among them (left to the colours,
  // or runs too short to be one). A spring missed or counted twice would be off by its whole force; the
  // two sums differ by their roundings only.
  ClothDef cloth;
  cloth.nx = 38;  // rows of 37 springs and 36 bending springs, the rope's last parts 43 and 42: 0 to 3 after the fours
  cloth.ny = 9;
  cloth.bending = SpringParameters{ 20.0, 0.01 };
  RopeDef rope;
  rope.nodes = 300;  // runs cut at kMostRun
  rope.bending = 5.0;
  rope.bending_damping = 0.02;
  SceneDef scene;
  scene.bodies = { buildCloth("cloth", cloth), buildRope("rope", rope) };
  BodyDef loose;
  loose.name = "loose";
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int i = 0; i < 40; ++i)
    loose.nodes.push_back(NodeDef{ Vec3(unit(random), unit(random), unit(random)), 0.1 });
  for (int i = 0; i + 9 < 40; ++i)
    for (int distance = 1; distance <= 9; ++distance)
      loose.springs.push_back(SpringDef{ i, i + distance, 50.0 + i, 0.1, 0.3 });
  loose.springs.push_back(SpringDef{ 3, 1, 80.0, 0.2, 0.25 });  // again, and reversed
  scene.bodies.push_back(loose);
  const World world = buildWorld(scene);
  const Model& model = world.model();
  NodeArray x = world.state().position;
  NodeArray v = NodeArray::Zero(3, x.cols());
  for (Eigen::Index n = 0; n < x.cols(); ++n)
  {
    x.col(n) += 0.01 * Vec3(unit(random), unit(random), unit(random));
    v.col(n) = Vec3(unit(random), unit(random), unit(random));
  }
  x.col(model.nodeCount() - 40 + 12) = x.col(model.nodeCount() - 40 + 13);  // a spring of coincident ends
  const int cloth_first = 0;
  x.col(cloth_first + 5) = x.col(cloth_first + 6);  // one in a run
  NodeArray expected = NodeArray::Zero(3, x.cols());
  NodeArray magnitude = NodeArray::Zero(3, x.cols());
  for (const Spring& s : model.springs)
  {
    Vec3 u;
    double length;
    if (!springAxis(x, s.a, s.b, u, length))
      continue;
    const Vec3 f = -springTension(s, u, length, v) * u;
    expected.col(s.a) += f;
    expected.col(s.b) -= f;
    magnitude.col(s.a) += f.cwiseAbs();
    magnitude.col(s.b) += f.cwiseAbs();
  }
  const SpringArrays springs = springArrays(model);
  ASSERT_EQ(springs.size(), model.springs.size());
  EXPECT_GT(springs.run_springs, model.springs.size() * 9 / 10) << "the cloth's and the rope's springs in runs";
  std::vector<NodeArray> lanes;
  for (const bool wide : { true, false })
  {
    useWideLanes(wide);
    NodeArray force = NodeArray::Zero(3, x.cols());
    accumulateSpringForces(springs, x, v, force);
    for (Eigen::Index n = 0; n < x.cols(); ++n)
      for (int c = 0; c < 3; ++c)
        ASSERT_NEAR(force(c, n), expected(c, n), 1e-13 * magnitude(c, n) + 1e-300)
            << "node " << n << ", coordinate " << c << (wide ? ", four lanes" : ", two lanes");
    lanes.push_back(force);
  }
  useWideLanes(true);
  EXPECT_EQ(std::memcmp(lanes[0].data(), lanes[1].data(), sizeof(double) * static_cast<std::size_t>(lanes[0].size())), 0)
      << "the four lanes and the two give other bits";
}

TEST(IntegratorNames, RoundTripAndRejectUnknown)
{
  ASSERT_EQ(integratorNames().size(), kAllIntegrators.size());
  for (IntegratorType integrator : kAllIntegrators)
  {
    IntegratorType parsed{};
    ASSERT_TRUE(integratorFromName(integratorName(integrator), parsed));
    EXPECT_EQ(parsed, integrator);
  }
  IntegratorType unused{};
  EXPECT_FALSE(integratorFromName("euler", unused));
}

}  // namespace
}  // namespace soft_body_sim::test
