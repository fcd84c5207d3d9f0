#include "python/holder.h"

#include "python/names.h"
#include "soft_body_sim/core/elements/rods.h"

namespace soft_body_sim::python
{
Holder Holder::find(const World& world, const std::string& name)
{
  Holder holder;
  for (const GraspedNodes& grasp : world.grasps())
    if (grasp.name == name)
    {
      holder.grasp_ = name;
      return holder;
    }
  const std::size_t slash = name.find('/');
  if (slash != std::string::npos)
    if (const std::optional<int> k = world.findAnchor(name.substr(0, slash), name.substr(slash + 1)))
    {
      holder.anchor_ = *k;
      return holder;
    }
  std::vector<std::string> anchors, grasps;
  for (const Anchor& anchor : world.model().anchors)
    anchors.push_back(anchor.body + "/" + anchor.name);
  for (const GraspedNodes& grasp : world.grasps())
    grasps.push_back(grasp.name);
  throw UnknownName("no anchor or grasp '" + name + "'; anchors (\"body/anchor\"): " + listed(anchors) +
                    "; grasps' frames: " + listed(grasps));
}

RigidPose Holder::pose(const World& world) const
{
  if (!anchor_)
    return world.grasps()[findGrasp(world, grasp_)].pose;
  const int node = world.model().anchors[static_cast<std::size_t>(*anchor_)].node;
  RigidPose pose;
  pose.position = world.state().position.col(node);
  // As AnchorSet::setVelocities reads the orientation a rod's end turns from.
  if (const StationIndex at = findRodStation(world.model(), node))
  {
    const RodStation& station = rodStation(world.model(), at);
    pose.orientation = station.frame[0] * station.held[0].conjugate();
  }
  return pose;
}

void Holder::move(World& world, const RigidPose& pose, bool turn) const
{
  if (!anchor_)
    world.moveGrasp(grasp_, pose);
  else if (turn)
    world.moveAnchor(*anchor_, pose.position, pose.orientation);
  else
    world.moveAnchor(*anchor_, pose.position);
}

}  // namespace soft_body_sim::python
