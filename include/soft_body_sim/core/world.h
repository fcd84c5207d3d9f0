// A running simulation: model + state + the chosen integrator, advanced in fixed steps.
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "soft_body_sim/core/holding/anchors.h"
#include "soft_body_sim/core/contact/contact_stage.h"
#include "soft_body_sim/core/bodies/controller.h"
#include "soft_body_sim/core/holding/grasps.h"
#include "soft_body_sim/core/guard.h"
#include "soft_body_sim/core/integrators/integrator.h"
#include "soft_body_sim/core/integrators/integrator_groups.h"
#include "soft_body_sim/core/material_scaling.h"
#include "soft_body_sim/core/model.h"
#include "soft_body_sim/core/holding/reactions.h"
#include "soft_body_sim/core/contact/self_contacts.h"
#include "soft_body_sim/core/state_archive.h"

namespace soft_body_sim
{
/// A body's controller, made by buildWorld from the body's ControllerFactory.
struct BodyController
{
  int body = 0;  ///< index into Model::bodies
  std::unique_ptr<Controller> controller;
};

/// Looks at the state between two stages of a step (World::observeIntegration).
using StateObserver = std::function<void(const Model& model, const State& state)>;

class World;

/// A moment of a world (World::snapshot): everything its future depends on, to go back to it
/// (World::restore). It shares nothing with the world it was taken from but the paths (see the copy).
class WorldSnapshot
{
public:
  /// [s] the world's simulated time then.
  double time() const;
  std::int64_t stepCount() const;

  /// The snapshot as bytes, to keep in a file or send to another process: a header (the format and its
  /// version, a fingerprint of the scene and its bodies in words, the time and step count, a checksum of
  /// the rest) and then every value a clone copies but the paths, which are functions (docs/physics.md,
  /// "Snapshots and clones"). Only a build of the same format version on a machine of the same byte order
  /// reads them.
  std::string toBytes() const;
  /// A snapshot of bytes from toBytes, to restore into a world of the same scene. Throws
  /// std::invalid_argument, saying which, for bytes that are no snapshot, of another format version or
  /// byte order, damaged (the checksum) or cut short.
  static WorldSnapshot fromBytes(std::string bytes);

private:
  friend class World;
  explicit WorldSnapshot(std::shared_ptr<World> world) : world_(std::move(world)) {}
  WorldSnapshot() = default;

  std::shared_ptr<World> world_;  ///< never changed while shared (copies of a snapshot share it); or null:
  std::shared_ptr<const std::string> bytes_;  ///< a snapshot read from bytes: all of them
  std::size_t body_ = 0;          ///< where in bytes_ the values begin, after the header
  std::uint64_t fingerprint_ = 0; ///< the header's (World::fingerprint)
  std::string summary_;           ///< the header's: the scene's bodies in words
  double time_ = 0.0;             ///< [s] the header's
  std::int64_t steps_ = 0;        ///< the header's
};

class World
{
public:
  /// @param model what the scene is; @param initial where it starts (3 x nodeCount arrays)
  World(Model model, State initial, IntegratorType integrator, StepSettings settings,
        std::vector<BodyController> controllers = {});
  /// A clone: everything the future depends on is copied (the state, the time and step count, the anchors'
  /// and grasps' goals and paths, the colliders' poses, goals and paths, the controllers' own state, the
  /// guard's checkpoint and counts, each integrator's carried state, the self-contact lists), so that the
  /// copy, given the same inputs, steps on to the same bits as the original. Paths (functions of time) are
  /// shared: one that keeps state of its own (a ROS frame's glide) is not a pure input. The
  /// integration observer is not copied.
  World(const World& other);
  World(World&&) = default;
  World& operator=(World&&) = default;
  /// As the copy, into this world's buffers (a world of the same scene allocates little); the integration
  /// observer stays.
  World& operator=(const World& other);

