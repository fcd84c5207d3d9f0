#include "soft_body_sim/core/world.h"

#include <stdexcept>

#include "soft_body_sim/core/collisions.h"
#include "soft_body_sim/core/forces.h"

namespace soft_body_sim
{
World::World(Model model, State initial, IntegratorType integrator, StepSettings settings,
             std::vector<BodyController> controllers)
  : model_(std::move(model))
  , state_(std::move(initial))
  , settings_(settings)
  , integrator_type_(integrator)
  , integrator_(makeIntegrator(integrator))
  , controllers_(std::move(controllers))
  , anchor_goals_(model_.anchors.size())
{
  const Eigen::Index n = model_.nodeCount();
  if (model_.inverse_mass.size() != n || state_.position.cols() != n || state_.velocity.cols() != n)
    throw std::invalid_argument("World: mass, inverse mass, position and velocity sizes differ");
  if (!(settings_.dt > 0.0) || settings_.substeps < 1 || settings_.iterations < 1)
    throw std::invalid_argument("World: dt must be > 0, substeps and iterations >= 1");
  for (const Anchor& anchor : model_.anchors)
    if (anchor.node < 0 || anchor.node >= n || model_.isFree(anchor.node))
      throw std::invalid_argument("World: anchor '" + anchor.name + "' must name a pinned node");
}

void World::step()
{
  const double dt = settings_.dt;
  const double h = dt / settings_.substeps;
  const bool kinematic = driveKinematicNodes(dt);
  // A node resting on a plane approaches it by ~|g| h per sub-step; twice that does not bounce.
  const double resting_speed = 2.0 * model_.gravity.norm() * h;
  for (int substep = 0; substep < settings_.substeps; ++substep)
  {
    if (kinematic)
    {
      for (const Anchor& anchor : model_.anchors)
        state_.position.col(anchor.node) += h * state_.velocity.col(anchor.node);
      integrator_->invalidate();
    }
    integrator_->step(model_, state_, h, settings_.iterations);
    if (!model_.planes.empty() && collideWithPlanes(model_, state_, resting_speed, touching_))
      integrator_->invalidate();
  }
  // Land exactly on the anchor goals (the sub-step sums differ from them by round-off).
  for (std::size_t k = 0; k < model_.anchors.size(); ++k)
    if (anchor_goals_[k])
    {
      state_.position.col(model_.anchors[k].node) = *anchor_goals_[k];
      anchor_goals_[k].reset();
    }
  ++steps_;
}

bool World::driveKinematicNodes(double dt)
{
  bool moved = !controllers_.empty();
  for (BodyController& body : controllers_)
    body.controller->step(dt, state_);
  for (std::size_t k = 0; k < model_.anchors.size(); ++k)
  {
    const int node = model_.anchors[k].node;
    if (anchor_goals_[k])
    {
      state_.velocity.col(node) = (*anchor_goals_[k] - state_.position.col(node)) / dt;
      moved = true;
    }
    else if (!state_.velocity.col(node).isZero(0.0))
    {
      // It arrived last step and stands still now.
      state_.velocity.col(node).setZero();
      moved = true;
    }
  }
  return moved;
}

std::optional<int> World::findAnchor(const std::string& body, const std::string& anchor) const
{
  for (std::size_t k = 0; k < model_.anchors.size(); ++k)
    if (model_.anchors[k].body == body && model_.anchors[k].name == anchor)
      return static_cast<int>(k);
  return std::nullopt;
}

void World::moveAnchor(int anchor, const Vec3& position) { anchor_goals_.at(static_cast<std::size_t>(anchor)) = position; }

bool World::setTarget(const std::string& body, const Vec3& target)
{
  for (BodyController& c : controllers_)
    if (model_.bodies[static_cast<std::size_t>(c.body)].name == body)
      return c.controller->setTarget(target);
  return false;
}

void World::setNode(int node, const Vec3& position, const Vec3& velocity)
{
  state_.position.col(node) = position;
  state_.velocity.col(node) = velocity;
  integrator_->invalidate();
}

double World::energy() const { return kineticEnergy(model_, state_) + potentialEnergy(model_, state_); }

}  // namespace soft_body_sim
