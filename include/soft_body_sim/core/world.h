// A running simulation: model + state + the chosen integrator, advanced in fixed steps.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "soft_body_sim/core/controller.h"
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

class World
{
public:
  /// @param model what the scene is; @param initial where it starts (3 x nodeCount arrays)
  World(Model model, State initial, IntegratorType integrator, StepSettings settings,
        std::vector<BodyController> controllers = {});

  /// Advances the simulation by settings().dt [s]. Stages: controllers drive their nodes; anchors set
  /// their nodes' velocities toward their new poses; then per sub-step of dt / substeps: anchors move,
  /// the integrator steps, planes push nodes out.
  void step();

  /// Simulated time [s] = number of steps taken * dt (no accumulated round-off).
  double time() const { return static_cast<double>(steps_) * settings_.dt; }
  std::int64_t stepCount() const { return steps_; }

  const Model& model() const { return model_; }
  const State& state() const { return state_; }
  const StepSettings& settings() const { return settings_; }
  IntegratorType integrator() const { return integrator_type_; }
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

  /// Kinetic + potential energy [J] (see forces.h).
  double energy() const;

private:
  /// Controllers and anchors set their nodes for this step; true if any kinematic node moves.
  bool driveKinematicNodes(double dt);

  Model model_;
  State state_;
  StepSettings settings_;
  IntegratorType integrator_type_;
  std::unique_ptr<Integrator> integrator_;
  std::vector<BodyController> controllers_;
  std::vector<std::optional<Vec3>> anchor_goals_;  ///< per anchor: where to be at the end of the next step
  std::vector<std::uint8_t> touching_;              ///< per node: on a plane after the last sub-step
  std::int64_t steps_ = 0;
};

}  // namespace soft_body_sim