  /// This moment, to come back to with restore.
  WorldSnapshot snapshot() const { return WorldSnapshot(std::make_shared<World>(*this)); }
  /// This moment into `into`, in its buffers if no copy of it shares them (a planner's snapshot taken again
  /// each cycle allocates little).
  void snapshot(WorldSnapshot& into) const;
  /// Back to the moment `snapshot` took (of this world or of another of the same scene: the same bodies,
  /// node counts and elements), as copy assignment; a snapshot of bytes keeps this world's paths, for the
  /// scene's anchors, the grasps of the same names and the colliders. Throws std::invalid_argument, naming
  /// both scenes' bodies, for a snapshot of another scene (for bytes: another fingerprint), or saying what
  /// is wrong with bytes that do not read; the world is unchanged then.
  void restore(const WorldSnapshot& snapshot);
  /// Tells scenes apart: a hash of what the scene fixes (the bodies, masses, contact radii and geometry,
  /// the elements as built, the colliders as declared), not of what changes as it runs. Two worlds built
  /// from the same scene file have the same.
  std::uint64_t fingerprint() const;

  /// Advances the simulation by settings().dt [s], as the named stages in world.cpp.
  void step();

  /// Simulated time [s] = number of steps taken * dt (no accumulated round-off); after setStepSettings,
  /// the time of that change + the steps since * the new dt.
  double time() const { return time_origin_ + static_cast<double>(steps_ - steps_origin_) * settings_.dt; }
  std::int64_t stepCount() const { return steps_; }

  /// What the scene is, with its live values: material scaling, gravity, drag and live pinning (attach,
  /// the guard's freeze) are written into it; the scene's own values stay in MaterialScaling.
  const Model& model() const { return model_; }
  const State& state() const { return state_; }
  const StepSettings& settings() const { return settings_; }
  /// The scene's integrator (setIntegrator's); a body the guard switched may use another.
  IntegratorType integrator() const { return integrators_.sceneType(); }
  /// The integrator stepping body `body` (index into model().bodies).
  IntegratorType bodyIntegrator(std::size_t body) const { return integrators_.bodyType(body); }
  const std::vector<BodyController>& controllers() const { return controllers_; }

  /// Calls `observer` after the integration of every sub-step, before contact (empty: none). For
  /// measurements inside the step, such as how deep a node gets behind a plane before contact pushes it
  /// out (the work-precision benchmark).
  void observeIntegration(StateObserver observer) { integration_observer_ = std::move(observer); }

  /// Index of the anchor `anchor` of body `body` in model().anchors, or nullopt.
  std::optional<int> findAnchor(const std::string& body, const std::string& anchor) const
  {
    return AnchorSet::find(model_, body, anchor);
  }
  /// Moves the anchor's (pinned) node to `position` [m] during the next step, at constant velocity,
  /// so that springs and dashpots feel a smooth motion. The latest call before a step wins.
  void moveAnchor(int anchor, const Vec3& position) { anchors_.setGoal(static_cast<std::size_t>(anchor), position); }
  /// moveAnchor, and an anchor holding a rod (a scene's anchor on a rod) also turns it there to
  /// `orientation` (identity: as built; AnchorSet::setGoal), at constant angular velocity the shorter way round: to turn an end further than
  /// half a turn, turn it over several steps (the rod counts the whole turns of its twist).
  void moveAnchor(int anchor, const Vec3& position, const Eigen::Quaterniond& orientation)
  {
    anchors_.setGoal(static_cast<std::size_t>(anchor), position, orientation);
  }
  /// Sets the target [m] of body `body` (creature, humanoid); false if it has none or is unknown.
  bool setTarget(const std::string& body, const Vec3& target);
  /// True if body `body` (index into model().bodies) takes a target.
  bool takesTarget(std::size_t body) const;
  /// The point [m] body `body` (index into model().bodies) moves toward now, if it takes a target.
  std::optional<Vec3> target(std::size_t body) const;

  /// The current pose of every placed drawable collider, by kind (spheres, capsules, boxes, cylinders,
  /// meshes), each kind in declaration order.
  std::vector<ColliderPose> colliderPoses() const { return contacts_.poses(); }
  /// Every step, collider `name` moves to path(t) at the step's end time t, at constant linear and angular
  /// velocity over the step (which friction sees); where the path has no pose it holds still. False if there
  /// is none of that name.
  bool followColliderPath(const std::string& name, ColliderPath path) { return contacts_.followPath(name, std::move(path)); }
  /// Collider `name` moves to `pose` during the next step, at constant linear and angular velocity (which
  /// friction sees), and holds still there after it. The latest call before a step wins; a path the collider
  /// follows overrides it. False if there is none of that name.
  bool moveCollider(const std::string& name, const RigidPose& pose) { return contacts_.setGoal(name, pose, settings_.dt); }

