// Grasps: a gripper of some width closing on a body. Every free node of the body within a radius of a
// frame's origin is held rigidly in that frame, keeping its offset, so that the grasped part moves and
// turns with the gripper; released, the nodes go on with their velocities. A grasp with a force limit
// slips (lets go) at the first step whose force exceeds it.
#pragma once

#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "soft_body_sim/core/contact/contact_stage.h"
#include "soft_body_sim/core/model.h"
#include "soft_body_sim/core/holding/reactions.h"
#include "soft_body_sim/core/state_archive.h"

namespace soft_body_sim
{
/// Where a grasp's frame should be at simulated time t [s]; nullopt leaves it where it is.
using GraspPath = ColliderPath;

/// One grasp: its nodes and their offsets in its frame.
struct GraspedNodes
{
  std::string name;  ///< the frame's name; one grasp per name
  std::size_t body = 0;  ///< index into Model::bodies
  std::vector<int> nodes;    ///< global node indices, pinned while held
  std::vector<Vec3> offsets; ///< each node's position in the frame [m]
  RigidPose pose;            ///< the frame's pose now
  /// On a rod: the first node of each station it holds there (a run of consecutive nodes; RodStation), which
  /// turn with its frame.
  std::vector<int> rod_stations;
  double max_force = std::numeric_limits<double>::infinity();  ///< [N]: above it the grasp slips

  void carry(StateArchive& archive) { archive(name, body, nodes, offsets, pose, rod_stations, max_force); }
};

/// A grasp that let go because its force exceeded its max_force.
struct GraspSlip
{
  double time = 0.0;  ///< [s] simulated, at the end of the step
  std::string grasp;
  std::string body;
  double force = 0.0;      ///< [N] the magnitude that exceeded the limit
  double max_force = 0.0;  ///< [N]
  /// One line for a log: "grasp 'gripper' on body 'rope' slipped at t = 1.25 s: force 12.3 N > max_force 10 N".
  std::string describe() const;

  void carry(StateArchive& archive) { archive(time, grasp, body, force, max_force); }
};

class GraspSet
{
public:
  /// Grasps every free node of body `body` within `radius` [m] of `pose`'s origin: pins them (inverse mass
  /// 0) and keeps their offsets in the frame. On a rod, each run of consecutive nodes it holds becomes a
  /// station (holdRod) that holds the rod's orientation there too. Returns how many nodes it holds. Throws std::invalid_argument if a
  /// grasp `name` exists, the body is unknown, radius is not finite and > 0, max_force is not > 0 (infinity:
  /// no limit), or no free node of the body is in reach.
  std::size_t grasp(Model& model, State& state, const std::string& name, const std::string& body,
                    const RigidPose& pose, double radius, double max_force);
  /// Lets grasp `name` go: its nodes are free again (unless `frozen`: a body the guard froze stays pinned)
  /// and keep their velocities; its rod stations go (releaseRod). False if there is none of that name.
  bool release(Model& model, State& state, const std::string& name, bool frozen);
  /// Grasp `name`'s frame moves to `pose` during the next step; the latest call before a step wins. False if
  /// there is none of that name.
  bool setGoal(const std::string& name, const RigidPose& pose);
  /// Grasp `name`'s frame follows path(t) every step (a tf frame); a goal set for a step overrides it.
  /// False if there is none of that name.
  bool followPath(const std::string& name, GraspPath path);

  /// Stage: the grasps without a goal for the step ending at t [s] take their path's.
  void goalsFromPaths(double t);

  bool empty() const { return grasps_.empty(); }
  const std::vector<GraspedNodes>& grasps() const { return grasps_; }

  /// Stage, per sub-step `substep` (1 to `substeps`) of h [s]: each grasp's frame is at fraction
  /// substep / substeps of its way to its goal (position linear, orientation by slerp: constant linear and
  /// angular velocity), its nodes at their offsets in it, with the velocity that got them there, its rod
  /// stations turned with it. Without a goal the frame holds still.
  void advance(Model& model, State& state, int substep, int substeps, double h) const;
  /// Stage, at the step's end: the frames are at their goals, and the goals are used up.
  void land();

  /// Per grasp, the wrench its body exerts on it (holdingWrench), torque about its frame's origin, with a
  /// rod's moments at its stations (stationTorque); `pull` is internalPulls' (with the rods' forces).
  std::vector<Wrench> wrenches(const Model& model, const State& state, const NodeArray& pull) const;
  /// True if some grasp has a force limit (its wrench is then needed every step).
  bool limited() const;

  /// Writes or reads the grasps and their goals (state_archive.h). Paths are functions, not state: read,
  /// a grasp keeps the path this set's grasp of its name had.
  void carry(StateArchive& archive);

private:
  /// The pose at fraction s in [0, 1] of grasp k's way to its goal.
  RigidPose at(std::size_t k, double s) const;

  std::vector<GraspedNodes> grasps_;
  std::vector<std::optional<RigidPose>> goals_;  ///< per grasp: where its frame is at the next step's end
  std::vector<GraspPath> paths_;                 ///< per grasp: followed every step if set
  /// Index of grasp `name`, or grasps_.size().
  std::size_t find(const std::string& name) const;
};

}  // namespace soft_body_sim
