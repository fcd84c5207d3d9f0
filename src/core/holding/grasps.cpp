#include "soft_body_sim/core/holding/grasps.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "soft_body_sim/core/elements/rods.h"
#include "soft_body_sim/core/format_number.h"

namespace soft_body_sim
{
namespace
{
/// `pose` with its orientation normalised (slerp and the offsets' rotation assume a unit quaternion).
RigidPose unit(const RigidPose& pose) { return RigidPose{ pose.position, pose.orientation.normalized() }; }
}  // namespace

std::string GraspSlip::describe() const
{
  char text[128];
  std::snprintf(text, sizeof text, "' slipped at t = %.6g s: force %.6g N > max_force %.6g N", time, force, max_force);
  return "grasp '" + grasp + "' on body '" + body + text;
}

std::size_t GraspSet::grasp(Model& model, State& state, const std::string& name, const std::string& body,
                            const RigidPose& pose, double radius, double max_force)
{
  if (find(name) < grasps_.size())
    throw std::invalid_argument("there is a grasp '" + name + "' already (release it first)");
  if (!(radius > 0.0 && std::isfinite(radius)))
    throw std::invalid_argument("radius must be a finite number > 0 [m]");
  if (!(max_force > 0.0))
    throw std::invalid_argument("max_force must be > 0 [N] (infinity: no limit)");
  std::size_t b = 0;
  while (b < model.bodies.size() && model.bodies[b].name != body)
    ++b;
  if (b == model.bodies.size())
    throw std::invalid_argument("there is no body '" + body + "'");
  GraspedNodes g{ name, b, {}, {}, unit(pose), {}, max_force };
  const Eigen::Quaterniond to_frame = g.pose.orientation.conjugate();
  const BodyRange& range = model.bodies[b];
  for (int i = range.first; i < range.first + range.count; ++i)
    if (model.isFree(i) && (state.position.col(i) - pose.position).norm() <= radius)
    {
      g.nodes.push_back(i);
      g.offsets.push_back(to_frame * (state.position.col(i) - pose.position));
    }
  if (g.nodes.empty())
    throw std::invalid_argument("no free node of body '" + body + "' within " + formatNumber(radius) + " m of the frame's origin");
  // Pinned = inverse mass 0: from now on only the grasp moves them (Ten Minute Physics' grab).
  for (const int node : g.nodes)
    model.inverse_mass[node] = 0.0;
  for (Rod& rod : model.rods)
    if (rod.first == range.first)
      for (std::size_t k = 0; k < g.nodes.size();)
      {
        // g.nodes ascend: each run of consecutive nodes is one station.
        std::size_t end = k + 1;
        while (end < g.nodes.size() && g.nodes[end] == g.nodes[end - 1] + 1)
          ++end;
        holdRod(rod, state.position, state.twist, g.nodes[k], g.nodes[end - 1], g.pose.orientation);
        g.rod_stations.push_back(g.nodes[k]);
        k = end;
      }
  grasps_.push_back(std::move(g));
  goals_.emplace_back();
  paths_.emplace_back();
  return grasps_.back().nodes.size();
}

bool GraspSet::release(Model& model, State& state, const std::string& name, bool frozen)
{
  const std::size_t k = find(name);
  if (k == grasps_.size())
    return false;
  for (const int node : grasps_[k].rod_stations)
  {
    const StationIndex at = findRodStation(model, node);
    releaseRod(model.rods[static_cast<std::size_t>(at.rod)], state.position, state.twist, at.station);
  }
  for (const int node : grasps_[k].nodes)
    model.releaseNode(node, frozen);
  const auto at = static_cast<std::ptrdiff_t>(k);
  grasps_.erase(grasps_.begin() + at);
  goals_.erase(goals_.begin() + at);
  paths_.erase(paths_.begin() + at);
  return true;
}

bool GraspSet::setGoal(const std::string& name, const RigidPose& pose)
{
  const std::size_t k = find(name);
  if (k == grasps_.size())
    return false;
  goals_[k] = unit(pose);
  return true;
}

void GraspSet::carry(StateArchive& archive)
{
  if (!archive.reading())
  {
    archive(grasps_, goals_);
    return;
  }
  std::vector<std::string> names_before;
  for (const GraspedNodes& grasp : grasps_)
    names_before.push_back(grasp.name);
  std::vector<GraspPath> paths_before = std::move(paths_);
  archive(grasps_, goals_);
  paths_.assign(grasps_.size(), GraspPath{});
  for (std::size_t k = 0; k < names_before.size(); ++k)
    if (const std::size_t now = find(names_before[k]); now < grasps_.size())
      paths_[now] = std::move(paths_before[k]);
}

bool GraspSet::followPath(const std::string& name, GraspPath path)
{
  const std::size_t k = find(name);
  if (k == grasps_.size())
    return false;
  paths_[k] = std::move(path);
  return true;
}

void GraspSet::goalsFromPaths(double t)
{
  for (std::size_t k = 0; k < grasps_.size(); ++k)
    if (paths_[k] && !goals_[k])
      if (const std::optional<RigidPose> pose = paths_[k](t))
        goals_[k] = unit(*pose);
}

std::size_t GraspSet::find(const std::string& name) const
{
  std::size_t k = 0;
  while (k < grasps_.size() && grasps_[k].name != name)
    ++k;
  return k;
}

RigidPose GraspSet::at(std::size_t k, double s) const
{
  const RigidPose& from = grasps_[k].pose;
  if (!goals_[k])
    return from;
  return RigidPose{ from.position + s * (goals_[k]->position - from.position),
                    from.orientation.slerp(s, goals_[k]->orientation) };
}

void GraspSet::advance(Model& model, State& state, int substep, int substeps, double h) const
{
  const double s = static_cast<double>(substep) / substeps;
  for (std::size_t k = 0; k < grasps_.size(); ++k)
  {
    const GraspedNodes& g = grasps_[k];
    const RigidPose pose = at(k, s);
    for (const int node : g.rod_stations)
      rodStation(model, findRodStation(model, node)).turn(pose.orientation);
    for (std::size_t n = 0; n < g.nodes.size(); ++n)
    {
      const Vec3 x = pose.position + pose.orientation * g.offsets[n];
      state.velocity.col(g.nodes[n]) = (x - state.position.col(g.nodes[n])) / h;
      state.position.col(g.nodes[n]) = x;
    }
  }
}

void GraspSet::land()
{
  for (std::size_t k = 0; k < grasps_.size(); ++k)
    if (goals_[k])
    {
      grasps_[k].pose = *goals_[k];
      goals_[k].reset();
    }
}

std::vector<Wrench> GraspSet::wrenches(const Model& model, const State& state, const NodeArray& pull) const
{
  std::vector<Wrench> wrenches;
  for (const GraspedNodes& g : grasps_)
  {
    wrenches.push_back(holdingWrench(model, state.position, pull, g.nodes, g.pose.position));
    for (const int node : g.rod_stations)
    {
      const StationIndex at = findRodStation(model, node);
      wrenches.back().torque +=
          stationTorque(model.rods[static_cast<std::size_t>(at.rod)], at.station, state.position, state.twist);
    }
  }
  return wrenches;
}

bool GraspSet::limited() const
{
  for (const GraspedNodes& g : grasps_)
    if (std::isfinite(g.max_force))
      return true;
  return false;
}

}  // namespace soft_body_sim
