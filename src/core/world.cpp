#include "soft_body_sim/core/world.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <utility>

#include "core/elements/element_kinds.h"
#include "soft_body_sim/core/elements/forces.h"
#include "soft_body_sim/core/elements/rods.h"
#include "soft_body_sim/core/elements/tetrahedra.h"

namespace soft_body_sim
{
World::World(Model model, State initial, IntegratorType integrator, StepSettings settings,
             std::vector<BodyController> controllers)
  : model_(std::move(model))
  , state_(std::move(initial))
  , settings_(settings)
  , controllers_(std::move(controllers))
  , anchors_(model_.anchors.size())
  , integrators_(integrator, model_.bodies.size())
  , contacts_(model_)
  , self_contacts_(model_, state_.position)
  , material_(model_)
  , guard_(state_, model_.bodies.size())
{
  const Eigen::Index n = model_.nodeCount();
  if (model_.contact_radius.size() == 0)
    model_.contact_radius.setZero(n);  // a model made without radii: points
  const Eigen::Index twists = model_.rods.empty() ? 0 : n;
  if (state_.twist.size() == 0 && twists > 0)
  {
    state_.twist.setZero(twists);  // a state made without twists: its rods untwisted
    guard_.checkpoint(state_, 0, true);
  }
  if (model_.inverse_mass.size() != n || model_.contact_radius.size() != n || state_.position.cols() != n ||
      state_.velocity.cols() != n || state_.twist.size() != twists)
    throw std::invalid_argument("World: mass, inverse mass, contact radius, position, velocity and twist sizes differ");
  if (!(settings_.dt > 0.0) || settings_.substeps < 1 || settings_.iterations < 1)
    throw std::invalid_argument("World: dt must be > 0, substeps and iterations >= 1");
  for (const Anchor& anchor : model_.anchors)
    if (anchor.node < 0 || anchor.node >= n || model_.isFree(anchor.node))
      throw std::invalid_argument("World: anchor '" + anchor.name + "' must name a pinned node");
}

World::World(const World& other)
  : model_(other.model_)
  , state_(other.state_)
  , settings_(other.settings_)
  , anchors_(other.anchors_)
  , grasps_(other.grasps_)
  , slips_(other.slips_)
  , integrators_(other.integrators_)
  , contacts_(other.contacts_)
  , self_contacts_(other.self_contacts_)
  , material_(other.material_)
  , guard_(other.guard_)
  , time_origin_(other.time_origin_)
  , steps_origin_(other.steps_origin_)
  , steps_(other.steps_)
{
  for (const BodyController& controller : other.controllers_)
    controllers_.push_back(BodyController{ controller.body, controller.controller->clone() });
}

World& World::operator=(const World& other)
{
  if (this == &other)
    return *this;
  model_ = other.model_;
  state_ = other.state_;
  settings_ = other.settings_;
  controllers_.clear();
  for (const BodyController& controller : other.controllers_)
    controllers_.push_back(BodyController{ controller.body, controller.controller->clone() });
  anchors_ = other.anchors_;
  grasps_ = other.grasps_;
  slips_ = other.slips_;
  integrators_ = other.integrators_;
  contacts_ = other.contacts_;
  self_contacts_ = other.self_contacts_;
  material_ = other.material_;
  guard_ = other.guard_;
  time_origin_ = other.time_origin_;
  steps_origin_ = other.steps_origin_;
  steps_ = other.steps_;
  return *this;
}

void World::snapshot(WorldSnapshot& into) const
{
  if (into.world_ && into.world_.use_count() == 1)
    *into.world_ = *this;
  else
    into = snapshot();
}

void World::step()
{
  const double dt = settings_.dt;
  const double h = dt / settings_.substeps;
  integrators_.prepare(model_);
  anchors_.goalsFromPaths(time() + dt);
  grasps_.goalsFromPaths(time() + dt);
  contacts_.goalsFromPaths(time() + dt, dt);
  contacts_.beginStep(dt);
  const bool kinematic = driveKinematicNodes(dt);
  for (int substep = 0; substep < settings_.substeps; ++substep)
  {
    self_contacts_.remember(state_);  // before the anchors move: a dragged link slips past the others
    if (kinematic)
      moveHeldNodes(substep + 1, h);
    integrate(h);
    resolveContacts(h);
    resolveSelfContacts();
  }
  landKinematics();
  ++steps_;
  slipGrasps();
  guardBodies();
}

bool World::driveKinematicNodes(double dt)
{
  bool moved = !controllers_.empty();
  for (BodyController& body : controllers_)
    if (!guard_.isFrozen(static_cast<std::size_t>(body.body)))  // a frozen body stands still, driven points too
      body.controller->step(dt, state_);
  return anchors_.setVelocities(model_, state_, dt) || !grasps_.empty() || moved;
}

void World::moveHeldNodes(int substep, double h)
{
  anchors_.advance(model_, state_, substep, settings_.substeps, h);
  grasps_.advance(model_, state_, substep, settings_.substeps, h);
  integrators_.invalidate();
}

void World::integrate(double h)
{
  contacts_.remember(state_);
  integrators_.step(model_, state_, h, settings_.iterations, contacts_.query());
  if (integration_observer_)
    integration_observer_(model_, state_);
}

void World::resolveContacts(double h)
{
  if (contacts_.resolve(model_, state_, h))
    integrators_.invalidate();
}

void World::resolveSelfContacts()
{
  if (self_contacts_.resolve(model_, state_))
    integrators_.invalidate();
}

void World::landKinematics()
{
  anchors_.land(model_, state_);
  grasps_.land();
  contacts_.land();
}

void World::slipGrasps()
{
  if (!grasps_.limited())
    return;
  const std::vector<Wrench> wrenches = graspWrenches();
  // Released in reverse: a release moves the later grasps down one index.
  for (std::size_t k = wrenches.size(); k-- > 0;)
  {
    const GraspedNodes& g = grasps_.grasps()[k];
    const double force = wrenches[k].force.norm();
    if (force > g.max_force)
    {
      slips_.push_back(GraspSlip{ time(), g.name, model_.bodies[g.body].name, force, g.max_force });
      release(slips_.back().grasp);
    }
  }
}

void World::guardBodies()
{
  const std::vector<DivergenceGuard::Catch> caught = guard_.restoreDiverged(model_, state_);
  for (const DivergenceGuard::Catch& c : caught)
    guard_.record(model_, c, time(), treatDiverged(c.body));
  if (!caught.empty())
    integrators_.invalidate();
  guard_.checkpoint(state_, steps_, !caught.empty());
}

std::string World::treatDiverged(std::size_t body)
{
  const IntegratorType type = integrators_.bodyType(body);
  const auto freeze = [&] {
    std::string action = guard_.freeze(model_, state_, body);
    modelChanged();
    return action;
  };
  switch (guard_.settings().policy)
  {
    case GuardPolicy::HalveStep:
      if (2 * settings_.substeps > kGuardMaxSubsteps)
        return "already at " + std::to_string(settings_.substeps) + " sub-steps per step: " + freeze();
      settings_.substeps *= 2;
      integrators_.invalidate();  // a multistep history (verlet) holds the old h
      {
        char text[120];
        std::snprintf(text, sizeof text, "sub-step halved to %.3g s (%d per step, every body)",
                      settings_.dt / settings_.substeps, settings_.substeps);
        return text;
      }
    case GuardPolicy::SwitchIntegrator:
      if (type == IntegratorType::ImplicitEuler)
        return "already on implicit_euler: " + freeze();
      integrators_.switchBody(body, IntegratorType::ImplicitEuler);
      return "switched from " + integratorName(type) + " to implicit_euler";
    case GuardPolicy::Freeze:
      break;
  }
  return freeze();
}

void World::setIntegrator(IntegratorType type)
{
  requireIntegratorRunsModel(model_, type);
  integrators_.setAll(type);
}

bool World::takesTarget(std::size_t body) const
{
  for (const BodyController& c : controllers_)
    if (static_cast<std::size_t>(c.body) == body)
      return c.controller->takesTarget();
  return false;
}

std::optional<Vec3> World::target(std::size_t body) const
{
  for (const BodyController& c : controllers_)
    if (static_cast<std::size_t>(c.body) == body)
      return c.controller->target();
  return std::nullopt;
}

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
  integrators_.invalidate();
}

