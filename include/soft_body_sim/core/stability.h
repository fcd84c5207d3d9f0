// Stability limits of the explicit integrators, reported before a run rather than silently clamped.
// The jelly seed's third failure: its dashpot force is c v, and "if the coefficient goes above the
// scaled equivalent of 1", i.e. c h / m >= 1, an explicit update reverses the velocity instead of
// slowing it and the structure explodes. Which value of c that is depends on the masses and the step,
// so the limit is computed from the model, and a scene past it is reported, not changed.
#pragma once

#include <string>
#include <vector>

#include "soft_body_sim/core/integrators/integrator.h"
#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
/// Bounds of the fastest rates of the model linearised about a state, over the free nodes (w = inverse
/// mass). The damping matrix is D = sum_s c_s (e_a - e_b)(e_a - e_b)^T (x) u u^T; its fastest rate is
/// the largest eigenvalue of M^-1/2 D M^-1/2, i.e. the largest y^T M^-1/2 D M^-1/2 y over unit y, where
///   y^T M^-1/2 D M^-1/2 y = sum_s c_s (u . (sqrt(w_a) y_a - sqrt(w_b) y_b))^2.
/// Upper bound: by Cauchy-Schwarz each term is <= c_s (w_a + w_b)(|y_a|^2 + |y_b|^2), so the rate is
/// <= max_i sum_{s at i} c_s (w_a + w_b). Lower bound: y on the two ends of one spring, along it, gives
/// >= c_s (w_a + w_b) for every spring. The same holds for the stiffness matrix, whose spring blocks are
/// at most k_s I (the transverse term k (1 - L/l) is below k), and for a pressure cell's Gauss-Newton
/// block S g g^T (g = dA/dx, S = d^2E/dA^2), which adds S sum_l w_l |g_l|^2. Drag adds exactly `drag`
/// to every damping rate. Both bounds are exact for one spring with a pinned end (c / m, k / m).
struct RateBounds
{
  double damping_lower = 0.0;  ///< [1/s]: drag + max_s c_s (w_a + w_b)
  double damping_upper = 0.0;  ///< beta_max [1/s]: drag + max_i sum_{s at i} c_s (w_a + w_b)
  double omega2_lower = 0.0;   ///< [1/s^2]: max_s k_s (w_a + w_b), or a cell's S sum_l w_l |g_l|^2
  double omega2_upper = 0.0;   ///< omega_max^2 [1/s^2]: max_i (sum_{s at i} k_s (w_a + w_b) + cells' share)
};
RateBounds rateBounds(const Model& model, const State& state);

/// One line per stability limit that the explicit integrator `type` may exceed at the sub-step
/// h = dt / substeps, for the model about `state` (springs need no state; cells use it). A limit is
/// reported when the upper bound of RateBounds reaches it (every scene that may be past it is
/// reported); the line gives both bounds. Empty for implicit_euler and xpbd, stable at any step.
///  - damping: h beta_max >= 1, the jelly seed's threshold c h / m >= 1. A pure dashpot's relative
///    velocity is multiplied per step by 1 - z, z = h beta (both Eulers: it reverses above 1 and
///    diverges above 2), by the Adams-Bashforth-2 factors of verlet's velocity estimate (diverges above
///    1), by 1 - z + z^2/2 (velocity_verlet, diverges above 2) and by the quartic Taylor polynomial of
///    e^-z (rk4, diverges above 2.79). Past 1 none of them resolves the damping in time.
///  - stiffness: omega_max h >= the scheme's limit for an undamped oscillator: 2 (symplectic Euler,
///    both Verlets), 2 sqrt(2) (rk4). Explicit Euler has no such limit: it amplifies every undamped
///    mode by 1 + (omega h)^2 in energy per step at any h (docs/physics.md, "Integrators"); it is
///    reported at 2 as well, where that factor reaches 5.
///  - explicit Euler only: any spring whose mode is under-damped for the step, h omega^2 >= beta
///    (omega^2 = k (1/m_a + 1/m_b), beta = c (1/m_a + 1/m_b) + drag): such a mode grows at any h.
std::vector<std::string> stabilityWarnings(const Model& model, const State& state, IntegratorType type,
                                           const StepSettings& settings);

/// Safety factor of chooseStableStep: the step stays this fraction of the limit it meets first.
constexpr double kAutoStepSafety = 0.9;
/// The step of a scene without springs or cells, where nothing limits it [s].
constexpr double kAutoStepUnlimited = 0.01;

/// The `dt: auto` step for `type`: one sub-step of the largest h that keeps, from RateBounds' upper
/// bounds, omega_max h at kAutoStepSafety times the scheme's limit (2, or 2 sqrt(2) for rk4; 2 also for
/// implicit_euler and xpbd, stable at any step but no longer following the fastest mode past it), and
/// for the explicit schemes h beta_max at kAutoStepSafety; explicit Euler also needs every spring's
/// h omega^2 below its damping rate beta. So stabilityWarnings stays silent at the chosen step, and the
/// step is within 1 / kAutoStepSafety of the bound it meets (exact for one spring with a pinned end).
/// Throws std::invalid_argument for explicit Euler with an undamped spring: no step is stable.
StepSettings chooseStableStep(const Model& model, const State& state, IntegratorType type, int iterations);

}  // namespace soft_body_sim
