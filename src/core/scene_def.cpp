#include "soft_body_sim/core/scene_def.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "soft_body_sim/core/stability.h"

#include "core/elements/element_kinds.h"

#include "soft_body_sim/core/elements/forces.h"
#include "soft_body_sim/core/elements/rods.h"
#include "soft_body_sim/core/elements/tetrahedra.h"

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

/// How body `index` of the scene looks (Look): its faces, else its solid surface, else its contact
/// segments, else its links; its other nodes as balls. `first` is its first global node.
Look lookOf(const BodyDef& body, std::size_t index, int first, const std::vector<std::array<int, 3>>& surface)
{
  Look look;
  look.radius = body.contact_radius > 0.0 ? body.contact_radius : kDefaultLookRadius;
  look.color = body.color.value_or(defaultBodyColor(index));
  const auto global = [&](int local) { return globalIndex(body, first, local); };
  look.faces.reserve(body.faces.size());  // a 100,000-node cloth's faces grown by doubling held 8 bytes a node more
  for (const std::array<int, 3>& face : body.faces)
    look.faces.push_back({ global(face[0]), global(face[1]), global(face[2]) });
  if (look.faces.empty())
    look.faces = surface;
  if (look.faces.empty())
  {
    for (const auto& [a, b] : body.contact_segments)
      look.tubes.emplace_back(global(a), global(b));
    if (look.tubes.empty())
    {
      for (const SpringDef& spring : body.springs)
        look.tubes.emplace_back(global(spring.a), global(spring.b));
      for (const ConstraintDef& constraint : body.constraints)
        look.tubes.emplace_back(global(constraint.a), global(constraint.b));
    }
  }
  std::vector<bool> seen(body.nodes.size(), false);
  for (const std::array<int, 3>& face : look.faces)
    for (const int node : face)
      seen[static_cast<std::size_t>(node - first)] = true;
  for (const auto& [a, b] : look.tubes)
    seen[static_cast<std::size_t>(a - first)] = seen[static_cast<std::size_t>(b - first)] = true;
  for (std::size_t k = 0; k < seen.size(); ++k)
    if (!seen[k])
      look.balls.push_back(first + static_cast<int>(k));
  return look;
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

std::optional<TunnellingRisk> tunnellingRisk(const SceneDef& scene, const StepSettings& step)
{
  const double g = scene.physics.gravity.norm();
  const Vec3 up = g > 0.0 ? Vec3(-scene.physics.gravity / g) : Vec3::UnitZ();
  const double h = step.dt / step.substeps;
  for (std::size_t b = 0; b < scene.bodies.size(); ++b)
  {
    const BodyDef& body = scene.bodies[b];
    if (!body.self_collision || !(body.contact_radius > 0.0))
      continue;
    std::vector<bool> held(body.nodes.size(), false);  // pinned or anchored: they do not fall
    for (std::size_t k = 0; k < body.nodes.size(); ++k)
      held[k] = body.nodes[k].pinned;
    for (const AnchorDef& anchor : body.anchors)
      held[static_cast<std::size_t>(resolveNodeIndex(anchor.node, static_cast<int>(body.nodes.size())))] = true;
    double fall = 0.0, initial = 0.0;
    for (std::size_t k = 0; k < body.nodes.size(); ++k)
    {
      const NodeDef& node = body.nodes[k];
      initial = std::max(initial, node.velocity.norm());
      if (held[k])
        continue;
      double below = kUnsupportedFall;  // down to the first plane under it that faces up
      bool supported = false;
      for (const Plane& plane : scene.colliders.planes)
      {
        const double facing = plane.normal.dot(up);
        const double height = (node.position - plane.point).dot(plane.normal) / facing;
        if (facing > 0.0 && height >= 0.0 && (!supported || height < below))
        {
          below = height;
          supported = true;
        }
      }
      fall = std::max(fall, below);
    }
    const double speed = std::sqrt(2.0 * g * fall) + initial;
    if (speed * h <= body.contact_radius)
      continue;
    TunnellingRisk risk;
    risk.body = b;
    const double needed = std::ceil(speed * step.dt / body.contact_radius);
    constexpr int kMost = 1000000;  // a bound for absurd scenes (a node 1e300 m up), not a count to use
    risk.substeps = needed < kMost ? static_cast<int>(needed) : kMost;
    char numbers[400];
    std::snprintf(numbers, sizeof numbers,
                  "a fall of %.3g m (its highest free node onto the first floor below, or %g m without one) and "
                  "its initial speeds give %.3g m/s, %.3g mm per sub-step of %.3g ms, more than its contact radius "
                  "%.3g mm: its parts could pass through each other; needs substeps >= %d at dt %g s",
                  fall, kUnsupportedFall, speed, 1e3 * speed * h, 1e3 * h, 1e3 * body.contact_radius, risk.substeps,
                  step.dt);
    risk.why = "body '" + body.name + "' (self_collision): " + numbers;
    return risk;
  }
  return std::nullopt;
}

World buildWorld(const SceneDef& scene)
{
  int node_count = 0;
  std::size_t spring_count = 0, constraint_count = 0;
  for (const BodyDef& body : scene.bodies)
  {
    node_count += static_cast<int>(body.nodes.size());
    spring_count += body.springs.size();
    constraint_count += body.constraints.size();
  }

  Model model;
  // Their exact lengths: grown by doubling, a 100,000-node cloth's 596,000 springs held capacity for 1.75
  // times as many (14.5 MB, 145 bytes a node, of memory_footprint's heap).
  model.springs.reserve(spring_count);
  model.constraints.reserve(constraint_count);
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
    // A generated body's builder (buildRope, buildJelly, ...) checked its definition, at the keys that set
    // it (a rope's `radius`, a jelly's `pressure`); a custom body is its own definition, checked here.
    const bool custom = body.type == "custom";
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
      if (!(cell.rest_area > 0.0) || (custom && !(cell.pressure > 0.0)))
        throw std::invalid_argument("body '" + body.name + "': a cell needs a positive rest area (its nodes "
                                    "counter-clockwise about its normal) and a positive pressure");
      model.cells.push_back(cell);
    }
    if (body.rod)
    {
      Rod rod = *body.rod;
      rod.first += first;
      for (RodStation& station : rod.stations)
      {
        station.first += first;
        station.last += first;
      }
      // An anchor holds its orientation as well as its position: a gripper turns and bends the rod there.
      for (const AnchorDef& anchor : body.anchors)
        clampRod(rod, globalIndex(body, first, anchor.node));
      if (!rod.end_moment.isZero(0.0) && !rod.stations.empty() && rod.stations.back().last == rod.last())
        throw std::invalid_argument("body '" + body.name + "': end_moment acts on a free last node, but its "
                                    "last node is clamped or anchored (the holder takes any moment there)");
      model.rods.push_back(rod);
    }
    for (Tetrahedron tet : body.tetrahedra)
    {
      for (int& node : tet.nodes)
        node = globalIndex(body, first, node);
      model.tetrahedra.push_back(tet);
    }
    std::vector<std::array<int, 3>> surface = body.surface;
    for (std::array<int, 3>& triangle : surface)
      for (int& node : triangle)
        node = globalIndex(body, first, node);
    for (SurfaceSample sample : body.surface_samples)
    {
      for (int& node : sample.triangle)
        node = globalIndex(body, first, node);
      model.surface_samples.push_back(sample);
    }
    for (const auto& [a, b] : body.contact_segments)
      model.contact_segments.emplace_back(globalIndex(body, first, a), globalIndex(body, first, b));
    for (const std::array<int, 3>& triangle : body.contact_triangles)
      model.contact_triangles.push_back({ globalIndex(body, first, triangle[0]), globalIndex(body, first, triangle[1]),
                                          globalIndex(body, first, triangle[2]) });
    for (const AnchorDef& anchor : body.anchors)
    {
      const int node = globalIndex(body, first, anchor.node);
      model.inverse_mass[node] = 0.0;
      model.anchors.push_back({ body.name, anchor.name, node, anchor.frame });
    }
    if (body.controller)
      controllers.push_back({ static_cast<int>(model.bodies.size()), body.controller(first) });
    if (custom)
      requireSelfContact("body '" + body.name + "'", body.self_collision, body.self_friction, body.contact_radius,
                         "contact_radius");
    Look look = lookOf(body, model.bodies.size(), first, surface);
    model.bodies.push_back({ body.name, first, count, body.self_collision, body.self_friction, body.springs_collide,
                             std::move(surface), body.surface_friction, std::move(look) });
    first += count;
  }
  try
  {
    requireIntegratorRunsModel(model, scene.physics.integrator);
  }
  catch (const std::invalid_argument& e)
  {
    throw std::invalid_argument(std::string("physics.integrator: ") + e.what());
  }
  if (!model.rods.empty())
    state.twist.setZero(model.nodeCount());
  StepSettings step = scene.physics.step;
  if (scene.physics.auto_dt)
  {
    step = chooseStableStep(model, state, scene.physics.integrator, step.iterations);
    // and the sub-steps that keep the rule against passing through
    for (std::optional<TunnellingRisk> risk = tunnellingRisk(scene, step); risk && risk->substeps > step.substeps;
         risk = tunnellingRisk(scene, step))
      step.substeps = risk->substeps;
  }
  World world(std::move(model), std::move(state), scene.physics.integrator, step, std::move(controllers));
  world.setGuard(scene.physics.guard);
  return world;
}

}  // namespace soft_body_sim
