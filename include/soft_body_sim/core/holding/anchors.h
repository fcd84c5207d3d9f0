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
#include "soft_body_sim/core/state_archive.h"

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
  /// Anchor k also turns to `orientation` (unit; identity = as the scene built it) during the next step, if
  /// it holds a rod station (a scene's anchor on a rod: RodStation): the station's frames turn with it
  /// (RodStation::turn), at constant angular velocity (slerp) over the step's sub-steps. Other anchors hold
  /// no orientation.
  void setGoal(std::size_t k, const Vec3& position, const Eigen::Quaterniond& orientation)
  {
    goals_.at(k) = position;
    turns_.at(k) = orientation.normalized();
  }
  /// Anchor k follows path(t) every step (an empty path stops it); a goal set for a step overrides it.
  void followPath(std::size_t k, AnchorPath path) { paths_.at(k) = std::move(path); }

  /// Stage: the anchors without a goal for the step ending at t [s] take their path's.
  void goalsFromPaths(double t);
  /// Stage: each anchor's node gets the velocity that reaches its goal in dt [s]; one that has arrived
  /// stands still; a turning one notes the orientation it turns from. True if any anchor node moves or
  /// stopped moving, or turns.
  bool setVelocities(const Model& model, State& state, double dt);
  /// Stage, sub-step `substep` (1 to substeps) of h [s]: every anchor node moves by h v; a turning rod end
  /// turns substep / substeps of its way.
  void advance(Model& model, State& state, int substep, int substeps, double h) const;
  /// Stage, at the step's end: anchors land exactly on their goals (the sub-step sums differ from them by
  /// round-off), and the goals are used up.
  void land(Model& model, State& state);

  /// A new anchor was appended to model.anchors (attach).
  void added();
  /// Anchor k was erased from model.anchors (detach): the ones after it move down one index.
  void removed(std::size_t k);
  /// True for an anchor made by attach (after the scene's).
  bool isAttached(int k) const;

  /// Writes or reads the goals and turns (state_archive.h). Paths are functions, not state: read, the
  /// scene's anchors keep this set's paths and the attached ones have none.
  void carry(StateArchive& archive);

private:
  std::vector<std::optional<Vec3>> goals_;  ///< per anchor: where to be at the end of the next step
  std::vector<AnchorPath> paths_;           ///< per anchor: followed every step if set
  /// per anchor: the orientation to turn to by the end of the next step (rod ends only)
  std::vector<std::optional<Eigen::Quaterniond>> turns_;
  std::vector<Eigen::Quaterniond> turned_from_;  ///< per anchor: its orientation when its turn began
  std::size_t scene_anchors_;               ///< anchors [0, scene_anchors_) came with the scene
};

}  // namespace soft_body_sim
