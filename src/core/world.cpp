#include "soft_body_sim/core/world.h"

#include <cmath>
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
  , anchor_paths_(model_.anchors.size())
  , scene_anchors_(model_.anchors.size())
  , built_springs_(model_.springs)
  , built_constraints_(model_.constraints)
  , built_cells_(model_.cells)
  , body_scaling_(model_.bodies.size())
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
  for (std::size_t k = 0; k < model_.anchors.size(); ++k)
    if (anchor_paths_[k] && !anchor_goals_[k])
      anchor_goals_[k] = anchor_paths_[k](time() + dt);
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

void World::setStepSettings(const StepSettings& settings)
{
  if (!(settings.dt > 0.0 && std::isfinite(settings.dt)) || settings.substeps < 1 || settings.iterations < 1)
    throw std::invalid_argument("World: dt must be finite and > 0, substeps and iterations >= 1");
  // Time goes on from here in steps of the new dt: time() stays continuous.
  time_origin_ = time();
  steps_origin_ = steps_;
  settings_ = settings;
  integrator_->invalidate();  // a multistep history (verlet) holds the old h
}

void World::setIntegrator(IntegratorType type)
{
  // Every integrator's state is (x, v) plus caches it rebuilds from them: a fresh one continues.
  integrator_ = makeIntegrator(type);
  integrator_type_ = type;
}

void World::setGravity(const Vec3& gravity)
{
  if (!gravity.allFinite())
    throw std::invalid_argument("World: gravity must be finite");
  model_.gravity = gravity;
  integrator_->invalidate();  // a cached acceleration (velocity_verlet) holds the old gravity
}

void World::setDrag(double drag)
{
  if (!(drag >= 0.0 && std::isfinite(drag)))
    throw std::invalid_argument("World: drag must be finite and >= 0");
  model_.drag = drag;
  integrator_->invalidate();
}

std::size_t World::bodyOf(int node) const
{
  for (std::size_t b = 0; b < model_.bodies.size(); ++b)
    if (node >= model_.bodies[b].first && node < model_.bodies[b].first + model_.bodies[b].count)
      return b;
  throw std::out_of_range("World: node " + std::to_string(node) + " belongs to no body");
}

bool World::setBodyScaling(const std::string& body, const BodyScaling& scaling)
{
  // Stiffness and pressure divide (compliance = 1 / k, Boyle's law p0 A0 / A): they must stay > 0.
  if (!(scaling.stiffness > 0.0 && std::isfinite(scaling.stiffness)) ||
      !(scaling.pressure > 0.0 && std::isfinite(scaling.pressure)) ||
      !(scaling.damping >= 0.0 && std::isfinite(scaling.damping)))
    throw std::invalid_argument("World: body scaling: stiffness and pressure must be finite and > 0, damping >= 0");
  std::size_t b = 0;
  while (b < model_.bodies.size() && model_.bodies[b].name != body)
    ++b;
  if (b == model_.bodies.size())
    return false;
  body_scaling_[b] = scaling;
  // From the built values, not the current ones: factors do not compound and 1 restores the scene.
  for (std::size_t k = 0; k < model_.springs.size(); ++k)
    if (bodyOf(built_springs_[k].a) == b)
    {
      model_.springs[k].stiffness = built_springs_[k].stiffness * scaling.stiffness;
      model_.springs[k].damping = built_springs_[k].damping * scaling.damping;
    }
  for (std::size_t k = 0; k < model_.constraints.size(); ++k)
    if (bodyOf(built_constraints_[k].a) == b)
      model_.constraints[k].compliance = built_constraints_[k].compliance / scaling.stiffness;
  for (std::size_t k = 0; k < model_.cells.size(); ++k)
    if (bodyOf(built_cells_[k].nodes[0]) == b)
      model_.cells[k].pressure = built_cells_[k].pressure * scaling.pressure;
  integrator_->invalidate();
  return true;
}

BodyScaling World::bodyScaling(const std::string& body) const
{
  for (std::size_t b = 0; b < model_.bodies.size(); ++b)
    if (model_.bodies[b].name == body)
      return body_scaling_[b];
  return {};
}

void World::followPath(int anchor, AnchorPath path) { anchor_paths_.at(static_cast<std::size_t>(anchor)) = std::move(path); }

std::optional<int> World::nearestFreeNode(const Vec3& point, const std::string& body, double radius) const
{
  std::optional<int> nearest;
  double best = radius;
  for (const BodyRange& range : model_.bodies)
  {
    if (!body.empty() && range.name != body)
      continue;
    for (int i = range.first; i < range.first + range.count; ++i)
    {
      const double distance = (state_.position.col(i) - point).norm();
      if (model_.isFree(i) && distance <= best)
      {
        best = distance;
        nearest = i;
      }
    }
  }
  return nearest;
}

int World::attach(int node, const std::string& name)
{
  if (node < 0 || node >= model_.nodeCount() || !model_.isFree(node))
    throw std::invalid_argument("World: only a free node can be attached");
  const std::string& body = model_.bodies[bodyOf(node)].name;
  if (findAnchor(body, name))
    throw std::invalid_argument("World: body '" + body + "' already has an anchor '" + name + "'");
  // Pinned = inverse mass 0: from now on only the anchor moves it (Ten Minute Physics' grab).
  model_.inverse_mass[node] = 0.0;
  model_.anchors.push_back({ body, name, node });
  anchor_goals_.emplace_back();
  anchor_paths_.emplace_back();
  integrator_->invalidate();
  return static_cast<int>(model_.anchors.size()) - 1;
}

bool World::detach(int anchor)
{
  if (!isAttached(anchor))
    return false;
  const auto k = static_cast<std::size_t>(anchor);
  const int node = model_.anchors[k].node;
  model_.inverse_mass[node] = 1.0 / model_.mass[node];
  model_.anchors.erase(model_.anchors.begin() + anchor);
  anchor_goals_.erase(anchor_goals_.begin() + anchor);
  anchor_paths_.erase(anchor_paths_.begin() + anchor);
  integrator_->invalidate();
  return true;
}

bool World::isAttached(int anchor) const
{
  return anchor >= 0 && static_cast<std::size_t>(anchor) >= scene_anchors_ &&
         static_cast<std::size_t>(anchor) < model_.anchors.size();
}

double World::energy() const { return kineticEnergy(model_, state_) + potentialEnergy(model_, state_); }

}  // namespace soft_body_sim
