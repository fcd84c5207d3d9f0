// The energy a World reports, for every element kind, against truth that does not come from our code:
//  1. a tetrahedron stretched by a known deformation gradient F: V0 Psi(F) of the stable neo-Hookean
//     material in closed form (Smith, de Goes and Kim 2018, without their log term), with and without gas;
//  2. a bar hanging from its top under its own weight (Poisson's ratio 0): its elastic energy
//     A (rho g)^2 L^3 / (6 E), from the strain rho g (L - s) / E at depth s;
//  3. bookkeeping: the force each integrator applies is minus the gradient of the energy the world
//     reports (a conservative force is), for springs, distance constraints, gas cells, rods and tetrahedra,
//     and in a damping-free run implicit Euler's energy never rises and what it loses shrinks in
//     proportion to the step (a first-order scheme's numerical dissipation), which it could not if an
//     element's energy were left out of the account.
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "soft_body_sim/core/bodies/jelly.h"
#include "soft_body_sim/core/bodies/rod.h"
#include "soft_body_sim/core/bodies/rope.h"
#include "test_util.h"

namespace soft_body_sim
{
namespace
{
using test::boxVolume;

/// A scene of the given bodies, no gravity unless asked, at step dt.
SceneDef sceneOf(std::vector<BodyDef> bodies, IntegratorType integrator, double dt, const Vec3& gravity = Vec3::Zero())
{
  SceneDef scene;
  scene.physics.integrator = integrator;
  scene.physics.step.dt = dt;
  scene.physics.gravity = gravity;
  scene.bodies = std::move(bodies);
  return scene;
}

/// One tetrahedron on the corners of the cube [0, a]^3 at the origin, its nodes moved to F X.
BodyDef stretchedTetrahedron(double a, const Eigen::Matrix3d& F, double youngs_modulus, double nu, double pressure)
{
  BodyDef body;
  body.name = "tet";
  const Vec3 rest[4] = { Vec3::Zero(), Vec3(a, 0, 0), Vec3(0, a, 0), Vec3(0, 0, a) };
  NodeArray x(3, 4);
  for (int k = 0; k < 4; ++k)
  {
    x.col(k) = rest[k];
    body.nodes.push_back(NodeDef{ F * rest[k], 1.0, Vec3::Zero(), false });
  }
  Tetrahedron tet = makeTetrahedron({ 0, 1, 2, 3 }, x, lameParameters(youngs_modulus, nu));
  tet.pressure = pressure;
  body.tetrahedra.push_back(tet);
  return body;
}

/// V0 Psi(F) written out from the material's definition (tetrahedra.h), E and nu to mu and lambda by the
/// textbook relations: mu = E / (2 (1 + nu)), lambda = E nu / ((1 + nu)(1 - 2 nu)).
double closedFormTetEnergy(double a, const Eigen::Matrix3d& F, double youngs_modulus, double nu, double pressure)
{
  const double mu = youngs_modulus / (2.0 * (1.0 + nu));
  const double lambda = youngs_modulus * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  const double J = F.determinant();
  const double psi = 0.5 * mu * (F.squaredNorm() - 3.0) - mu * (J - 1.0) + 0.5 * (lambda + mu) * (J - 1.0) * (J - 1.0) +
                     pressure * (J - 1.0 - std::log(J));
  return a * a * a / 6.0 * psi;
}

TEST(Energy, ATetrahedronStretchedByAKnownDeformationHoldsItsClosedFormEnergy)
{
  const double a = 0.1, E = 2.0e5, nu = 0.35;
  Eigen::Matrix3d F;
  F << 1.2, 0.1, 0.0,  //
      0.05, 0.9, 0.02,  //
      0.0, -0.03, 1.1;
  for (const double pressure : { 0.0, 3.0e4 })
  {
    const World world = buildWorld(sceneOf({ stretchedTetrahedron(a, F, E, nu, pressure) }, IntegratorType::ImplicitEuler, 0.01));
    const double expected = closedFormTetEnergy(a, F, E, nu, pressure);
    ASSERT_GT(expected, 0.0);
    EXPECT_NEAR(world.energy(), expected, 1e-12 * expected) << "pressure " << pressure;
  }
}

TEST(Energy, ABarHangingFromItsTopStoresItsClosedFormElasticEnergy)
{
  // A 4 x 4 x 40 cm bar, its top face pinned, Poisson's ratio 0 so that each slice stretches alone by
  // the weight below it: strain rho g (L - s) / E, energy A E/2 int_0^L strain^2 ds = A (rho g)^2 L^3 / (6 E).
  const double side = 0.04, length = 0.4, rho = 1000.0, E = 1.0e6, g = 9.81;
  VolumeDef bar = boxVolume(Vec3(side, side, length), 0.02, Vec3(0, 0, 1.0), E, 0.0, rho);
  bar.pinned_faces = { "z_max" };
  World world = buildWorld(sceneOf({ buildVolume("bar", bar) }, IntegratorType::ImplicitEuler, 0.01, Vec3(0, 0, -g)));
  ASSERT_TRUE(test::settle(world, 1e-7, 20000));
  const Model& model = world.model();
  const State& state = world.state();
  double gravitational = 0.0;
  for (int i = 0; i < model.nodeCount(); ++i)
    if (model.isFree(i))
      gravitational -= model.mass[i] * model.gravity.dot(state.position.col(i));
  const double kinetic = 0.5 * (state.velocity.colwise().squaredNorm().transpose().array() * model.mass.array()).sum();
  const double elastic = world.energy() - kinetic - gravitational;
  const double expected = side * side * std::pow(rho * g, 2) * std::pow(length, 3) / (6.0 * E);
  // Linear tetrahedra take the displacement, quadratic along the bar, as piecewise linear: the energy of
  // the discrete solution lies below the exact one by about (resolution / L)^2 / 4 (0.06 % at 20 layers);
  // the material departs from linear elasticity by the order of the strain, 5 per mille at the top and
  // less below. (Measured: 0.03 % low.)
  EXPECT_NEAR(elastic, expected, 0.005 * expected);
}

/// Every element kind in one scene: a rope of springs, a jelly (springs and gas cells), a rod (springs,
/// bending, twisting), a soft block (tetrahedra with gas); no damping, no gravity.
std::vector<BodyDef> everyKind()
{
  RopeDef rope;
  rope.nodes = 6;
  rope.from = Vec3(0, 0, 0);
  rope.to = Vec3(0.5, 0, 0);
  rope.bending = 50.0;
  JellyDef jelly;
  jelly.nx = jelly.ny = 2;
  jelly.corners = GridCorners{ Vec3(0, 1, 0.4), Vec3(0.4, 1, 0.4), Vec3(0, 1, 0) };
  jelly.edges.damping = jelly.diagonals.damping = 0.0;
  RodDef rod;
  rod.nodes = 7;
  rod.from = Vec3(0, 2, 0);
  rod.to = Vec3(0.6, 2, 0);
  rod.radius = 0.01;
  rod.youngs_modulus = 1.0e7;
  VolumeDef block = boxVolume(Vec3(0.1, 0.1, 0.1), 0.05, Vec3(0, 3, 0), 5.0e4, 0.3, 100.0);
  block.pressure = 1.0e4;
  return { buildRope("rope", rope), buildJelly("jelly", jelly), buildRod("rod", rod), buildVolume("block", block) };
}

/// The world of `scene` with every node moved off its rest shape, at rest, by a smooth, deterministic field
/// of a few per cent of the bodies' sizes.
World offRest(const SceneDef& scene)
{
  World world = buildWorld(scene);
  for (int i = 0; i < world.model().nodeCount(); ++i)
  {
    const double s = static_cast<double>(i);
    world.setNode(i, world.state().position.col(i) + 0.01 * Vec3(std::sin(1.3 * s), std::cos(0.7 * s), std::sin(0.4 * s + 1.0)),
                  Vec3::Zero());
  }
  return world;
}

/// The force [N] the integrator of `scene` applies to each node off rest (offRest): a step of h takes
/// v = h f / m up to h^2 K / m (implicit Euler) or h^2 w / alpha (XPBD's compliance), far below 1e-6 at the
/// steps below. XPBD moves positions, so its h must keep h^2 f / m well above the positions' round-off.
NodeArray appliedForces(SceneDef scene, double h)
{
  scene.physics.step.dt = h;
  World world = offRest(scene);
  world.step();
  NodeArray force = world.state().velocity / h;
  for (int i = 0; i < world.model().nodeCount(); ++i)
    force.col(i) *= world.model().mass[i];
  return force;
}

/// -dE/dx of the world's reported energy off rest (offRest), by central differences of step delta [m].
NodeArray energyGradientForces(const SceneDef& scene, double delta)
{
  World world = offRest(scene);
  NodeArray force(3, world.model().nodeCount());
  for (int i = 0; i < world.model().nodeCount(); ++i)
  {
    const Vec3 x = world.state().position.col(i);
    for (int c = 0; c < 3; ++c)
    {
      Vec3 moved = x;
      moved[c] = x[c] + delta;
      world.setNode(i, moved, Vec3::Zero());
      const double plus = world.energy();
      moved[c] = x[c] - delta;
      world.setNode(i, moved, Vec3::Zero());
      const double minus = world.energy();
      force(c, i) = -(plus - minus) / (2.0 * delta);
    }
    world.setNode(i, x, Vec3::Zero());
  }
  return force;
}

TEST(Energy, TheForceOfEveryElementKindIsMinusTheGradientOfTheEnergyTheWorldReports)
{
  const SceneDef scene = sceneOf(everyKind(), IntegratorType::ImplicitEuler, 0.01);
  const NodeArray applied = appliedForces(scene, 1e-9);
  // Central differences err by delta^2 / 6 times the third derivative, about (delta / l)^2 of the forces
  // for bodies of size l ~ 0.05 m: 1e-8 at 1e-6 m; the energy's round-off adds eps E / delta, as small.
  // (Measured: 1e-9 of the largest force.)
  const NodeArray gradient = energyGradientForces(scene, 1e-6);
  const double scale = applied.cwiseAbs().maxCoeff();
  ASSERT_GT(scale, 1.0);
  EXPECT_TRUE(test::expectNear(gradient, applied, 1e-6 * scale));
}

TEST(Energy, ACompliantDistanceConstraintStoresHalfItsViolationSquaredOverItsCompliance)
{
  // XPBD's constraint of compliance alpha is a spring of stiffness 1 / alpha (Macklin et al. 2016): stretched
  // by C it stores C^2 / (2 alpha) and pulls with C / alpha.
  BodyDef body;
  body.name = "link";
  body.nodes = { NodeDef{ Vec3(0, 0, 0), 0.5, Vec3::Zero(), false }, NodeDef{ Vec3(0.13, 0.02, 0), 0.3, Vec3::Zero(), false },
                 NodeDef{ Vec3(0.2, 0.1, 0.05), 0.2, Vec3::Zero(), false } };
  const double alpha = 1e-3;
  body.constraints = { ConstraintDef{ 0, 1, alpha, 0.1 }, ConstraintDef{ 1, 2, alpha, 0.1 } };
  const SceneDef scene = sceneOf({ body }, IntegratorType::Xpbd, 0.01);
  const World world = buildWorld(scene);  // as placed: both links stretched or squeezed off their 0.1 m
  double expected = 0.0;
  for (const auto& [a, b] : { std::pair{ 0, 1 }, std::pair{ 1, 2 } })
  {
    const double violation = (body.nodes[a].position - body.nodes[b].position).norm() - 0.1;
    expected += violation * violation / (2.0 * alpha);
  }
  EXPECT_NEAR(world.energy(), expected, 1e-12 * expected);
  const NodeArray applied = appliedForces(scene, 1e-6);
  EXPECT_TRUE(test::expectNear(energyGradientForces(scene, 1e-7), applied, 1e-5 * applied.cwiseAbs().maxCoeff()));
}

/// The energy implicit Euler loses over `duration` [s] of the damping-free scene at step h, checking that
/// it never rises by more than round-off from one step to the next.
double implicitEulerLoss(std::vector<BodyDef> bodies, double h, double duration)
{
  World world = buildWorld(sceneOf(std::move(bodies), IntegratorType::ImplicitEuler, h, Vec3(0, 0, -9.81)));
  const double start = world.energy();
  double previous = start;
  const long steps = std::lround(duration / h);
  for (long n = 0; n < steps; ++n)
  {
    world.step();
    const double now = world.energy();
    EXPECT_LE(now, previous + 1e-9 * std::abs(start)) << "step " << n << " at h = " << h;
    previous = now;
  }
  return start - previous;
}

TEST(Energy, ImplicitEulerLosesEnergyInProportionToItsStepForEveryElementKind)
{
  // Backward Euler damps a mode of angular frequency w by a factor 1 / (1 + (w h)^2) in energy per step:
  // over a fixed time it loses a fraction ~ w^2 h t, first order in h. So halving h halves the loss. An
  // element whose energy the world left out would show its energy as a loss that does not shrink with h
  // (the elastic energy the motion stored), and the ratio would stay near 1.
  // Each kind on its own, falling under gravity from rest with one end (or face) held: the motion is slow
  // against h, so every excited mode is resolved.
  RopeDef rope;
  rope.nodes = 8;
  rope.to = Vec3(0.4, 0, 0);
  rope.stiffness = 200.0;
  rope.pinned = { 0 };
  JellyDef jelly;
  jelly.nx = jelly.ny = 2;
  jelly.edges = { 200.0, 0.0 };
  jelly.diagonals = { 100.0, 0.0 };
  jelly.pressure = 100.0;
  RodDef rod;
  rod.nodes = 9;
  rod.radius = 0.01;
  rod.youngs_modulus = 1.0e6;
  rod.clamped = { 0 };
  VolumeDef block = boxVolume(Vec3(0.3, 0.06, 0.06), 0.03, Vec3(0, 0, 1), 2.0e4, 0.3, 100.0);
  block.pinned_faces = { "x_min" };
  block.pressure = 2.0e3;
  BodyDef hung_jelly = buildJelly("jelly", jelly);
  hung_jelly.nodes[0].pinned = true;
  const std::vector<std::pair<std::string, BodyDef>> kinds{ { "springs", buildRope("rope", rope) },
                                                            { "gas cells", hung_jelly },
                                                            { "rod", buildRod("rod", rod) },
                                                            { "tetrahedra", buildVolume("block", block) } };
  for (const auto& [kind, body] : kinds)
  {
    const double coarse = implicitEulerLoss({ body }, 1.0 / 2000.0, 0.2);
    const double fine = implicitEulerLoss({ body }, 1.0 / 4000.0, 0.2);
    ASSERT_GT(coarse, 0.0) << kind;
    // Halving h: 0.5 up to the next order's share, the loss's own size relative to the energy in motion
    // (a few per cent). (Measured: 0.502 to 0.521.)
    EXPECT_NEAR(fine / coarse, 0.5, 0.05) << kind << ": loss " << coarse << " J at h, " << fine << " J at h / 2";
  }
}

}  // namespace
}  // namespace soft_body_sim
