#include "soft_body_sim/ros/state_viewer.h"

#include <algorithm>

#include "ros/node_parameters.h"
#include "soft_body_sim/ros/robot_colliders.h"
#include "soft_body_sim/ros/ros_converter.h"
#include "soft_body_sim/scene/scene_loader.h"

namespace soft_body_sim
{
StateViewer::StateViewer(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh) : nh_(nh), private_nh_(private_nh)
{
}

void StateViewer::initialize()
{
  const std::optional<std::string> scene = readParam<std::string>(private_nh_, "scene", "the path of a scene file");
  if (!scene)
    throw std::runtime_error(private_nh_.resolveName("scene") + ": parameter not set (the scene file of the recording)");
  scene_path_ = *scene;
  scene_ = loadSceneFile(scene_path_);
  world_ = std::make_unique<World>(buildWorld(scene_));
  force_scale_ = readParam<double>(private_nh_, "force_scale", "a finite number > 0 [m/N]", finitePositive)
                     .value_or(force_scale_);
  Colliders shapes = scene_.colliders;
  if (scene_.robot_colliders)
  {
    const std::string& param = scene_.robot_colliders->param;
    std::string urdf;
    if (!nh_.getParam(param, urdf))
      ROS_WARN("%s: robot_colliders.param: '%s' is not set: the robot's colliders are not drawn", scene_path_.c_str(),
               nh_.resolveName(param).c_str());
    else
    {
      std::vector<std::string> skipped;
      addRobotColliders(urdf, *scene_.robot_colliders, shapes, skipped);
    }
  }
  // As the simulator's contact stage holds them (makeColliderKinds): by kind, each in declaration order.
  for (const Sphere& s : shapes.spheres)
    colliders_.push_back(ColliderPose::of(s));
  for (const Capsule& c : shapes.capsules)
    colliders_.push_back(ColliderPose::of(c));
  for (const Box& b : shapes.boxes)
    colliders_.push_back(ColliderPose::of(b));
  for (const Cylinder& c : shapes.cylinders)
    colliders_.push_back(ColliderPose::of(c));
  for (const Mesh& m : shapes.meshes)
    colliders_.push_back(ColliderPose::of(m));
  publisher_ = nh_.advertise<visualization_msgs::MarkerArray>("markers", 1);
  force_publisher_ = nh_.advertise<visualization_msgs::MarkerArray>("force_markers", 1);
  subscriber_ = nh_.subscribe("state", 10, &StateViewer::onState, this);
  ROS_INFO("state viewer: scene %s, %d nodes in %zu bodies; drawing %s onto %s", scene_path_.c_str(),
           world_->model().nodeCount(), world_->model().bodies.size(), subscriber_.getTopic().c_str(),
           publisher_.getTopic().c_str());
}

bool StateViewer::draw(const SimState& message, visualization_msgs::MarkerArray& markers,
                       visualization_msgs::MarkerArray& force_markers, std::string& why) const
{
  const Model& model = world_->model();
  if (message.bodies.size() != model.bodies.size())
  {
    why = std::to_string(message.bodies.size()) + " bodies where the scene has " + std::to_string(model.bodies.size());
    return false;
  }
  State state;
  state.position.resize(3, model.nodeCount());
  state.velocity.setZero(3, model.nodeCount());
  if (!model.rods.empty())
    state.twist.setZero(model.nodeCount());
  for (std::size_t b = 0; b < model.bodies.size(); ++b)
  {
    const BodyRange& range = model.bodies[b];
    const BodyState& body = message.bodies[b];
    if (body.name != range.name || body.positions.size() != static_cast<std::size_t>(range.count))
    {
      why = "body " + std::to_string(b) + " is '" + body.name + "' of " + std::to_string(body.positions.size()) +
            " nodes where the scene has '" + range.name + "' of " + std::to_string(range.count);
      return false;
    }
    for (int i = 0; i < range.count; ++i)
      state.position.col(range.first + i) = RosConverter::toVec3(body.positions[static_cast<std::size_t>(i)]);
    if (state.twist.size() > 0 && body.twists.size() == static_cast<std::size_t>(range.count))
      for (int i = 0; i < range.count; ++i)
        state.twist[range.first + i] = body.twists[static_cast<std::size_t>(i)];
  }
  if (!state.position.allFinite())
  {
    why = "a position is not finite";
    return false;
  }
  // A named collider where the message has it (left out while not placed), any other where the scene has it.
  std::vector<ColliderPose> colliders;
  for (const ColliderPose& collider : colliders_)
  {
    const auto named = std::find(message.colliders.begin(), message.colliders.end(), collider.name);
    const std::size_t k = static_cast<std::size_t>(named - message.colliders.begin());
    if (collider.name.empty() || k >= message.collider_poses.size())
    {
      colliders.push_back(collider);
      continue;
    }
    if (const std::optional<RigidPose> pose = RosConverter::toRigidPose(message.collider_poses[k]))
    {
      colliders.push_back(collider);
      colliders.back().position = pose->position;
      colliders.back().orientation = pose->orientation;
    }
  }
  markers = RosConverter::toMarkers(model, state, world_->controllers(), colliders, message.header.frame_id,
                                    message.header.stamp);
  // The holders body by body (the simulator numbers its arrows anchors first, then grasps: the same arrows).
  std::vector<Holder> holders;
  for (std::size_t b = 0; b < message.bodies.size(); ++b)
  {
    const BodyState& body = message.bodies[b];
    for (std::size_t k = 0; k < body.holders.size() && k < body.holder_points.size() && k < body.wrenches.size(); ++k)
      holders.push_back({ b, body.holders[k], RosConverter::toVec3(body.holder_points[k]),
                          Wrench{ RosConverter::toVec3(body.wrenches[k].force), RosConverter::toVec3(body.wrenches[k].torque) } });
  }
  force_markers = RosConverter::toForceMarkers(holders, force_scale_, message.header.frame_id, message.header.stamp);
  return true;
}

void StateViewer::onState(const SimState& message)
{
  visualization_msgs::MarkerArray markers, force_markers;
  std::string why;
  if (!draw(message, markers, force_markers, why))
  {
    ROS_ERROR_THROTTLE(5.0, "state viewer: %s at %.3f: %s (is %s the recording's scene?); not drawn",
                       subscriber_.getTopic().c_str(), message.header.stamp.toSec(), why.c_str(), scene_path_.c_str());
    return;
  }
  publisher_.publish(markers);
  force_publisher_.publish(force_markers);
}

}  // namespace soft_body_sim
