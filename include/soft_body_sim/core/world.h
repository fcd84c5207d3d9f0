// A running simulation: model + state + the chosen integrator, advanced in fixed steps.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "soft_body_sim/core/controller.h"
#include "soft_body_sim/core/guard.h"
#include "soft_body_sim/core/integrator.h"
#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
/// A body's controller, made by buildWorld from the body's ControllerFactory.
struct BodyController
{
  int body = 0;  ///< index into Model::bodies
  std::unique_ptr<Controller> controller;
};

/// Live multipliers of one body's material, relative to the scene's values (the jelly seed's sliders
/// "to make it more springy or viscous"). 1 = as loaded; each > 0.
struct BodyScaling
{
  double stiffness = 1.0;  ///< [-] spring stiffness k, and constraint stiffness 1 / compliance
  double damping = 1.0;    ///< [-] spring dashpots c
  double pressure = 1.0;   ///< [-] rest gas pressure p0 of the body's cells
};

/// Where an anchor should be at simulated time t [s]; nullopt leaves it where it is.
using AnchorPath = std::function<std::optional<Vec3>(double t)>;

class World
{
public:
  /// @param model what the scene is; @param initial where it starts (3 x nodeCount arrays)
  World(Model model, State initial, IntegratorType integrator, StepSettings settings,
        std::vector<BodyController> controllers = {});

  /// Advances the simulation by settings().dt [s]. Stages: controllers drive their nodes; anchors set
  /// their nodes' velocities toward their new poses; then per sub-step of dt / substeps: anchors move,
  /// the integrator(s) step, planes push nodes out; last, the divergence guard checks every body.
  void step();

  /// Simulated time [s] = number of steps taken * dt (no accumulated round-off); after setStepSettings,
  /// the time of that change + the steps since * the new dt.
  double time() const { return time_origin_ + static_cast<double>(steps_ - steps_origin_) * settings_.dt; }
  std::int64_t stepCount() const { return steps_; }

  const Model& model() const { return model_; }
  const State& state() const { return state_; }
  const StepSettings& settings() const { return settings_; }
  /// The scene's integrator (setIntegrator's); a body the guard switched may use another.
  IntegratorType integrator() const { return integrator_type_; }
  /// The integrator stepping body `body` (index into model().bodies).
  IntegratorType bodyIntegrator(std::size_t body) const { return body_integrator_.at(body); }
  const std::vector<BodyController>& controllers() const { return controllers_; }

  /// Index of the anchor `anchor` of body `body` in model().anchors, or nullopt.
  std::optional<int> findAnchor(const std::string& body, const std::string& anchor) const;
  /// Moves the anchor's (pinned) node to `position` [m] during the next step, at constant velocity,
  /// so that springs and dashpots feel a smooth motion. The latest call before a step wins.
  void moveAnchor(int anchor, const Vec3& position);
  /// Sets the target [m] of body `body` (creature, humanoid); false if it has none or is unknown.
  bool setTarget(const std::string& body, const Vec3& target);

  /// Sets a node's position [m] and velocity [m/s] directly.
  void setNode(int node, const Vec3& position, const Vec3& velocity);

  // --- live tuning: each takes effect at the next step; positions and velocities do not jump -------
  /// New dt [s] (> 0), substeps and iterations (>= 1); simulated time goes on from time(). Throws
  /// std::invalid_argument on a bad value and keeps the old settings.
  void setStepSettings(const StepSettings& settings);
  /// Switches the integrator of every body; the new one starts from the current positions and velocities.
  void setIntegrator(IntegratorType type);
  /// [m/s^2], finite; throws std::invalid_argument otherwise.
  void setGravity(const Vec3& gravity);
  /// Linear air drag [1/s], finite and >= 0; throws std::invalid_argument otherwise.
  void setDrag(double drag);
  /// Scales body `body`'s springs, constraints and cells from the values it was built with; false if
  /// there is no such body. Throws std::invalid_argument if a factor is out of range (see BodyScaling).
  bool setBodyScaling(const std::string& body, const BodyScaling& scaling);
  /// The scaling last set for `body` (all 1 if never set or unknown).
  BodyScaling bodyScaling(const std::string& body) const;

