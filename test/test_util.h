// Helpers shared by the core tests: small scenes built from plain structs, and Eigen comparisons.
#pragma once

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/elements/element_kinds.h"
#include "soft_body_sim/core/bodies/volume.h"
#include "soft_body_sim/core/elements/rods.h"
#include "soft_body_sim/core/scene_def.h"
#include "soft_body_sim/core/world.h"
#include "soft_body_sim/core/stability.h"
#include "soft_body_sim/core/elements/tetrahedra.h"

namespace soft_body_sim::test
{
/// Says that the running test is about the divergence guard, so its catches are expected; any other test
/// that trips the guard fails (test_main.cpp).
void expectGuardEvents();

/// A box volume (buildVolume's VolumeDef) of full extents `size` [m] about `centre`, meshed at `resolution`
/// [m], of Young's modulus E [Pa], Poisson's ratio nu and density rho [kg/m^3]; no friction, no gas.
inline VolumeDef boxVolume(const Vec3& size, double resolution, const Vec3& centre, double youngs_modulus, double nu,
                           double density)
{
  VolumeDef box;
  box.size = size;
  box.resolution = resolution;
  box.position = centre;
  box.youngs_modulus = youngs_modulus;
  box.poisson_ratio = nu;
  box.density = density;
  return box;
}

/// Strain (l - L) / L of every spring of `world`, or of those whose stiffness is `stiffness` (a cloth's spring
/// family).
inline std::vector<double> strains(const World& world, std::optional<double> stiffness = std::nullopt)
{
  std::vector<double> out;
  for (const Spring& s : world.model().springs)
    if (!stiffness || s.stiffness == *stiffness)
      out.push_back((world.state().position.col(s.a) - world.state().position.col(s.b)).norm() / s.rest_length - 1.0);
  return out;
}

/// The largest of `values` (not empty).
inline double maxOf(const std::vector<double>& values) { return *std::max_element(values.begin(), values.end()); }

/// Asserts |a - b|_inf <= tol and prints both sides on failure.
template <typename A, typename B>
::testing::AssertionResult expectNear(const A& a, const B& b, double tol)
{
  const double error = (a - b).cwiseAbs().maxCoeff();
  if (error <= tol)
    return ::testing::AssertionSuccess();
  Eigen::IOFormat format(Eigen::FullPrecision, 0, ", ", "; ", "", "", "[", "]");
  return ::testing::AssertionFailure() << "\n  actual:   " << a.format(format) << "\n  expected: " << b.format(format)
                                       << "\n  max |difference| " << error << " > tolerance " << tol;
}

/// The integrators whose stability limits (stability.h) `scene`'s step keeps, in integratorNames() order:
/// the ones the scene may use (not those that refuse it: a rod runs under implicit_euler only).
inline std::vector<IntegratorType> stableIntegrators(const SceneDef& scene)
{
  std::vector<IntegratorType> stable;
  SceneDef as_built = scene;
  as_built.physics.integrator = IntegratorType::ImplicitEuler;  // the one integrator every scene loads under
  const Model model = buildWorld(as_built).model();
  for (const std::string& name : integratorNames())
  {
    SceneDef with = scene;
    integratorFromName(name, with.physics.integrator);
    try
    {
      requireIntegratorRunsModel(model, with.physics.integrator);
    }
    catch (const std::invalid_argument&)
    {
      continue;
    }
    const World world = buildWorld(with);
    if (stabilityWarnings(world.model(), world.state(), with.physics.integrator, world.settings()).empty())
      stable.push_back(with.physics.integrator);
  }
  return stable;
}

/// Steps until every node is slower than `speed` [m/s]; false if `max_steps` pass first.
inline bool settle(World& world, double speed, long max_steps)
{
  for (long n = 0; n < max_steps; ++n)
  {
    world.step();
    if (world.state().velocity.colwise().norm().maxCoeff() < speed)
      return true;
  }
  return false;
}

inline bool allFinite(const State& state)
{
  return state.position.allFinite() && state.velocity.allFinite();
}

/// A scene with one custom body and no gravity.
inline SceneDef oneBodyScene(IntegratorType integrator, double dt)
{
  SceneDef scene;
  scene.physics.integrator = integrator;
  scene.physics.step.dt = dt;
  scene.physics.gravity = Vec3::Zero();
  BodyDef body;
  body.name = "body";
  scene.bodies.push_back(body);
  return scene;
}

/// The damped harmonic oscillator: node 0 pinned at the origin, node 1 of mass m on a spring of
/// stiffness k, rest length 1 m and dashpot c along x, plus air drag; starts displaced by x0 [m] from rest
/// with velocity v0 [m/s]. Motion stays on the x axis, where the spring force is linear.
struct Oscillator
{
  double mass = 1.0;                     ///< [kg]
  double stiffness = 4.0 * M_PI * M_PI;  ///< [N/m]: w0 = 2 pi rad/s
  double damping = 0.0;                  ///< [N s/m]
  double drag = 0.0;                     ///< [1/s]
  double x0 = 0.1;                       ///< [m]
  double v0 = 0.0;                       ///< [m/s]
  static constexpr double kRest = 1.0;   ///< [m]

  double omega0() const { return std::sqrt(stiffness / mass); }

  World world(IntegratorType integrator, double dt, int substeps = 1) const
  {
    SceneDef scene = oneBodyScene(integrator, dt);
    scene.physics.drag = drag;
    scene.physics.step.substeps = substeps;
    BodyDef& body = scene.bodies[0];
    body.nodes.push_back(NodeDef{ Vec3::Zero(), mass, Vec3::Zero(), true });
    body.nodes.push_back(NodeDef{ Vec3(kRest + x0, 0, 0), mass, Vec3(v0, 0, 0), false });
    body.springs.push_back(SpringDef{ 0, 1, stiffness, damping, kRest });
    return buildWorld(scene);
  }

  /// Displacement from rest [m] of the moving node.
  static double displacement(const World& world) { return world.state().position(0, 1) - kRest; }

  /// Closed-form x(t) of m x'' + b x' + k x = 0 with b = c + m drag (underdamped).
  double exact(double t) const
  {
    const double zeta_omega = (damping + mass * drag) / (2.0 * mass);
    const double omega_d = std::sqrt(omega0() * omega0() - zeta_omega * zeta_omega);
    return std::exp(-zeta_omega * t) *
           (x0 * std::cos(omega_d * t) + (v0 + zeta_omega * x0) / omega_d * std::sin(omega_d * t));
  }
};

/// Whether segment pq passes through triangle abc (its interior or boundary).
inline bool crossesTriangle(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c)
{
  const Vec3 n = (b - a).cross(c - a);
  const double dp = n.dot(p - a), dq = n.dot(q - a);
  if (dp * dq > 0.0 || dp == dq)
    return false;
  const Vec3 x = p + dp / (dp - dq) * (q - p);
  return n.dot((b - a).cross(x - a)) >= 0.0 && n.dot((c - b).cross(x - b)) >= 0.0 && n.dot((a - c).cross(x - c)) >= 0.0;
}

}  // namespace soft_body_sim::test
