// The divergence guard: after every step the world checks each body cheaply for a state no stable
// scheme produces (a non-finite value, or a free node faster than max_speed), puts that body's free
// nodes back where the last saved good state had them, and applies a policy so that it does not happen
// again.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "soft_body_sim/core/model.h"
#include "soft_body_sim/core/state_archive.h"

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

  void carry(StateArchive& archive) { archive(policy, max_speed); }
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

  void carry(StateArchive& archive) { archive(body, time, reason, action); }
};

/// The guard's memory: the last good state, which bodies it froze, what it caught. The world runs it as
/// the last stage of a step (World::guardBodies) and applies the policy to each body it caught.
class DivergenceGuard
{
public:
  DivergenceGuard(const State& initial, std::size_t bodies);

  /// Throws std::invalid_argument if max_speed is not a finite number > 0.
  void setSettings(const GuardSettings& settings);
  const GuardSettings& settings() const { return settings_; }

  /// A body caught diverging, and why.
  struct Catch
  {
    std::size_t body;
    std::string reason;
  };
  /// Stage: every body that is not frozen and has a non-finite or too fast free node gets its free nodes
  /// back from the last good state (pinned ones belong to the anchors and controllers, which moved them
  /// on purpose). Returns those bodies, for the world to treat by the policy and then record().
  std::vector<Catch> restoreDiverged(const Model& model, State& state) const;
  /// Counts a catch and keeps its event for takeEvents().
  void record(const Model& model, const Catch& caught, double time, std::string action);
  /// Saves `state` as the last good one after a catch and every kGuardCheckpointSteps steps.
  void checkpoint(const State& state, std::int64_t step, bool caught);

  /// Pins body `body`'s free nodes at rest and stops its controller (World::driveKinematicNodes asks
  /// isFrozen). Returns what it did, for the event.
  std::string freeze(Model& model, State& state, std::size_t body);
  bool isFrozen(std::size_t body) const { return frozen_.at(body) != 0; }

  std::int64_t count() const { return count_; }
  std::int64_t count(std::size_t body) const { return body_counts_.at(body); }
  /// The catches since the last call, oldest first.
  std::vector<DivergenceEvent> takeEvents();

  /// Writes or reads all of it (state_archive.h).
  void carry(StateArchive& archive) { archive(settings_, last_good_, frozen_, body_counts_, count_, events_); }

private:
  /// True if body `body` is certainly fine (false says: look closer).
  bool looksGood(const State& state, const BodyRange& body) const;
  /// Why the body counts as diverged now, or empty.
  std::string divergence(const Model& model, const State& state, const BodyRange& body) const;

  GuardSettings settings_;
  State last_good_;                        ///< saved every kGuardCheckpointSteps steps and after a catch
  std::vector<std::uint8_t> frozen_;       ///< per body
  std::vector<std::int64_t> body_counts_;  ///< per body
  std::int64_t count_ = 0;
  std::vector<DivergenceEvent> events_;    ///< not yet taken
};

/// Catches by every World of this process so far (thread-safe). The test harness (test/test_main.cpp)
/// fails every test that caught one without saying it is about the guard, so that the guard, a safety net
/// for users, can never turn a bug into a log line that no test reads.
std::int64_t divergenceEventsInProcess();

}  // namespace soft_body_sim
