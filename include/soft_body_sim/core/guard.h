// The divergence guard: after every step the world checks each body cheaply for a state no stable
// scheme produces (a non-finite value, or a free node faster than max_speed), puts that body's free
// nodes back where the last saved good state had them, and applies a policy so that it does not happen
// again.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace soft_body_sim
{
/// What the guard does to a body it caught diverging, after restoring it.
enum class GuardPolicy
{
  /// Halve the world's sub-step (substeps x 2, every body; dt and the publishing rate stay). Past
  /// kGuardMaxSubsteps the body is frozen instead: a scheme that diverges at any step (explicit Euler
  /// on an undamped spring) is not helped by a smaller one.
  HalveStep,
  /// Step that body with implicit_euler from now on (the others keep theirs): unconditionally stable for
  /// springs, and the one scheme here without a step limit of its own (xpbd's direct chain solve has
  /// one). A body already on implicit_euler is frozen instead.
  SwitchIntegrator,
  /// Pin the body's free nodes where they are, at rest, and stop its controller (if any), so that the
  /// body stands still; its anchors still move their nodes. The rest of the scene goes on.
  Freeze,
};

/// The scene-file name of each policy, e.g. "switch_integrator".
std::string guardPolicyName(GuardPolicy policy);
/// Parses a scene-file name; false if the name is unknown.
bool guardPolicyFromName(const std::string& name, GuardPolicy& policy);
/// Every valid name, in declaration order.
const std::vector<std::string>& guardPolicyNames();

/// Steps between two saves of the last good state (every position and velocity), and after a catch. A
/// save costs about as much as a light integrator pass (a 1000-node rope's semi-implicit Euler step
/// took ~20 % longer with one every step); a caught body goes back at most this many steps.
constexpr int kGuardCheckpointSteps = 8;

/// Sub-steps per step beyond which HalveStep freezes the body instead (ten halvings of a one-sub-step
/// scene).
constexpr int kGuardMaxSubsteps = 1024;

struct GuardSettings
{
  GuardPolicy policy = GuardPolicy::SwitchIntegrator;
  /// [m/s], > 0. A free node faster than this counts as diverged: it bounds each node's kinetic energy
  /// per kilogram by max_speed^2 / 2. The default is far above anything a rope or cloth does (a node
  /// dragged 10 m in one 1 ms sub-step moves at 10^4 m/s) and far below what a diverging scheme reaches
  /// within a few steps (its energy grows geometrically, by (omega h)^2 per step for explicit Euler).
  double max_speed = 1.0e5;
};

/// One catch of the guard, for the caller to report.
struct DivergenceEvent
{
  std::string body;    ///< the body's name
  double time = 0.0;   ///< [s] simulated time at the end of the step that diverged
  std::string reason;  ///< what was found, e.g. "node 3 moves at 2.1e+05 m/s > max_speed 1e+05 m/s"
  std::string action;  ///< what the policy did, e.g. "switched to implicit_euler"

  /// "body 'rope' diverged at t = 1.250 s (REASON): restored to its last good state, ACTION".
  std::string describe() const;
};

/// Catches by every World of this process so far (thread-safe). The test harness (test/test_main.cpp)
/// fails every test that caught one without saying it is about the guard, so that the guard, a safety net
/// for users, can never turn a bug into a log line that no test reads.
std::int64_t divergenceEventsInProcess();
/// Counts one catch in divergenceEventsInProcess (World's guard stage calls it).
void countDivergenceEventInProcess();

}  // namespace soft_body_sim
