#include "soft_body_sim/core/world.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <stdexcept>
#include <utility>

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
  , body_integrator_(model_.bodies.size(), integrator)
  , last_good_(state_)
  , frozen_(model_.bodies.size())
  , body_divergences_(model_.bodies.size())
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
  if (groups_dirty_)
    rebuildGroups();
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
      invalidateIntegrators();
    }
    stepIntegrators(h);
    if (!model_.planes.empty() && collideWithPlanes(model_, state_, resting_speed, touching_))
      invalidateIntegrators();
  }
  // Land exactly on the anchor goals (the sub-step sums differ from them by round-off).
  for (std::size_t k = 0; k < model_.anchors.size(); ++k)
    if (anchor_goals_[k])
    {
      state_.position.col(model_.anchors[k].node) = *anchor_goals_[k];
      anchor_goals_[k].reset();
    }
  ++steps_;
  guardBodies();
}

void World::stepIntegrators(double h)
{
  if (groups_.empty())
    integrator_->step(model_, state_, h, settings_.iterations);
  for (IntegratorGroup& group : groups_)
    group.integrator->step(group.model, state_, h, settings_.iterations);
}

void World::invalidateIntegrators()
{
  integrator_->invalidate();
  for (IntegratorGroup& group : groups_)
    group.integrator->invalidate();
}

void World::modelChanged()
{
  integrator_->modelChanged();
  for (IntegratorGroup& group : groups_)
    group.integrator->modelChanged();
  if (!groups_.empty())
    groups_dirty_ = true;
}

void World::rebuildGroups()
{
  groups_dirty_ = false;
  groups_.clear();
  // Each node goes with its body's integrator; a node of no body with the scene's.
  std::vector<IntegratorType> node_type(static_cast<std::size_t>(model_.nodeCount()), integrator_type_);
  for (std::size_t b = 0; b < model_.bodies.size(); ++b)
  {
    const BodyRange& body = model_.bodies[b];
    for (int i = body.first; i < body.first + body.count; ++i)
      node_type[static_cast<std::size_t>(i)] = body_integrator_[b];
  }
  std::vector<IntegratorType> types;
  for (const IntegratorType type : node_type)
    if (std::find(types.begin(), types.end(), type) == types.end())
      types.push_back(type);
  if (types.size() == 1 && types.front() == integrator_type_)
    return;  // every node is on the scene's integrator: one model, no copies
  for (const IntegratorType type : types)
  {
    const auto mine = [&](int node) { return node_type[static_cast<std::size_t>(node)] == type; };
    IntegratorGroup group{ type, model_, makeIntegrator(type) };
    Model& m = group.model;
    for (int i = 0; i < m.nodeCount(); ++i)
      if (!mine(i))
        m.inverse_mass[i] = 0.0;
    // The elements that touch a node of the group (the others belong to other groups); no planes:
    // collisions are the world's stage, not the group's.
    m.springs.clear();
    std::copy_if(model_.springs.begin(), model_.springs.end(), std::back_inserter(m.springs),
                 [&](const Spring& s) { return mine(s.a) || mine(s.b); });
    m.constraints.clear();
    std::copy_if(model_.constraints.begin(), model_.constraints.end(), std::back_inserter(m.constraints),
                 [&](const DistanceConstraint& c) { return mine(c.a) || mine(c.b); });
    m.cells.clear();
    std::copy_if(model_.cells.begin(), model_.cells.end(), std::back_inserter(m.cells), [&](const PressureCell& c) {
      return std::any_of(std::begin(c.nodes), std::end(c.nodes), mine);
    });
    m.planes.clear();
    groups_.push_back(std::move(group));
  }
}

void World::setGuard(const GuardSettings& guard)
{
  if (!(guard.max_speed > 0.0 && std::isfinite(guard.max_speed)))
    throw std::invalid_argument("World: guard max_speed must be a finite number > 0 [m/s]");
  guard_ = guard;
}

std::vector<DivergenceEvent> World::takeDivergenceEvents() { return std::exchange(events_, {}); }

void World::guardBodies()
{
  bool restored = false;
  for (std::size_t b = 0; b < model_.bodies.size(); ++b)
  {
    const BodyRange& body = model_.bodies[b];
    if (frozen_[b] || looksGood(body))
      continue;
    std::string reason = divergence(body);
    if (reason.empty())
      continue;
    // Free nodes only: pinned ones belong to the anchors and controllers, which moved them on purpose.
    for (int i = body.first; i < body.first + body.count; ++i)
      if (model_.isFree(i))
      {
        state_.position.col(i) = last_good_.position.col(i);
        state_.velocity.col(i) = last_good_.velocity.col(i);
      }
    restored = true;
    ++divergence_count_;
    ++body_divergences_[b];
    countDivergenceEventInProcess();
    std::string action = treatDiverged(b);
    events_.push_back({ body.name, time(), std::move(reason), std::move(action) });
  }
  if (restored)
    invalidateIntegrators();
  if (!restored && steps_ % kGuardCheckpointSteps != 0)
    return;
  // Same sizes: a plain copy, no allocation.
  std::copy_n(state_.position.data(), state_.position.size(), last_good_.position.data());
  std::copy_n(state_.velocity.data(), state_.velocity.size(), last_good_.velocity.data());
}

