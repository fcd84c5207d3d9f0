#include "soft_body_sim/core/scene_def.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "soft_body_sim/core/stability.h"

#include "soft_body_sim/core/forces.h"

namespace soft_body_sim
{
namespace
{
int globalIndex(const BodyDef& body, int first, int local)
{
  if (local < 0 || local >= static_cast<int>(body.nodes.size()))
    throw std::invalid_argument("body '" + body.name + "': node index " + std::to_string(local) + " out of range");
  return first + local;
}

double restLengthOr(const std::optional<double>& rest_length, const State& state, int a, int b)
{
  return rest_length ? *rest_length : (state.position.col(a) - state.position.col(b)).norm();
}
}  // namespace

int resolveNodeIndex(long long index, int node_count)
{
  const long long resolved = index < 0 ? index + node_count : index;
  if (resolved < 0 || resolved >= node_count)
    throw std::out_of_range("node index " + std::to_string(index) + " out of range for " +
                            std::to_string(node_count) + " nodes");
  return static_cast<int>(resolved);
}

void requireSelfContact(const std::string& what, bool self_collision, double self_friction, double contact_radius,
                        const std::string& radius_key)
{
  requireDefinition(!self_collision || contact_radius > 0.0, what, { "self_collision", radius_key },
                    "self_collision needs " + radius_key + " > 0: parts without thickness cannot keep apart");
  requireDefinition(self_friction >= 0.0, what, { "self_friction" }, "self_friction must be >= 0");
  requireDefinition(self_friction == 0.0 || self_collision, what, { "self_friction" },
                    "self_friction needs self_collision: true: parts that do not touch have no friction");
}

double maxContactRadius(const SceneDef& scene)
{
  double radius = 0.0;
  for (const BodyDef& body : scene.bodies)
    radius = std::max(radius, body.contact_radius);
  return radius;
}

World buildWorld(const SceneDef& scene)
{
  int node_count = 0;
  for (const BodyDef& body : scene.bodies)
    node_count += static_cast<int>(body.nodes.size());

  Model model;
  model.gravity = scene.physics.gravity;
  model.drag = scene.physics.drag;
  model.colliders = scene.colliders;
  model.mass.resize(node_count);
  model.inverse_mass.resize(node_count);
  model.contact_radius.resize(node_count);
  State state;
  std::vector<BodyController> controllers;
  state.position.resize(3, node_count);
  state.velocity.resize(3, node_count);

  int first = 0;
  for (const BodyDef& body : scene.bodies)
  {
    const int count = static_cast<int>(body.nodes.size());
    for (int k = 0; k < count; ++k)
    {
      const NodeDef& node = body.nodes[static_cast<std::size_t>(k)];
      model.mass[first + k] = node.mass;
      model.inverse_mass[first + k] = node.pinned ? 0.0 : 1.0 / node.mass;
      model.contact_radius[first + k] = body.contact_radius;
      state.position.col(first + k) = node.position;
      state.velocity.col(first + k) = node.velocity;
    }
    for (const SpringDef& s : body.springs)
    {
      const int a = globalIndex(body, first, s.a);
      const int b = globalIndex(body, first, s.b);
      model.springs.push_back({ a, b, restLengthOr(s.rest_length, state, a, b), s.stiffness, s.damping });
    }
    for (const ConstraintDef& c : body.constraints)
    {
      const int a = globalIndex(body, first, c.a);
      const int b = globalIndex(body, first, c.b);
      model.constraints.push_back({ a, b, restLengthOr(c.rest_length, state, a, b), c.compliance });
    }
    for (const CellDef& c : body.cells)
    {
      PressureCell cell;
      for (int k = 0; k < 4; ++k)
        cell.nodes[k] = globalIndex(body, first, c.nodes[k]);
      if (!(c.normal.norm() > 0.0))
        throw std::invalid_argument("body '" + body.name + "': cell normal must not be zero");
      cell.normal = c.normal.normalized();
      cell.pressure = c.pressure;
      cell.rest_area = c.rest_area ? *c.rest_area : cellArea(cell, state.position);
      if (!(cell.rest_area > 0.0) || !(cell.pressure > 0.0))
        throw std::invalid_argument("body '" + body.name + "': a cell needs a positive rest area (its nodes "
                                    "counter-clockwise about its normal) and a positive pressure");
      model.cells.push_back(cell);
    }
    for (const auto& [a, b] : body.contact_segments)
      model.contact_segments.emplace_back(globalIndex(body, first, a), globalIndex(body, first, b));
    for (const AnchorDef& anchor : body.anchors)
    {
      const int node = globalIndex(body, first, anchor.node);
      model.inverse_mass[node] = 0.0;
      model.anchors.push_back({ body.name, anchor.name, node, anchor.frame });
    }
    if (body.controller)
      controllers.push_back({ static_cast<int>(model.bodies.size()), body.controller(first) });
    requireSelfContact("body '" + body.name + "'", body.self_collision, body.self_friction, body.contact_radius,
                       "contact_radius");
    model.bodies.push_back({ body.name, first, count, body.self_collision, body.self_friction, body.springs_collide });
    first += count;
  }
  StepSettings step = scene.physics.step;
  if (scene.physics.auto_dt)
    step = chooseStableStep(model, state, scene.physics.integrator, step.iterations);
  World world(std::move(model), std::move(state), scene.physics.integrator, step, std::move(controllers));
  world.setGuard(scene.physics.guard);
  return world;
}

}  // namespace soft_body_sim
