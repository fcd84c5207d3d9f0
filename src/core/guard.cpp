#include "soft_body_sim/core/guard.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <utility>

#include "core/names.h"

namespace soft_body_sim
{
const std::vector<std::string>& guardPolicyNames()
{
  static const std::vector<std::string> names = { "halve_step", "switch_integrator", "freeze" };
  return names;
}

std::string guardPolicyName(GuardPolicy policy) { return guardPolicyNames().at(static_cast<std::size_t>(policy)); }

bool guardPolicyFromName(const std::string& name, GuardPolicy& policy)
{
  return enumFromName(guardPolicyNames(), name, policy);
}

namespace
{
std::atomic<std::int64_t> events_in_process{ 0 };
}  // namespace

std::int64_t divergenceEventsInProcess() { return events_in_process.load(); }

std::string DivergenceEvent::describe() const
{
  char at[32];
  std::snprintf(at, sizeof at, "%.3f", time);
  return "body '" + body + "' diverged at t = " + at + " s (" + reason + "): restored to its last good state, " +
         action;
}

DivergenceGuard::DivergenceGuard(const State& initial, std::size_t bodies)
  : last_good_(initial), frozen_(bodies), body_counts_(bodies)
{
}

void DivergenceGuard::setSettings(const GuardSettings& settings)
{
  if (!(settings.max_speed > 0.0 && std::isfinite(settings.max_speed)))
    throw std::invalid_argument("World: guard max_speed must be a finite number > 0 [m/s]");
  settings_ = settings;
}

std::vector<DivergenceGuard::Catch> DivergenceGuard::restoreDiverged(const Model& model, State& state) const
{
  std::vector<Catch> caught;  // empty, and so no allocation, while nothing diverges
  for (std::size_t b = 0; b < model.bodies.size(); ++b)
  {
    const BodyRange& body = model.bodies[b];
    if (frozen_[b] || looksGood(state, body))
      continue;
    std::string reason = divergence(model, state, body);
    if (reason.empty())
      continue;
    for (int i = body.first; i < body.first + body.count; ++i)
      if (model.isFree(i))
      {
        state.position.col(i) = last_good_.position.col(i);
        state.velocity.col(i) = last_good_.velocity.col(i);
      }
    // A rod's twists (State::twist, one entry per node) go back with its nodes: the whole body's state is
    // the saved one, not its positions with the twists counted at the diverged step.
    if (state.twist.size() > 0)
      state.twist.segment(body.first, body.count) = last_good_.twist.segment(body.first, body.count);
    caught.push_back({ b, std::move(reason) });
  }
  return caught;
}

void DivergenceGuard::record(const Model& model, const Catch& caught, double time, std::string action)
{
  ++count_;
  ++body_counts_[caught.body];
  ++events_in_process;
  events_.push_back({ model.bodies[caught.body].name, time, caught.reason, std::move(action) });
}

void DivergenceGuard::checkpoint(const State& state, std::int64_t step, bool caught)
{
  if (!caught && step % kGuardCheckpointSteps != 0)
    return;
  // Same sizes: a plain copy, no allocation.
  std::copy_n(state.position.data(), state.position.size(), last_good_.position.data());
  std::copy_n(state.velocity.data(), state.velocity.size(), last_good_.velocity.data());
  std::copy_n(state.twist.data(), state.twist.size(), last_good_.twist.data());
}

std::string DivergenceGuard::freeze(Model& model, State& state, std::size_t body)
{
  frozen_[body] = 1;
  const BodyRange& range = model.bodies[body];
  for (int i = range.first; i < range.first + range.count; ++i)
  {
    // Its controller stops too (World::driveKinematicNodes): a controller whose own points run away (as
    // the codeling's compounding antic once did) would otherwise drag the frozen body on to infinity.
    state.velocity.col(i).setZero();
    if (model.isFree(i))
      model.inverse_mass[i] = 0.0;
  }
  return "frozen (its free nodes pinned at rest)";
}

std::vector<DivergenceEvent> DivergenceGuard::takeEvents() { return std::exchange(events_, {}); }

bool DivergenceGuard::looksGood(const State& state, const BodyRange& body) const
{
  // Two vectorised sums over every node, pinned ones too: a sum is finite only if all its terms are,
  // and sum |v_i|^2 <= max_speed^2 bounds every node's speed. A body that fails (a NaN compares false)
  // gets the exact look, node by node, which leaves the pinned nodes (the caller's) out.
  const double x_sum = state.position.middleCols(body.first, body.count).sum();
  const double v2_sum = state.velocity.middleCols(body.first, body.count).squaredNorm();
  return std::isfinite(x_sum) && v2_sum <= settings_.max_speed * settings_.max_speed;
}

std::string DivergenceGuard::divergence(const Model& model, const State& state, const BodyRange& body) const
{
  char text[160];
  const double max_speed2 = settings_.max_speed * settings_.max_speed;
  for (int i = body.first; i < body.first + body.count; ++i)
  {
    if (!model.isFree(i))
      continue;
    if (!state.position.col(i).allFinite() || !state.velocity.col(i).allFinite())
    {
      std::snprintf(text, sizeof text, "node %d is not finite", i - body.first);
      return text;
    }
    const double speed2 = state.velocity.col(i).squaredNorm();
    if (speed2 > max_speed2)
    {
      std::snprintf(text, sizeof text, "node %d moves at %.3g m/s > max_speed %.3g m/s", i - body.first,
                    std::sqrt(speed2), settings_.max_speed);
      return text;
    }
  }
  return {};
}

}  // namespace soft_body_sim
