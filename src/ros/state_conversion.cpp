// RosConverter: the state message, the holders of each body and the wrenches they take.
#include "soft_body_sim/ros/ros_converter.h"

#include <algorithm>

namespace soft_body_sim
{
namespace
{
/// The pose of the collider called `name`: a plane's from its point and normal, a shape's from `placed`
/// (World::colliderPoses), all zeros for a shape not placed yet.
geometry_msgs::Pose colliderPose(const Colliders& colliders, const std::vector<ColliderPose>& placed,
                                 const std::string& name)
{
  for (const Plane& plane : colliders.planes)
    if (plane.name == name)
      return RosConverter::toPose(RigidPose{ plane.point, Eigen::Quaterniond::FromTwoVectors(Vec3::UnitZ(), plane.normal) });
  for (const ColliderPose& shape : placed)
    if (shape.name == name)
      return RosConverter::toPose(RigidPose{ shape.position, shape.orientation });
  geometry_msgs::Pose none;
  none.orientation.w = 0.0;
  return none;
}
}  // namespace

std::vector<Holder> RosConverter::holders(const World& world)
{
  std::vector<Holder> holders;
  const Model& model = world.model();
  const std::vector<Wrench> anchors = world.anchorWrenches();
  for (std::size_t k = 0; k < anchors.size(); ++k)
  {
    const Anchor& anchor = model.anchors[k];
    holders.push_back({ model.bodyOf(anchor.node), anchor.name, world.state().position.col(anchor.node), anchors[k] });
  }
  const std::vector<Wrench> grasps = world.graspWrenches();
  for (std::size_t k = 0; k < grasps.size(); ++k)
  {
    const GraspedNodes& grasp = world.grasps()[k];
    holders.push_back({ grasp.body, grasp.name, grasp.pose.position, grasps[k] });
  }
  return holders;
}

geometry_msgs::WrenchStamped RosConverter::toWrench(const Wrench& wrench, const std::string& frame_id,
                                                    const ros::Time& stamp)
{
  geometry_msgs::WrenchStamped out;
  out.header.frame_id = frame_id;
  out.header.stamp = stamp;
  out.wrench.force = toVector3(wrench.force);
  out.wrench.torque = toVector3(wrench.torque);
  return out;
}

SimState RosConverter::toState(const World& world, const std::string& frame_id, const ros::Time& stamp,
                               const StepStatistics& statistics, const std::vector<Holder>& holders,
                               const std::vector<GraspSlip>& slips)
{
  const Model& model = world.model();
  const Eigen::VectorXd tension = world.linkTensions();
  SimState state;
  state.header.frame_id = frame_id;
  state.header.stamp = stamp;
  state.real_time_factor = statistics.real_time_factor;
  state.wall_seconds_per_step = statistics.wall_seconds_per_step;
  state.divergence_events = statistics.divergence_events;
  const std::vector<ColliderPose> placed = world.colliderPoses();
  for (const ColliderWrench& collider : world.colliderWrenches())
  {
    state.colliders.push_back(collider.name);
    geometry_msgs::Wrench wrench;
    wrench.force = toVector3(collider.wrench.force);
    wrench.torque = toVector3(collider.wrench.torque);
    state.collider_wrenches.push_back(wrench);
    state.collider_poses.push_back(colliderPose(model.colliders, placed, collider.name));
  }
  for (std::size_t b = 0; b < world.model().bodies.size(); ++b)
  {
    const BodyRange& range = world.model().bodies[b];
    BodyState body;
    body.name = range.name;
    body.integrator = integratorName(world.bodyIntegrator(b));
    body.divergence_events = static_cast<std::uint32_t>(world.divergenceCount(b));
    body.frozen = world.isFrozen(b);
    for (int i = range.first; i < range.first + range.count; ++i)
    {
      body.positions.push_back(toPoint(world.state().position.col(i)));
      body.velocities.push_back(toVector3(world.state().velocity.col(i)));
    }
    if (std::any_of(model.rods.begin(), model.rods.end(), [&](const Rod& rod) { return rod.first == range.first; }))
      for (int i = range.first; i < range.first + range.count; ++i)
        body.twists.push_back(world.state().twist[i]);
    for (const Holder& holder : holders)
      if (holder.body == b)
      {
        body.holders.push_back(holder.name);
        body.holder_points.push_back(toPoint(holder.origin));
        geometry_msgs::Wrench wrench;
        wrench.force = toVector3(holder.wrench.force);
        wrench.torque = toVector3(holder.wrench.torque);
        body.wrenches.push_back(wrench);
      }
    if (const std::optional<Vec3> target = world.target(b))
      body.target.push_back(toPoint(*target));
    for (const GraspSlip& slip : slips)
      if (slip.body == range.name)
        body.slips.push_back(slip.describe());
    state.bodies.push_back(body);
  }
  // A link belongs to the body of its first node; buildWorld adds each body's links in order.
  for (std::size_t k = 0; k < model.springs.size(); ++k)
    state.bodies[model.bodyOf(model.springs[k].a)].tensions.push_back(tension[static_cast<Eigen::Index>(k)]);
  for (std::size_t k = 0; k < model.constraints.size(); ++k)
    state.bodies[model.bodyOf(model.constraints[k].a)].tensions.push_back(
        tension[static_cast<Eigen::Index>(model.springs.size() + k)]);
  return state;
}

}  // namespace soft_body_sim
