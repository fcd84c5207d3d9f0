#include "soft_body_sim/core/integrators/integrator_groups.h"

#include <algorithm>
#include <stdexcept>

#include "core/elements/element_kinds.h"

namespace soft_body_sim
{
IntegratorGroups::IntegratorGroups(IntegratorType scene_type, std::size_t bodies)
  : scene_type_(scene_type), integrator_(makeIntegrator(scene_type)), body_type_(bodies, scene_type)
{
}

IntegratorGroups::IntegratorGroups(const IntegratorGroups& other)
  : scene_type_(other.scene_type_), integrator_(other.integrator_->clone()), body_type_(other.body_type_),
    dirty_(other.dirty_)
{
  for (const Group& group : other.groups_)
    groups_.push_back(Group{ group.type, group.model, group.integrator->clone(), group.elements });
}

IntegratorGroups& IntegratorGroups::operator=(const IntegratorGroups& other)
{
  if (this == &other)
    return *this;
  if (!integrator_->assign(*other.integrator_))
    integrator_ = other.integrator_->clone();
  groups_.resize(other.groups_.size());
  for (std::size_t k = 0; k < groups_.size(); ++k)
  {
    Group& group = groups_[k];
    const Group& theirs = other.groups_[k];
    group.type = theirs.type;
    group.model = theirs.model;
    group.elements = theirs.elements;
    if (!group.integrator || !group.integrator->assign(*theirs.integrator))
      group.integrator = theirs.integrator->clone();
  }
  scene_type_ = other.scene_type_;
  body_type_ = other.body_type_;
  dirty_ = other.dirty_;
  return *this;
}

void IntegratorGroups::setAll(IntegratorType type)
{
  // Every integrator's state is (x, v) plus caches it rebuilds from them: a fresh one continues.
  integrator_ = makeIntegrator(type);
  scene_type_ = type;
  std::fill(body_type_.begin(), body_type_.end(), type);
  groups_.clear();
  dirty_ = false;
}

void IntegratorGroups::switchBody(std::size_t body, IntegratorType type)
{
  body_type_.at(body) = type;
  dirty_ = true;
}

void IntegratorGroups::prepare(const Model& model)
{
  if (dirty_)
    rebuild(model);
}

void IntegratorGroups::step(const Model& model, State& state, double h, int iterations,
                            ContactQuery* contacts)
{
  if (groups_.empty())
    integrator_->stepWithContacts(model, state, h, iterations, contacts);
  for (Group& group : groups_)
    group.integrator->stepWithContacts(group.model, state, h, iterations, contacts);
}

void IntegratorGroups::internalForces(const Model& model, const State& state, InternalForces& forces) const
{
  if (groups_.empty())
  {
    integrator_->internalForces(model, state, forces);
    return;
  }
  forces.tension.setZero(static_cast<Eigen::Index>(model.springs.size() + model.constraints.size()));
  forces.pressure.setZero(static_cast<Eigen::Index>(model.cells.size()));
  InternalForces mine;
  const auto scene_index = [](std::size_t k) { return static_cast<Eigen::Index>(k); };
  for (const Group& group : groups_)
  {
    group.integrator->internalForces(group.model, state, mine);
    // A link's tension: the springs', then the constraints' after all springs (InternalForces).
    const std::vector<std::size_t>& springs = group.elements[kindIndex<SpringKind>()];
    const std::vector<std::size_t>& constraints = group.elements[kindIndex<DistanceConstraintKind>()];
    const std::vector<std::size_t>& cells = group.elements[kindIndex<GasCellKind>()];
    for (std::size_t k = 0; k < springs.size(); ++k)
      forces.tension[scene_index(springs[k])] = mine.tension[scene_index(k)];
    for (std::size_t k = 0; k < constraints.size(); ++k)
      forces.tension[scene_index(model.springs.size() + constraints[k])] = mine.tension[scene_index(springs.size() + k)];
    for (std::size_t k = 0; k < cells.size(); ++k)
      forces.pressure[scene_index(cells[k])] = mine.pressure[scene_index(k)];
  }
}

void IntegratorGroups::invalidate()
{
  integrator_->invalidate();
  for (Group& group : groups_)
    group.integrator->invalidate();
}

void IntegratorGroups::modelChanged()
{
  integrator_->modelChanged();
  for (Group& group : groups_)
    group.integrator->modelChanged();
  if (!groups_.empty())
    dirty_ = true;
}

void IntegratorGroups::carry(StateArchive& archive, const Model& model)
{
  // Dirty groups are made again, with fresh integrators, by the next step's prepare: none are written.
  const IntegratorType scene_type = scene_type_;
  std::size_t groups = dirty_ ? 0 : groups_.size();
  archive(scene_type_, body_type_, dirty_, groups);
  if (archive.reading())
  {
    if (scene_type_ != scene_type)
      integrator_ = makeIntegrator(scene_type_);
    if (body_type_.size() != model.bodies.size())
      throw std::invalid_argument("snapshot bytes: integrators for another number of bodies");
    const bool dirty = dirty_;
    groups_.clear();
    if (groups > 0)
      rebuild(model);
    dirty_ = dirty;
    if (groups_.size() != groups)
      throw std::invalid_argument("snapshot bytes: integrator groups that this model does not make");
  }
  integrator_->carry(archive, model);
  for (std::size_t k = 0; k < groups; ++k)
    groups_[k].integrator->carry(archive, groups_[k].model);
}

void IntegratorGroups::rebuild(const Model& model)
{
  dirty_ = false;
  groups_.clear();
  // Each node goes with its body's integrator; a node of no body with the scene's.
  std::vector<IntegratorType> node_type(static_cast<std::size_t>(model.nodeCount()), scene_type_);
  for (std::size_t b = 0; b < model.bodies.size(); ++b)
  {
    const BodyRange& body = model.bodies[b];
    for (int i = body.first; i < body.first + body.count; ++i)
      node_type[static_cast<std::size_t>(i)] = body_type_[b];
  }
  std::vector<IntegratorType> types;
  for (const IntegratorType type : node_type)
    if (std::find(types.begin(), types.end(), type) == types.end())
      types.push_back(type);
  if (types.size() == 1 && types.front() == scene_type_)
    return;  // every node is on the scene's integrator: one model, no copies
  for (const IntegratorType type : types)
  {
    const auto mine = [&](int node) { return node_type[static_cast<std::size_t>(node)] == type; };
    Group group{ type, model, makeIntegrator(type), std::vector<std::vector<std::size_t>>(ElementKinds::size) };
    Model& m = group.model;
    for (int i = 0; i < m.nodeCount(); ++i)
      if (!mine(i))
        m.inverse_mass[i] = 0.0;
    // The elements that touch a node of the group (the others belong to other groups); no colliders:
    // contact is the world's stage, not the group's.
    std::size_t kind_index = 0;
    forEachKind([&](auto kind) {
      auto& elements = kind.of(m);
      const auto& all = kind.of(model);
      elements.clear();
      for (std::size_t k = 0; k < all.size(); ++k)
        if (kind.touches(all[k], mine))
        {
          elements.push_back(all[k]);
          group.elements[kind_index].push_back(k);
        }
      ++kind_index;
    });
    m.colliders = Colliders{};
    m.contact_segments.clear();
    m.contact_triangles.clear();
    groups_.push_back(std::move(group));
  }
}

}  // namespace soft_body_sim
