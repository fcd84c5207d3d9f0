#include "soft_body_sim/core/world.h"

#include <stdexcept>

#include "soft_body_sim/core/forces.h"

namespace soft_body_sim
{
World::World(Model model, State initial, IntegratorType integrator, StepSettings settings)
  : model_(std::move(model))
  , state_(std::move(initial))
  , settings_(settings)
  , integrator_type_(integrator)
  , integrator_(makeIntegrator(integrator))
{
  const Eigen::Index n = model_.nodeCount();
  if (model_.inverse_mass.size() != n || state_.position.cols() != n || state_.velocity.cols() != n)
    throw std::invalid_argument("World: mass, inverse mass, position and velocity sizes differ");
  if (!(settings_.dt > 0.0) || settings_.substeps < 1 || settings_.iterations < 1)
    throw std::invalid_argument("World: dt must be > 0, substeps and iterations >= 1");
}

void World::step()
{
  const double h = settings_.dt / settings_.substeps;
  for (int substep = 0; substep < settings_.substeps; ++substep)
    integrator_->step(model_, state_, h, settings_.iterations);
  ++steps_;
}

void World::setNode(int node, const Vec3& position, const Vec3& velocity)
{
  state_.position.col(node) = position;
  state_.velocity.col(node) = velocity;
  integrator_->restart();
}

double World::energy() const { return kineticEnergy(model_, state_) + potentialEnergy(model_, state_); }

}  // namespace soft_body_sim
