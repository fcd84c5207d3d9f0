// SimNode's inputs: pose topics and rviz handles scheduled by stamp, anchors following tf frames, and
// grasping with ~attach / ~detach.
#include <cmath>

#include <tf2_geometry_msgs/tf2_geometry_msgs.h>

#include "soft_body_sim/ros/sim_node.h"

namespace soft_body_sim
{
namespace
{
/// An input stamped further ahead than this is taken as a clock mix-up (e.g. sim-time stamps into a
/// wall-clock node) and applied now rather than held for ever.
constexpr double kMaxLead = 5.0;  // [s]
}  // namespace

void SimNode::subscribeInputs()
{
  for (std::size_t k = 0; k < world_->model().anchors.size(); ++k)
  {
    const Anchor& anchor = world_->model().anchors[k];
    const std::string topic = private_nh_.resolveName(anchor.body + "/" + anchor.name + "/pose");
    const int id = static_cast<int>(k);
    subscribers_.push_back(private_nh_.subscribe<geometry_msgs::PoseStamped>(
        topic, 10, [this, topic, id](const geometry_msgs::PoseStamped::ConstPtr& pose) {
          ScheduledInput input;
          input.kind = ScheduledInput::Kind::Anchor;
          input.anchor = id;
          if (toSceneFrame(*pose, topic, input.position))
            schedule(topic, pose->header.stamp, input);
        }));
  }
  for (const BodyDef& body : scene_.bodies)
  {
    if (body.type != "creature" && body.type != "humanoid")
      continue;
    const std::string topic = private_nh_.resolveName(body.name + "/target");
    const std::string name = body.name;
    subscribers_.push_back(private_nh_.subscribe<geometry_msgs::PoseStamped>(
        topic, 10, [this, topic, name](const geometry_msgs::PoseStamped::ConstPtr& pose) {
          ScheduledInput input;
          input.kind = ScheduledInput::Kind::Target;
          input.body = name;
          if (toSceneFrame(*pose, topic, input.position))
            schedule(topic, pose->header.stamp, input);
        }));
  }
}

void SimNode::addHandles()
{
  handles_ = std::make_unique<AnchorHandles>(private_nh_.resolveName("handles"), scene_.frame_id);
  const Model& model = world_->model();
  handle_names_.assign(model.anchors.size(), "");
  for (const BodyDef& body : scene_.bodies)
    for (const AnchorDef& def : body.anchors)
    {
      if (!def.frame.empty())
        continue;  // it follows its tf frame
      const int k = *world_->findAnchor(body.name, def.name);
      const std::string name = body.name + "/" + def.name;
      handle_names_[static_cast<std::size_t>(k)] = name;
      handles_->add(name, private_nh_.resolveName(name + "/pose"), world_->state().position.col(model.anchors[k].node));
    }
  for (std::size_t b = 0; b < scene_.bodies.size(); ++b)
  {
    const BodyDef& body = scene_.bodies[b];
    if (body.type != "creature" && body.type != "humanoid")
      continue;
    // Until a target is set, the handle waits at the body's first node (lead, pelvis).
    const std::string name = body.name + "/target";
    handles_->add(name, private_nh_.resolveName(name), world_->state().position.col(model.bodies[b].first));
    target_handles_.emplace_back(body.name, name);
  }
  handles_->applyChanges();
}

void SimNode::schedule(const std::string& topic, const ros::Time& stamp, const ScheduledInput& input)
{
  const ros::Time now = ros::Time::now();
  ros::Time when = stamp.isZero() ? now : stamp;
  if ((when - now).toSec() > kMaxLead)
  {
    ROS_WARN_THROTTLE(5.0, "%s: stamp %.3f s ahead of the ROS clock (a clock mix-up?): applied now", topic.c_str(),
                      (when - now).toSec());
    when = now;
  }
  inputs_.push(when, input);
}

void SimNode::applyDueInputs(const ros::Time& step_end)
{
  for (const ScheduledInput& input : inputs_.due(step_end))
  {
    if (input.kind == ScheduledInput::Kind::Anchor)
    {
      world_->moveAnchor(input.anchor, input.position);
      continue;
    }
    world_->setTarget(input.body, input.position);
    bool known = false;
    for (auto& [body, target] : targets_)
      if (body == input.body)
      {
        target = input.position;
        known = true;
      }
    if (!known)
      targets_.emplace_back(input.body, input.position);
  }
}

bool SimNode::toSceneFrame(const geometry_msgs::PoseStamped& pose, const std::string& topic, Vec3& position)
{
  std::string why;
  if (!RosConverter::fromPose(pose.pose, position, why))
  {
    ROS_WARN_THROTTLE(5.0, "%s: pose dropped: %s", topic.c_str(), why.c_str());
    return false;
  }
  if (pose.header.frame_id.empty())
  {
    ROS_WARN_THROTTLE(5.0, "%s: pose dropped: empty header.frame_id", topic.c_str());
    return false;
  }
  if (pose.header.frame_id == scene_.frame_id)
    return true;  // no lookup: the same with or without tf data
  try
  {
    geometry_msgs::PoseStamped in_scene;
    try
    {
      tf_buffer_.transform(pose, in_scene, scene_.frame_id);
    }
    catch (const tf2::ExtrapolationException&)
    {
      // Stamped just past the latest transform (it is still on its way): use the latest.
      geometry_msgs::PoseStamped latest = pose;
      latest.header.stamp = ros::Time(0);
      tf_buffer_.transform(latest, in_scene, scene_.frame_id);
    }
    if (!RosConverter::fromPose(in_scene.pose, position, why))
    {
      ROS_WARN_THROTTLE(5.0, "%s: pose dropped after the transform to '%s': %s", topic.c_str(),
                        scene_.frame_id.c_str(), why.c_str());
      return false;
    }
  }
  catch (const tf2::TransformException& e)
  {
    ROS_WARN_THROTTLE(5.0, "%s: pose dropped: no transform from '%s' to '%s': %s", topic.c_str(),
                      pose.header.frame_id.c_str(), scene_.frame_id.c_str(), e.what());
    return false;
  }
  return true;
}

std::optional<Vec3> SimNode::frameOrigin(const std::string& frame, const ros::Time& stamp)
{
  geometry_msgs::TransformStamped transform;
  try
  {
    try
    {
      transform = tf_buffer_.lookupTransform(scene_.frame_id, frame, stamp);
    }
    catch (const tf2::ExtrapolationException&)
    {
      transform = tf_buffer_.lookupTransform(scene_.frame_id, frame, ros::Time(0));
    }
  }
  catch (const tf2::TransformException& e)
  {
    ROS_WARN_THROTTLE(5.0, "%s: no transform from '%s' to '%s' yet: %s", name_.c_str(), frame.c_str(),
                      scene_.frame_id.c_str(), e.what());
    return std::nullopt;
  }
  const geometry_msgs::Vector3& t = transform.transform.translation;
  const Vec3 origin(t.x, t.y, t.z);
  if (!origin.allFinite())
    return std::nullopt;
  return origin;
}

void SimNode::followFrame(int anchor, const std::string& frame)
{
  // The path is asked for the step's end: the frame's pose at that ROS time, interpolated by tf.
  world_->followPath(anchor, [this, frame](double t) { return frameOrigin(frame, rosTime(t)); });
}

bool SimNode::onAttach(Attach::Request& request, Attach::Response& response)
{
  const auto refuse = [&](const std::string& why) {
    response.success = false;
    response.message = why;
    ROS_WARN("%s: attach refused: %s", name_.c_str(), why.c_str());
    return true;
  };
  if (request.frame.empty())
    return refuse("no frame given");
  if (!(request.radius > 0.0 && std::isfinite(request.radius)))
    return refuse("radius must be a finite number > 0 [m]");
  for (const Anchor& anchor : world_->model().anchors)
    if (anchor.name == request.frame && world_->isAttached(*world_->findAnchor(anchor.body, anchor.name)))
      return refuse("frame '" + request.frame + "' already holds a node of '" + anchor.body + "'");
  const std::optional<Vec3> origin = frameOrigin(request.frame, ros::Time(0));
  if (!origin)
    return refuse("no transform from '" + request.frame + "' to '" + scene_.frame_id + "'");
  const std::optional<int> node = world_->nearestFreeNode(*origin, request.body, request.radius);
  if (!node)
    return refuse("no free node" + (request.body.empty() ? std::string() : " of '" + request.body + "'") + " within " +
                  std::to_string(request.radius) + " m of '" + request.frame + "'");
  const int anchor = world_->attach(*node, request.frame);
  followFrame(anchor, request.frame);
  const Anchor& made = world_->model().anchors[static_cast<std::size_t>(anchor)];
  int first = 0;
  for (const BodyRange& body : world_->model().bodies)
    if (body.name == made.body)
      first = body.first;
  response.success = true;
  response.anchor = made.name;
  response.node = *node - first;
  response.message = "'" + request.frame + "' holds node " + std::to_string(response.node) + " of '" + made.body + "'";
  ROS_INFO("%s: %s", name_.c_str(), response.message.c_str());
  return true;
}

bool SimNode::onDetach(Detach::Request& request, Detach::Response& response)
{
  const std::vector<Anchor>& anchors = world_->model().anchors;
  for (std::size_t k = 0; k < anchors.size(); ++k)
    if (anchors[k].name == request.frame && world_->isAttached(static_cast<int>(k)))
    {
      const std::string body = anchors[k].body;
      world_->detach(static_cast<int>(k));
      response.success = true;
      response.message = "'" + request.frame + "' released '" + body + "'";
      ROS_INFO("%s: %s", name_.c_str(), response.message.c_str());
      return true;
    }
  response.success = false;
  response.message = "frame '" + request.frame + "' holds nothing";
  return true;
}

}  // namespace soft_body_sim
