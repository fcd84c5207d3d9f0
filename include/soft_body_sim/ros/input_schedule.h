// Inputs (anchor poses, targets) held until the physics step their header stamp falls in.
//
// A replay is exact only if every input reaches the same step as when it was recorded, whenever its
// message happens to arrive. So an input is not applied on arrival: it waits here, ordered by stamp
// (ties in arrival order), and the node applies, before each step, every input stamped before that
// step's end. An input stamped ahead of the simulation waits for its step; one stamped behind it (late,
// e.g. stamped now and a few milliseconds on the network) goes to the next step.
//
// What a ROS user expects of stamps that cannot be meant, as tf2's buffer does with its cache: an input
// stamped more than `max_age` behind the ROS clock is stale (a stopped and resumed publisher, a bag
// played without --clock) and dropped; one more than `max_lead` ahead is a clock mix-up (sim-time
// stamps into a wall-clock node) and dropped rather than held for hours. Memory stays bounded: each
// source (an anchor, a body's target) holds at most `max_held` inputs; beyond that the earliest-stamped
// goes, so under a flood the latest input still wins. Plain data apart from ros::Time: unit-testable
// without a master.
#pragma once

#include <algorithm>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <ros/time.h>

#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
struct ScheduledInput
{
  enum class Kind
  {
    Anchor,  ///< World::moveAnchor(anchor, position)
    Target,  ///< World::setTarget(body, position)
  };
  Kind kind = Kind::Anchor;
  int anchor = 0;          ///< index into Model::anchors (Kind::Anchor)
  std::string body;        ///< body name (Kind::Target)
  Vec3 position = Vec3::Zero();  ///< [m] in the scene frame
  /// Kind::Anchor: the orientation in the scene frame (turns an anchor holding a rod's end); none: it keeps
  /// its orientation.
  std::optional<Eigen::Quaterniond> orientation;
  ros::Time stamp;  ///< when it takes effect (InputSchedule::push: its header's stamp, or now for 0)
};

/// The bounds of InputSchedule (the node's ~max_input_age, ~max_input_lead, ~max_held_inputs).
struct InputLimits
{
  double max_age = 1.0;          ///< [s] an input stamped further behind the ROS clock is dropped, > 0
  double max_lead = 5.0;         ///< [s] an input stamped further ahead of it is dropped, > 0
  std::size_t max_held = 1000;   ///< inputs held per source (anchor or target), >= 1
};

class InputSchedule
{
public:
  enum class Verdict
  {
    Held,         ///< waits for the step its stamp falls in (the next step if it is late)
    Stale,        ///< dropped: stamped more than max_age behind the clock
    TooFarAhead,  ///< dropped: stamped more than max_lead ahead of the clock
  };
  struct Admission
  {
    Verdict verdict = Verdict::Held;
    bool evicted = false;  ///< held, but its source was full: its earliest-stamped input was dropped
    double offset = 0.0;   ///< [s] stamp minus clock (negative: behind)
  };

  explicit InputSchedule(const InputLimits& limits = InputLimits()) : limits_(limits) {}

  void setLimits(const InputLimits& limits) { limits_ = limits; }
  const InputLimits& limits() const { return limits_; }

  /// Admits `input` stamped `stamp` when the ROS clock reads `now`. Stamp 0 means now. A zero clock (
  /// /use_sim_time before the first /clock message) cannot date a stamp: the input is held by its
  /// stamp unjudged, so a replay may start its inputs and its clock in either order.
  Admission push(const ros::Time& now, const ros::Time& stamp, const ScheduledInput& input)
  {
    Admission admission;
    const ros::Time when = stamp.isZero() ? now : stamp;
    if (!now.isZero())
    {
      // In nanoseconds: ros::Time's difference throws beyond 68 years, and a stamp may be anything.
      admission.offset = 1e-9 * static_cast<double>(static_cast<std::int64_t>(when.toNSec()) -
                                                    static_cast<std::int64_t>(now.toNSec()));
      if (admission.offset < -limits_.max_age)
      {
        admission.verdict = Verdict::Stale;
        return admission;
      }
      if (admission.offset > limits_.max_lead)
      {
        admission.verdict = Verdict::TooFarAhead;
        return admission;
      }
    }
    Held& held = sources_[sourceOf(input)];
    const auto placed = held.emplace(when, Entry{ next_arrival_++, input });
    placed->second.input.stamp = when;
    if (held.size() > std::max<std::size_t>(1, limits_.max_held))
    {
      held.erase(held.begin());  // the earliest stamp, of equal stamps the first to arrive
      admission.evicted = true;
    }
    return admission;
  }

  /// Removes and returns, in stamp order (ties in arrival order), every input stamped before `step_end`.
  std::vector<ScheduledInput> due(const ros::Time& step_end)
  {
    std::vector<std::tuple<ros::Time, std::uint64_t, const ScheduledInput*>> order;
    for (const auto& [source, held] : sources_)
      for (auto it = held.begin(); it != held.end() && it->first < step_end; ++it)
        order.emplace_back(it->first, it->second.arrival, &it->second.input);
    std::sort(order.begin(), order.end(), [](const auto& a, const auto& b) {
      return std::tie(std::get<0>(a), std::get<1>(a)) < std::tie(std::get<0>(b), std::get<1>(b));
    });
    std::vector<ScheduledInput> out;
    out.reserve(order.size());
    for (const auto& entry : order)
      out.push_back(*std::get<2>(entry));
    for (auto& [source, held] : sources_)
      held.erase(held.begin(), held.lower_bound(step_end));
    return out;
  }

  void clear() { sources_.clear(); }

  /// Inputs held, over all sources.
  std::size_t size() const
  {
    std::size_t n = 0;
    for (const auto& [source, held] : sources_)
      n += held.size();
    return n;
  }

private:
  /// (anchor index, body name): an anchor's inputs, or a body's targets.
  using Source = std::pair<int, std::string>;
  struct Entry
  {
    std::uint64_t arrival;  ///< orders equal stamps of different sources
    ScheduledInput input;
  };
  using Held = std::multimap<ros::Time, Entry>;  ///< equal stamps keep their arrival order

  static Source sourceOf(const ScheduledInput& input)
  {
    return input.kind == ScheduledInput::Kind::Anchor ? Source(input.anchor, std::string()) : Source(-1, input.body);
  }

  InputLimits limits_;
  std::map<Source, Held> sources_;
  std::uint64_t next_arrival_ = 0;
};

}  // namespace soft_body_sim