void World::setStepSettings(const StepSettings& settings)
{
  if (!(settings.dt > 0.0 && std::isfinite(settings.dt)) || settings.substeps < 1 || settings.iterations < 1)
    throw std::invalid_argument("World: dt must be finite and > 0, substeps and iterations >= 1");
  // Time goes on from here in steps of the new dt: time() stays continuous.
  time_origin_ = time();
  steps_origin_ = steps_;
  settings_ = settings;
  integrators_.invalidate();  // a multistep history (verlet) holds the old h
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

bool World::setBodyScaling(const std::string& body, const BodyScaling& scaling)
{
  for (std::size_t b = 0; b < model_.bodies.size(); ++b)
    if (model_.bodies[b].name == body)
    {
      material_.set(model_, b, scaling);
      modelChanged();
      return true;
    }
  return false;
}

BodyScaling World::bodyScaling(const std::string& body) const
{
  for (std::size_t b = 0; b < model_.bodies.size(); ++b)
    if (model_.bodies[b].name == body)
      return material_.of(b);
  return {};
}

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
  const std::string& body = model_.bodies[model_.bodyOf(node)].name;
  if (findAnchor(body, name))
    throw std::invalid_argument("World: body '" + body + "' already has an anchor '" + name + "'");
  // Pinned = inverse mass 0: from now on only the anchor moves it (Ten Minute Physics' grab).
  model_.inverse_mass[node] = 0.0;
  model_.anchors.push_back({ body, name, node, "" });
  anchors_.added();
  modelChanged();
  return static_cast<int>(model_.anchors.size()) - 1;
}

