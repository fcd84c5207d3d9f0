// A running simulation: model + state + the chosen integrator, advanced in fixed steps.
#pragma once

#include <cstdint>
#include <memory>

#include "soft_body_sim/core/integrator.h"
#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
class World
{
public:
  /// @param model what the scene is; @param initial where it starts (3 x nodeCount arrays)
  World(Model model, State initial, IntegratorType integrator, StepSettings settings);

  /// Advances the simulation by settings().dt [s] in settings().substeps equal sub-steps.
  void step();

  /// Simulated time [s] = number of steps taken * dt (no accumulated round-off).
  double time() const { return static_cast<double>(steps_) * settings_.dt; }
  std::int64_t stepCount() const { return steps_; }

  const Model& model() const { return model_; }
  const State& state() const { return state_; }
  const StepSettings& settings() const { return settings_; }
  IntegratorType integrator() const { return integrator_type_; }

  /// Moves a node kinematically (position [m], velocity [m/s]); the integrator's history is restarted.
  void setNode(int node, const Vec3& position, const Vec3& velocity);

  /// Kinetic + potential energy [J] (see forces.h).
  double energy() const;

private:
  Model model_;
  State state_;
  StepSettings settings_;
  IntegratorType integrator_type_;
  std::unique_ptr<Integrator> integrator_;
  std::int64_t steps_ = 0;
};

}  // namespace soft_body_sim
