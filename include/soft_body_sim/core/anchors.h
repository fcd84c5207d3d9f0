// The anchors: named pinned nodes that the caller moves (a pose topic, a path, a grasp). Each step an
// anchor with a goal moves there at constant velocity, so that springs and dashpots feel a smooth motion,
// and lands on it exactly at the step's end.
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
/// Where an anchor should be at simulated time t [s]; nullopt leaves it where it is.
using AnchorPath = std::function<std::optional<Vec3>(double t)>;

/// The goals and paths of Model::anchors (same indices); anchors after the scene's were made by attach.
class AnchorSet
{
public:
  explicit AnchorSet(std::size_t scene_anchors);

  /// Index of the anchor `anchor` of body `body` in model.anchors, or nullopt.
  static std::optional<int> find(const Model& model, const std::string& body, const std::string& anchor);

  /// Anchor k moves to `position` [m] during the next step; the latest call before a step wins.
  void setGoal(std::size_t k, const Vec3& position) { goals_.at(k) = position; }
  /// Anchor k follows path(t) every step (an empty path stops it); a goal set for a step overrides it.
  void followPath(std::size_t k, AnchorPath path) { paths_.at(k) = std::move(path); }

  /// Stage: the anchors without a goal for the step ending at t [s] take their path's.
  void goalsFromPaths(double t);
  /// Stage: each anchor's node gets the velocity that reaches its goal in dt [s]; one that has arrived
  /// stands still. True if any anchor node moves or stopped moving.
  bool setVelocities(const Model& model, State& state, double dt) const;
  /// Stage, per sub-step of h [s]: every anchor node moves by h v.
  static void advance(const Model& model, State& state, double h);
  /// Stage, at the step's end: anchors land exactly on their goals (the sub-step sums differ from them by
  /// round-off), and the goals are used up.
  void land(const Model& model, State& state);

  /// A new anchor was appended to model.anchors (attach).
  void added();
  /// Anchor k was erased from model.anchors (detach): the ones after it move down one index.
  void removed(std::size_t k);
  /// True for an anchor made by attach (after the scene's).
  bool isAttached(int k) const;

private:
  std::vector<std::optional<Vec3>> goals_;  ///< per anchor: where to be at the end of the next step
  std::vector<AnchorPath> paths_;           ///< per anchor: followed every step if set
  std::size_t scene_anchors_;               ///< anchors [0, scene_anchors_) came with the scene
};

}  // namespace soft_body_sim
