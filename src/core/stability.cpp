#include "soft_body_sim/core/stability.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "soft_body_sim/core/elements/forces.h"

namespace soft_body_sim
{
namespace
{
/// What an explicit scheme does past each limit (see stabilityWarnings).
struct ExplicitLimits
{
  const char* damping_effect;  ///< what a pure dashpot does past h beta = 1
  double omega_h;             ///< omega h above which an undamped oscillator diverges
};

bool explicitLimits(IntegratorType type, ExplicitLimits& limits)
{
  switch (type)
  {
    case IntegratorType::ExplicitEuler:
    case IntegratorType::SemiImplicitEuler:
      limits = { "its dashpot update v <- (1 - h beta) v reverses velocities above 1 and diverges above 2", 2.0 };
      return true;
    case IntegratorType::Verlet:
      limits = { "its Adams-Bashforth-2 velocity estimate diverges above 1", 2.0 };
      return true;
    case IntegratorType::VelocityVerlet:
      limits = { "it no longer resolves the damping and diverges above 2", 2.0 };
      return true;
    case IntegratorType::Rk4:
      limits = { "it no longer resolves the damping and diverges above 2.79", 2.0 * std::sqrt(2.0) };
      return true;
    case IntegratorType::ImplicitEuler:
    case IntegratorType::Xpbd:
      break;
  }
  return false;
}

std::string format(double value)
{
  std::ostringstream out;
  out.precision(3);
  out << value;
  return out.str();
}
}  // namespace

RateBounds rateBounds(const Model& model, const State& state)
{
  const int n = model.nodeCount();
  Eigen::VectorXd damping = Eigen::VectorXd::Zero(n);
  Eigen::VectorXd stiffness = Eigen::VectorXd::Zero(n);
  RateBounds bounds;
  for (const Spring& s : model.springs)
  {
    const double w = model.inverse_mass[s.a] + model.inverse_mass[s.b];
    bounds.damping_lower = std::max(bounds.damping_lower, s.damping * w);
    bounds.omega2_lower = std::max(bounds.omega2_lower, s.stiffness * w);
    for (const int node : { s.a, s.b })
    {
      damping[node] += s.damping * w;
      stiffness[node] += s.stiffness * w;
    }
  }
  Vec3 g[4];
  for (const PressureCell& cell : model.cells)
  {
    double w = 0.0;
    const double s = cellGas(cell, cellArea(cell, state.position, g)).stiffness;
    for (int k = 0; k < 4; ++k)
      w += model.inverse_mass[cell.nodes[k]] * g[k].squaredNorm();
    bounds.omega2_lower = std::max(bounds.omega2_lower, s * w);
    for (const int node : cell.nodes)
      stiffness[node] += s * w;
  }
  for (int i = 0; i < n; ++i)
  {
    if (!model.isFree(i))
      continue;
    bounds.damping_upper = std::max(bounds.damping_upper, damping[i]);
    bounds.omega2_upper = std::max(bounds.omega2_upper, stiffness[i]);
  }
  bounds.damping_lower += model.drag;
  bounds.damping_upper += model.drag;
  return bounds;
}

StepSettings chooseStableStep(const Model& model, const State& state, IntegratorType type, int iterations)
{
  ExplicitLimits limits{};
  const bool is_explicit = explicitLimits(type, limits);
  const RateBounds bounds = rateBounds(model, state);
  double h = std::numeric_limits<double>::infinity();
  if (bounds.omega2_upper > 0.0)
    h = std::min(h, kAutoStepSafety * (is_explicit ? limits.omega_h : 2.0) / std::sqrt(bounds.omega2_upper));
  if (is_explicit && bounds.damping_upper > 0.0)
    h = std::min(h, kAutoStepSafety / bounds.damping_upper);
  if (type == IntegratorType::ExplicitEuler)
  {
    for (const Spring& spring : model.springs)
    {
      const double w = model.inverse_mass[spring.a] + model.inverse_mass[spring.b];
      if (w == 0.0)
        continue;
      const double beta = spring.damping * w + model.drag;
      if (!(beta > 0.0))
        throw std::invalid_argument("physics.dt: auto: explicit_euler has no stable step for an undamped spring "
                                    "(its energy grows by 1 + (omega h)^2 per step at any h); add damping or drag, "
                                    "or choose another integrator");
      h = std::min(h, kAutoStepSafety * beta / (spring.stiffness * w));
    }
  }
  if (!std::isfinite(h))
    h = kAutoStepUnlimited;
  StepSettings settings;
  settings.dt = h;
  settings.substeps = 1;
  settings.iterations = iterations;
  return settings;
}

std::vector<std::string> stabilityWarnings(const Model& model, const State& state, IntegratorType type,
                                           const StepSettings& settings)
{
  ExplicitLimits limits{};
  if (!explicitLimits(type, limits))
    return {};
  const double h = settings.dt / settings.substeps;
  const RateBounds bounds = rateBounds(model, state);
  const std::string name = integratorName(type);
  const std::string step = " (h = dt / substeps = " + format(h) + " s)";
  const std::string remedy = "; use implicit_euler or xpbd, a smaller dt or more substeps";
  std::vector<std::string> warnings;
  if (bounds.damping_upper * h >= 1.0)
    warnings.push_back(name + ": damping too strong for the step: h beta_max >= 1, the jelly seed's c h / m >= 1" +
                       step + ", with h beta_max between " + format(bounds.damping_lower * h) +
                       " (h (drag + c (1/m_a + 1/m_b)) of the strongest dashpot) and " +
                       format(bounds.damping_upper * h) +
                       " (h (drag + max over nodes of sum c (1/m_a + 1/m_b))); " + limits.damping_effect + remedy);
  if (std::sqrt(bounds.omega2_upper) * h >= limits.omega_h)
    warnings.push_back(name + ": springs too stiff for the step: omega_max h >= " + format(limits.omega_h) +
                       ", beyond which undamped oscillations diverge" + step + ", with omega_max h between " +
                       format(std::sqrt(bounds.omega2_lower) * h) + " (h sqrt(k (1/m_a + 1/m_b)) of the stiffest spring) and " +
                       format(std::sqrt(bounds.omega2_upper) * h) +
                       " (h sqrt(max over nodes of sum k (1/m_a + 1/m_b)), cell pressure included)" + remedy);
  if (type == IntegratorType::ExplicitEuler)
  {
    // A mode of rate omega and damping rate beta is amplified by |1 + h lambda|^2 = 1 - h beta + (h omega)^2
    // per step: it grows unless h omega^2 < beta. Each spring's own mode (exact for one spring with a
    // pinned end: omega^2 = k w, beta = c w + drag, w = 1/m_a + 1/m_b) is checked.
    double worst = 0.0;
    for (const Spring& spring : model.springs)
    {
      const double w = model.inverse_mass[spring.a] + model.inverse_mass[spring.b];
      if (w == 0.0)
        continue;
      const double beta = spring.damping * w + model.drag;
      worst = std::max(worst, beta > 0.0 ? h * spring.stiffness * w / beta : std::numeric_limits<double>::infinity());
    }
    if (worst >= 1.0)
      warnings.push_back(name + ": under-damped springs gain energy at any step: a spring's mode grows unless h omega^2 " +
                         "< beta (its damping rate c (1/m_a + 1/m_b) + drag), and the least damped spring has h omega^2 / " +
                         "beta = " + format(worst) + step + remedy);
  }
  return warnings;
}

}  // namespace soft_body_sim