bool World::looksGood(const BodyRange& body) const
{
  // Two vectorised sums over every node, pinned ones too: a sum is finite only if all its terms are,
  // and sum |v_i|^2 <= max_speed^2 bounds every node's speed. A body that fails (a NaN compares false)
  // gets the exact look, node by node, which leaves the pinned nodes (the caller's) out.
  const double x_sum = state_.position.middleCols(body.first, body.count).sum();
  const double v2_sum = state_.velocity.middleCols(body.first, body.count).squaredNorm();
  return std::isfinite(x_sum) && v2_sum <= guard_.max_speed * guard_.max_speed;
}

std::string World::divergence(const BodyRange& body) const
{
  char text[160];
  const double max_speed2 = guard_.max_speed * guard_.max_speed;
  for (int i = body.first; i < body.first + body.count; ++i)
  {
    if (!model_.isFree(i))
      continue;
    if (!state_.position.col(i).allFinite() || !state_.velocity.col(i).allFinite())
    {
      std::snprintf(text, sizeof text, "node %d is not finite", i - body.first);
      return text;
    }
    const double speed2 = state_.velocity.col(i).squaredNorm();
    if (speed2 > max_speed2)
    {
      std::snprintf(text, sizeof text, "node %d moves at %.3g m/s > max_speed %.3g m/s", i - body.first,
                    std::sqrt(speed2), guard_.max_speed);
      return text;
    }
  }
  return {};
}

std::string World::treatDiverged(std::size_t body)
{
  const IntegratorType type = body_integrator_[body];
  switch (guard_.policy)
  {
    case GuardPolicy::HalveStep:
      if (2 * settings_.substeps > kGuardMaxSubsteps)
        return "already at " + std::to_string(settings_.substeps) + " sub-steps per step: " + freeze(body);
      settings_.substeps *= 2;
      invalidateIntegrators();  // a multistep history (verlet) holds the old h
      {
        char text[120];
        std::snprintf(text, sizeof text, "sub-step halved to %.3g s (%d per step, every body)",
                      settings_.dt / settings_.substeps, settings_.substeps);
        return text;
      }
    case GuardPolicy::SwitchIntegrator:
      if (type == IntegratorType::ImplicitEuler)
        return "already on implicit_euler: " + freeze(body);
      body_integrator_[body] = IntegratorType::ImplicitEuler;
      groups_dirty_ = true;
      return "switched from " + integratorName(type) + " to implicit_euler";
    case GuardPolicy::Freeze:
      break;
  }
  return freeze(body);
}

std::string World::freeze(std::size_t body)
{
  frozen_[body] = 1;
  const BodyRange& range = model_.bodies[body];
  for (int i = range.first; i < range.first + range.count; ++i)
  {
    // Its controller stops too (driveKinematicNodes): a controller whose own points run away (as the
    // codeling's compounding antic once did) would otherwise drag the frozen body on to infinity.
    state_.velocity.col(i).setZero();
    if (model_.isFree(i))
      model_.inverse_mass[i] = 0.0;
  }
  modelChanged();
  return "frozen (its free nodes pinned at rest)";
}

bool World::driveKinematicNodes(double dt)
{
  bool moved = !controllers_.empty();
  for (BodyController& body : controllers_)
    if (!frozen_[static_cast<std::size_t>(body.body)])  // a frozen body stands still, driven points too
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
  invalidateIntegrators();
}

void World::setStepSettings(const StepSettings& settings)
{
  if (!(settings.dt > 0.0 && std::isfinite(settings.dt)) || settings.substeps < 1 || settings.iterations < 1)
    throw std::invalid_argument("World: dt must be finite and > 0, substeps and iterations >= 1");
  // Time goes on from here in steps of the new dt: time() stays continuous.
  time_origin_ = time();
  steps_origin_ = steps_;
  settings_ = settings;
  invalidateIntegrators();  // a multistep history (verlet) holds the old h
}

void World::setIntegrator(IntegratorType type)
{
  // Every integrator's state is (x, v) plus caches it rebuilds from them: a fresh one continues.
  integrator_ = makeIntegrator(type);
  integrator_type_ = type;
  std::fill(body_integrator_.begin(), body_integrator_.end(), type);
  groups_.clear();
  groups_dirty_ = false;
}

void World::setGravity(const Vec3& gravity)
{
  if (!gravity.allFinite())
    throw std::invalid_argument("World: gravity must be finite");
  model_.gravity = gravity;
  modelChanged();  // a cached acceleration (velocity_verlet) holds the old gravity
}

void World::setDrag(double drag)
{
  if (!(drag >= 0.0 && std::isfinite(drag)))
    throw std::invalid_argument("World: drag must be finite and >= 0");
  model_.drag = drag;
  modelChanged();
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
  modelChanged();
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
  modelChanged();
  return static_cast<int>(model_.anchors.size()) - 1;
}

bool World::detach(int anchor)
{
  if (!isAttached(anchor))
    return false;
  const auto k = static_cast<std::size_t>(anchor);
  const int node = model_.anchors[k].node;
  // A node of a frozen body stays pinned: the guard froze it there.
  model_.inverse_mass[node] = frozen_[bodyOf(node)] ? 0.0 : 1.0 / model_.mass[node];
  model_.anchors.erase(model_.anchors.begin() + anchor);
  anchor_goals_.erase(anchor_goals_.begin() + anchor);
  anchor_paths_.erase(anchor_paths_.begin() + anchor);
  modelChanged();
  return true;
}

bool World::isAttached(int anchor) const
{
  return anchor >= 0 && static_cast<std::size_t>(anchor) >= scene_anchors_ &&
         static_cast<std::size_t>(anchor) < model_.anchors.size();
}

double World::energy() const { return kineticEnergy(model_, state_) + potentialEnergy(model_, state_); }

}  // namespace soft_body_sim