  /// Sets a node's position [m] and velocity [m/s] directly.
  void setNode(int node, const Vec3& position, const Vec3& velocity);

  // --- live tuning: each takes effect at the next step; positions and velocities do not jump -------
  /// New dt [s] (> 0), substeps and iterations (>= 1); simulated time goes on from time(). Throws
  /// std::invalid_argument on a bad value and keeps the old settings.
  void setStepSettings(const StepSettings& settings);
  /// Switches the integrator of every body; the new one starts from the current positions and velocities.
  /// Throws std::invalid_argument (and keeps the old one) if `type` does not run every element kind of the
  /// scene (a rod or a soft solid runs only under implicit_euler: requireIntegratorRunsModel).
  void setIntegrator(IntegratorType type);
  /// [m/s^2], finite; throws std::invalid_argument otherwise.
  void setGravity(const Vec3& gravity);
  /// Linear air drag [1/s], finite and >= 0; throws std::invalid_argument otherwise.
  void setDrag(double drag);
  /// Scales body `body`'s elements (every kind's, MaterialScaling) from the values it was built with; false if
  /// there is no such body. Throws std::invalid_argument if a factor is out of range (see BodyScaling).
  bool setBodyScaling(const std::string& body, const BodyScaling& scaling);
  /// The scaling last set for `body` (all 1 if never set or unknown).
  BodyScaling bodyScaling(const std::string& body) const;
  /// True if body `body` (index into model().bodies) has a material to scale: elements of any kind (a
  /// humanoid, all kinematic nodes, has none).
  bool hasMaterial(std::size_t body) const { return material_.has(body); }

  // --- anchors that follow a path, and grasping -----------------------------------------------------
  /// Every step, the anchor moves (as by moveAnchor) to path(t) at the step's end time t; an empty path
  /// stops following. A moveAnchor call before a step overrides the path for that step only.
  void followPath(int anchor, AnchorPath path) { anchors_.followPath(static_cast<std::size_t>(anchor), std::move(path)); }
  /// The free node of `body` (any body if empty) nearest to `point` [m] within `radius` [m], or nullopt.
  std::optional<int> nearestFreeNode(const Vec3& point, const std::string& body, double radius) const;
  /// Grasps free node `node`: pins it as a new anchor `name` of its body and returns the anchor's index
  /// (after the scene's anchors). It holds still until moved or given a path. Throws
  /// std::invalid_argument if the node is out of range or pinned, or its body has an anchor `name`.
  int attach(int node, const std::string& name);
  /// Releases an anchor made by attach: its node is free again and keeps the anchor's last velocity,
  /// as a gripper lets go. Anchors after it move down one index. False for a scene anchor or an index
  /// out of range.
  bool detach(int anchor);
  /// True for an anchor made by attach.
  bool isAttached(int anchor) const { return anchors_.isAttached(anchor); }

  /// Grasps body `body` in frame `frame` at `pose` (GraspSet::grasp: every free node within `radius` [m] of
  /// its origin, held at its offset in the frame; slips above `max_force` [N]). Returns the nodes held;
  /// throws std::invalid_argument as GraspSet::grasp does.
  std::size_t grasp(const std::string& frame, const std::string& body, const RigidPose& pose, double radius,
                    double max_force = std::numeric_limits<double>::infinity());
  /// The grasp of frame `frame` moves to `pose` during the next step (GraspSet::setGoal); false if none.
  bool moveGrasp(const std::string& frame, const RigidPose& pose) { return grasps_.setGoal(frame, pose); }
  /// Every step, the grasp of frame `frame` moves (as by moveGrasp) to path(t) at the step's end time t;
  /// false if there is none.
  bool followGraspPath(const std::string& frame, GraspPath path) { return grasps_.followPath(frame, std::move(path)); }
  /// Lets the grasp of frame `frame` go: its nodes keep their velocities (GraspSet::release); false if none.
  bool release(const std::string& frame);
  const std::vector<GraspedNodes>& grasps() const { return grasps_.grasps(); }
  /// The grasps that slipped since the last call, oldest first, for the caller to log.
  std::vector<GraspSlip> takeGraspSlips() { return std::exchange(slips_, {}); }

