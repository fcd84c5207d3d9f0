#include "soft_body_sim/core/integrator_groups.h"

#include <algorithm>
#include <iterator>

namespace soft_body_sim
{
IntegratorGroups::IntegratorGroups(IntegratorType scene_type, std::size_t bodies)
  : scene_type_(scene_type), integrator_(makeIntegrator(scene_type)), body_type_(bodies, scene_type)
{
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
                            const ContactQuery* contacts)
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
  for (const Group& group : groups_)
  {
    group.integrator->internalForces(group.model, state, mine);
    for (std::size_t k = 0; k < group.links.size(); ++k)
      forces.tension[static_cast<Eigen::Index>(group.links[k])] = mine.tension[static_cast<Eigen::Index>(k)];
    for (std::size_t k = 0; k < group.cells.size(); ++k)
      forces.pressure[static_cast<Eigen::Index>(group.cells[k])] = mine.pressure[static_cast<Eigen::Index>(k)];
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
    Group group{ type, model, makeIntegrator(type), {}, {} };
    Model& m = group.model;
    for (int i = 0; i < m.nodeCount(); ++i)
      if (!mine(i))
        m.inverse_mass[i] = 0.0;
    // The elements that touch a node of the group (the others belong to other groups); no colliders:
    // contact is the world's stage, not the group's.
    m.springs.clear();
    m.constraints.clear();
    for (std::size_t k = 0; k < model.springs.size(); ++k)
      if (mine(model.springs[k].a) || mine(model.springs[k].b))
      {
        m.springs.push_back(model.springs[k]);
        group.links.push_back(k);
      }
    for (std::size_t k = 0; k < model.constraints.size(); ++k)
      if (mine(model.constraints[k].a) || mine(model.constraints[k].b))
      {
        m.constraints.push_back(model.constraints[k]);
        group.links.push_back(model.springs.size() + k);
      }
    m.cells.clear();
    for (std::size_t k = 0; k < model.cells.size(); ++k)
      if (std::any_of(std::begin(model.cells[k].nodes), std::end(model.cells[k].nodes), mine))
      {
        m.cells.push_back(model.cells[k]);
        group.cells.push_back(k);
      }
    m.rods.clear();
    for (const Rod& rod : model.rods)
      if (mine(rod.first))
        m.rods.push_back(rod);
    m.tetrahedra.clear();
    for (const Tetrahedron& tet : model.tetrahedra)
      if (mine(tet.nodes[0]))
        m.tetrahedra.push_back(tet);
    m.colliders = Colliders{};
    m.contact_segments.clear();
    groups_.push_back(std::move(group));
  }
}

}  // namespace soft_body_sim
