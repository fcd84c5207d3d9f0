// What sim.rollouts and World.pose name a holder by: "body/anchor" for an anchor, else the frame of a grasp.
#pragma once

#include <optional>
#include <string>

#include "soft_body_sim/core/world.h"

namespace soft_body_sim::python
{
/// An anchor or a grasp's frame that a caller moves.
class Holder
{
public:
  /// The grasp of frame `name` if there is one, else the anchor "body/anchor"; throws UnknownName naming
  /// the anchors and grasps.
  static Holder find(const World& world, const std::string& name);

  /// Where it is now: an anchor's node, turned as its rod station is (identity off a rod: it holds no
  /// orientation); a grasp's frame.
  RigidPose pose(const World& world) const;
  /// Sends it to `position` [m] during the next step (an anchor: moveAnchor; a grasp keeps `pose`'s
  /// orientation), or with `turn` to the whole pose (an anchor: moveAnchor with its orientation, which only
  /// a rod's anchor holds). A grasp that slipped meanwhile is gone and takes no goal.
  void move(World& world, const RigidPose& pose, bool turn) const;

private:
  std::optional<int> anchor_;  ///< index into model().anchors, or none for a grasp
  std::string grasp_;          ///< its frame
};

}  // namespace soft_body_sim::python