  // --- forces on what holds the bodies (reactions.h), worked out when asked ------------------------
  /// The forces inside the bodies in the last sub-step (Integrator::internalForces).
  InternalForces internalForces() const;
  /// Each link's tension [N] in the last sub-step, > 0 stretched: springs, then constraints, in model
  /// order (internalForces().tension).
  Eigen::VectorXd linkTensions() const { return internalForces().tension; }
  /// Per anchor of model().anchors, the wrench its body exerts on it, torque about its node (on a rod,
  /// with the rod's bending and twisting moment there, stationTorque).
  std::vector<Wrench> anchorWrenches() const;
  /// Per grasp of grasps(), the wrench its body exerts on it, torque about its frame's origin (on a rod,
  /// with the rod's moments at the stations the grasp holds, stationTorque).
  std::vector<Wrench> graspWrenches() const;
  /// Per named collider of the scene (planes, spheres, capsules, boxes, cylinders, meshes, each in
  /// declaration order; the robot's colliders among them), the wrench the bodies exerted on it in the last
  /// step: every contact impulse it received in the step's sub-steps (the contact stage's and those the
  /// integrators' solves took into themselves), summed and divided by dt, the torque about its origin (a
  /// plane's `point`), both in the scene frame. A body resting on it presses with its weight. Zero before
  /// the first step; empty without named colliders.
  std::vector<ColliderWrench> colliderWrenches() const { return contacts_.wrenches(); }

  /// Kinetic + potential energy [J] (see forces.h).
  double energy() const;

  // --- the divergence guard (guard.h) ---------------------------------------------------------------
  /// Throws std::invalid_argument if max_speed is not a finite number > 0.
  void setGuard(const GuardSettings& guard) { guard_.setSettings(guard); }
  const GuardSettings& guard() const { return guard_.settings(); }
  /// Catches since the world was made, over all bodies / of body `body` (index into model().bodies).
  std::int64_t divergenceCount() const { return guard_.count(); }
  std::int64_t divergenceCount(std::size_t body) const { return guard_.count(body); }
  /// True once the guard froze body `body`.
  bool isFrozen(std::size_t body) const { return guard_.isFrozen(body); }
  /// The catches since the last call, oldest first, for the caller to log.
  std::vector<DivergenceEvent> takeDivergenceEvents() { return guard_.takeEvents(); }

private:
  friend class WorldSnapshot;  // its bytes are the world's values
  /// Writes or reads every value a copy copies but the paths and the integration observer (state_archive.h).
  void carry(StateArchive& archive);

  // The stages of step(), in their order.
  /// Controllers and anchors set their nodes for this step; true if any kinematic node moves.
  bool driveKinematicNodes(double dt);
  /// Anchors and grasps move by sub-step `substep` (1 to substeps) of h [s].
  void moveHeldNodes(int substep, double h);
  void integrate(double h);
  void resolveContacts(double h);
  /// Links of the bodies with self_collision keep apart.
  void resolveSelfContacts();
  /// Anchors, grasps and path-driven colliders land on their goals.
  void landKinematics();
  /// Grasps whose force exceeds their max_force let go.
  void slipGrasps();
  /// Checks every body, restores and treats the diverged ones, keeps the good state.
  void guardBodies();

  /// Applies the guard's policy to body `body` and says what it did.
  std::string treatDiverged(std::size_t body);
  /// Per node, the internal forces on it (internalPulls).
  NodeArray pulls() const;
  /// The model's parameters or pinning changed: the integrators drop their caches.
  void modelChanged() { integrators_.modelChanged(); }

  Model model_;
  State state_;
  StepSettings settings_;
  std::vector<BodyController> controllers_;
  AnchorSet anchors_;
  GraspSet grasps_;
  std::vector<GraspSlip> slips_;  ///< not yet taken
  IntegratorGroups integrators_;
  ContactStage contacts_;
  SelfContacts self_contacts_;
  MaterialScaling material_;
  DivergenceGuard guard_;
  StateObserver integration_observer_;
  double time_origin_ = 0.0;        ///< [s] simulated time at the last change of dt
  std::int64_t steps_origin_ = 0;   ///< step count then
  std::int64_t steps_ = 0;
};

}  // namespace soft_body_sim