bool World::detach(int anchor)
{
  if (!isAttached(anchor))
    return false;
  const auto k = static_cast<std::size_t>(anchor);
  const int node = model_.anchors[k].node;
  if (const StationIndex at = findRodStation(model_, node))
    releaseRod(model_.rods[static_cast<std::size_t>(at.rod)], state_.position, state_.twist, at.station);
  model_.releaseNode(node, guard_.isFrozen(model_.bodyOf(node)));
  model_.anchors.erase(model_.anchors.begin() + anchor);
  anchors_.removed(k);
  modelChanged();
  return true;
}

InternalForces World::internalForces() const
{
  InternalForces forces;
  integrators_.internalForces(model_, state_, forces);
  return forces;
}

NodeArray World::pulls() const
{
  NodeArray pull;
  internalPulls(model_, state_, internalForces(), pull);
  return pull;
}

std::vector<Wrench> World::anchorWrenches() const
{
  std::vector<Wrench> wrenches;
  if (model_.anchors.empty())
    return wrenches;
  const NodeArray pull = pulls();
  for (const Anchor& anchor : model_.anchors)
  {
    wrenches.push_back(holdingWrench(model_, state_.position, pull, { anchor.node }, state_.position.col(anchor.node)));
    // A rod takes its bending and twisting moment there too.
    if (const StationIndex at = findRodStation(model_, anchor.node))
      wrenches.back().torque += stationTorque(model_.rods[static_cast<std::size_t>(at.rod)], at.station, state_.position, state_.twist);
  }
  return wrenches;
}

std::vector<Wrench> World::graspWrenches() const
{
  if (grasps_.empty())
    return {};
  return grasps_.wrenches(model_, state_, pulls());
}

std::size_t World::grasp(const std::string& frame, const std::string& body, const RigidPose& pose, double radius,
                         double max_force)
{
  const std::size_t held = grasps_.grasp(model_, state_, frame, body, pose, radius, max_force);
  modelChanged();
  return held;
}

bool World::release(const std::string& frame)
{
  for (const GraspedNodes& g : grasps_.grasps())
    if (g.name == frame)
    {
      grasps_.release(model_, state_, frame, guard_.isFrozen(g.body));
      modelChanged();
      return true;
    }
  return false;
}

double World::energy() const { return kineticEnergy(model_, state_) + potentialEnergy(model_, state_); }

}  // namespace soft_body_sim
