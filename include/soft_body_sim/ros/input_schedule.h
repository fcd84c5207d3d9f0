// Inputs (anchor poses, targets) held until the physics step their header stamp falls in.
//
// A replay is exact only if every input reaches the same step as when it was recorded, whenever its
// message happens to arrive. So an input is not applied on arrival: it waits here, ordered by stamp
// (ties in arrival order), and the node applies, before each step, every input stamped before that
// step's end. An input stamped ahead of the simulation waits for its step; one stamped behind it (late)
// goes to the next step, as before. Plain data apart from ros::Time: unit-testable without a master.
#pragma once

#include <map>
#include <string>
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
};

class InputSchedule
{
public:
  void push(const ros::Time& stamp, const ScheduledInput& input) { inputs_.emplace(stamp, input); }

  /// Removes and returns, in stamp order, every input stamped before `step_end`.
  std::vector<ScheduledInput> due(const ros::Time& step_end)
  {
    std::vector<ScheduledInput> out;
    const auto end = inputs_.lower_bound(step_end);
    for (auto it = inputs_.begin(); it != end; ++it)
      out.push_back(it->second);
    inputs_.erase(inputs_.begin(), end);
    return out;
  }

  void clear() { inputs_.clear(); }
  std::size_t size() const { return inputs_.size(); }

private:
  std::multimap<ros::Time, ScheduledInput> inputs_;  ///< equal stamps keep their arrival order
};

}  // namespace soft_body_sim