  // --- anchors that follow a path, and grasping -----------------------------------------------------
  /// Every step, the anchor moves (as by moveAnchor) to path(t) at the step's end time t; an empty path
  /// stops following. A moveAnchor call before a step overrides the path for that step only.
  void followPath(int anchor, AnchorPath path);
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
  bool isAttached(int anchor) const;

  /// Kinetic + potential energy [J] (see forces.h).
  double energy() const;

  // --- the divergence guard (guard.h) ---------------------------------------------------------------
  /// Throws std::invalid_argument if max_speed is not a finite number > 0.
  void setGuard(const GuardSettings& guard);
  const GuardSettings& guard() const { return guard_; }
  /// Catches since the world was made, over all bodies / of body `body` (index into model().bodies).
  std::int64_t divergenceCount() const { return divergence_count_; }
  std::int64_t divergenceCount(std::size_t body) const { return body_divergences_.at(body); }
  /// True once the guard froze body `body`.
  bool isFrozen(std::size_t body) const { return frozen_.at(body) != 0; }
  /// The catches since the last call, oldest first, for the caller to log.
  std::vector<DivergenceEvent> takeDivergenceEvents();

private:
  /// Controllers and anchors set their nodes for this step; true if any kinematic node moves.
  bool driveKinematicNodes(double dt);
  /// Index into model().bodies of the body holding `node`.
  std::size_t bodyOf(int node) const;
  /// The integrators step one sub-step h: one for the whole model while every body uses the same,
  /// else one per integrator over a copy of the model in which the other bodies' nodes are pinned.
  void stepIntegrators(double h);
  /// The model's parameters or pinning changed: integrators drop their caches, groups are rebuilt.
  void modelChanged();
  void invalidateIntegrators();
  void rebuildGroups();
  /// The guard stage: checks every body, restores and treats the diverged ones, keeps the good state.
  void guardBodies();
  /// The guard's cheap check: true if body `body` is certainly fine (false says: look closer).
  bool looksGood(const BodyRange& body) const;
  /// Why body `body` counts as diverged now, or empty.
  std::string divergence(const BodyRange& body) const;
  /// Applies guard_.policy to body `body` and says what it did.
  std::string treatDiverged(std::size_t body);
  std::string freeze(std::size_t body);

  /// Bodies stepped by one integrator type when bodies differ: the model with every other body's
  /// nodes pinned (their positions and velocities belong to their own group, as an anchor's to us).
  struct IntegratorGroup
  {
    IntegratorType type;
    Model model;
    std::unique_ptr<Integrator> integrator;
  };

  Model model_;
  State state_;
  StepSettings settings_;
  IntegratorType integrator_type_;
  std::unique_ptr<Integrator> integrator_;
  std::vector<BodyController> controllers_;
  std::vector<std::optional<Vec3>> anchor_goals_;  ///< per anchor: where to be at the end of the next step
  std::vector<AnchorPath> anchor_paths_;            ///< per anchor: followed every step if set
  std::size_t scene_anchors_ = 0;                   ///< anchors [0, scene_anchors_) came with the scene
  /// The material as built, which BodyScaling multiplies: per spring k and c, per constraint compliance,
  /// per cell pressure, and the scaling of each body.
  std::vector<Spring> built_springs_;
  std::vector<DistanceConstraint> built_constraints_;
  std::vector<PressureCell> built_cells_;
  std::vector<BodyScaling> body_scaling_;
  double time_origin_ = 0.0;        ///< [s] simulated time at the last change of dt
  std::int64_t steps_origin_ = 0;   ///< step count then
  std::vector<std::uint8_t> touching_;              ///< per node: on a plane after the last sub-step
  std::int64_t steps_ = 0;
  std::vector<IntegratorType> body_integrator_;     ///< per body
  std::vector<IntegratorGroup> groups_;             ///< empty while every body uses integrator_
  bool groups_dirty_ = false;
  GuardSettings guard_;
  State last_good_;  ///< the state after the last step the guard saved (kGuardCheckpointSteps)
  std::vector<std::uint8_t> frozen_;                ///< per body
  std::vector<std::int64_t> body_divergences_;      ///< per body
  std::int64_t divergence_count_ = 0;
  std::vector<DivergenceEvent> events_;             ///< not yet taken
};

}  // namespace soft_body_sim
