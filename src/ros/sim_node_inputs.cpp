// SimNode's inputs: pose topics and rviz handles scheduled by stamp, anchors following tf frames, and
// grasping with ~attach / ~detach (one node) and ~grasp / ~release (a gripper's width). Whatever arrives
// is checked before it reaches the world: a refused input or request is named in a (throttled) warning
// and changes nothing.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>

#include <tf2_geometry_msgs/tf2_geometry_msgs.h>

#include "ros/node_parameters.h"
#include "soft_body_sim/core/elements/rods.h"
#include "soft_body_sim/core/format_number.h"
#include "soft_body_sim/ros/sim_node.h"

namespace soft_body_sim
{
namespace
{
/// Messages a pose topic may queue between two turns of the node's spinner. Not 1, the ROS habit for
/// "latest wins": every stamped input has a step of its own, and a replay is exact only if none is lost
/// while a tick holds the spinner (100 covers a 1 kHz source for 100 ms). Under a flood roscpp drops
/// the oldest beyond it, so the latest still wins and memory stays bounded.
constexpr int kInputQueueSize = 100;
/// tf frame and body names longer than this are refused by their length alone, so that a huge string
/// in a request never reaches tf2 or a log line.
constexpr std::size_t kMaxNameLength = 256;
/// [s] of simulated time during which a tf frame that a collider or anchor follows may still be missing
/// without a warning (its publisher starting up).
constexpr double kFrameGraceSeconds = 5.0;

/// Why `name` cannot be a tf frame or body name (`what` says which), or empty.
std::string badName(const std::string& what, const std::string& name)
{
  if (name.size() > kMaxNameLength)
    return what + " of " + std::to_string(name.size()) + " characters (at most " + std::to_string(kMaxNameLength) + ")";
  // A newline or escape in a name would forge or garble the log lines that quote it.
  for (const char c : name)
    if (std::iscntrl(static_cast<unsigned char>(c)))
      return what + " holds a control character";
  return std::string();
}
}  // namespace

InputLimits SimNode::readInputLimits() const
{
  const std::string seconds = "a finite number of seconds > 0";
  InputLimits limits;
  limits.max_age = readParam<double>(private_nh_, "max_input_age", seconds, finitePositive).value_or(limits.max_age);
  limits.max_lead =
      readParam<double>(private_nh_, "max_input_lead", seconds, finitePositive).value_or(limits.max_lead);
  limits.max_held = static_cast<std::size_t>(
      readParam<int>(private_nh_, "max_held_inputs", "an integer >= 1", [](const int& n) { return n >= 1; })
          .value_or(static_cast<int>(limits.max_held)));
  return limits;
}

void SimNode::subscribeInputs()
{
  inputs_.setLimits(readInputLimits());
  max_input_interval_ = readParam<double>(private_nh_, "max_input_interval", "a finite number of seconds >= 0",
                                          finiteNonNegative)
                            .value_or(max_input_interval_);
  for (std::size_t k = 0; k < world_->model().anchors.size(); ++k)
  {
    const Anchor& anchor = world_->model().anchors[k];
    const std::string topic = private_nh_.resolveName(anchor.body + "/" + anchor.name + "/pose");
    const int id = static_cast<int>(k);
    subscribers_.push_back(private_nh_.subscribe<geometry_msgs::PoseStamped>(
        topic, kInputQueueSize, [this, topic, id](const geometry_msgs::PoseStamped::ConstPtr& pose) {
          ScheduledInput input;
          input.kind = ScheduledInput::Kind::Anchor;
          input.anchor = id;
          if (toSceneFrame(*pose, topic, input.position, &input.orientation))
            schedule(topic, pose->header.stamp, input);
        }));
  }
  const Model& model = world_->model();
  for (std::size_t b = 0; b < model.bodies.size(); ++b)
  {
    if (!world_->takesTarget(b))
      continue;
    const std::string name = model.bodies[b].name;
    const std::string topic = private_nh_.resolveName(name + "/target");
    subscribers_.push_back(private_nh_.subscribe<geometry_msgs::PoseStamped>(
        topic, kInputQueueSize, [this, topic, name](const geometry_msgs::PoseStamped::ConstPtr& pose) {
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
  for (std::size_t k = 0; k < model.anchors.size(); ++k)
  {
    const Anchor& anchor = model.anchors[k];
    if (!anchor.frame.empty())
      continue;  // it follows its tf frame
    const std::string name = anchor.body + "/" + anchor.name;
    handle_names_[k] = name;
    handles_->add(name, private_nh_.resolveName(name + "/pose"), world_->state().position.col(anchor.node));
  }
  for (std::size_t b = 0; b < model.bodies.size(); ++b)
  {
    if (!world_->takesTarget(b))
      continue;
    // Until a target is set, the handle waits at the body's first node (lead, pelvis).
    const std::string name = model.bodies[b].name + "/target";
    handles_->add(name, private_nh_.resolveName(name), world_->state().position.col(model.bodies[b].first));
    target_handles_.emplace_back(model.bodies[b].name, name);
  }
  handles_->applyChanges();
}

void SimNode::schedule(const std::string& topic, const ros::Time& stamp, const ScheduledInput& input)
{
  const InputSchedule::Admission admission = inputs_.push(ros::Time::now(), stamp, input);
  switch (admission.verdict)
  {
    case InputSchedule::Verdict::Held:
      if (!stamp.isZero() && started_ && stamp < rosTime(world_->time()))
        ROS_WARN_THROTTLE(5.0,
                          "%s: input late: stamped %.3g s before the simulated instant, so it takes effect at the "
                          "next step, and a replay (which has it in time) differs; stamp inputs ahead of now",
                          topic.c_str(), (rosTime(world_->time()) - stamp).toSec());
      break;
    case InputSchedule::Verdict::Stale:
      ROS_WARN_THROTTLE(5.0, "%s: input dropped: stamped %.3f s behind the ROS clock, more than ~max_input_age = %g s",
                        topic.c_str(), -admission.offset, inputs_.limits().max_age);
      break;
    case InputSchedule::Verdict::TooFarAhead:
      ROS_WARN_THROTTLE(5.0,
                        "%s: input dropped: stamped %.3f s ahead of the ROS clock, more than ~max_input_lead = %g s "
                        "(a clock mix-up? /use_sim_time differs between sender and simulator)",
                        topic.c_str(), admission.offset, inputs_.limits().max_lead);
      break;
  }
  if (admission.evicted)
    ROS_WARN_THROTTLE(5.0, "%s: %zu inputs waiting for their steps (~max_held_inputs): the earliest-stamped dropped",
                      topic.c_str(), inputs_.limits().max_held);
}

void SimNode::applyDueInputs(const ros::Time& step_end)
{
  const double start = world_->time(), end = (step_end - epoch_).toSec();
  std::vector<int> given;  // anchors with an input this step
  std::vector<std::string> aimed;  // bodies with a target this step
  const auto move = [&](int anchor, const Vec3& position, const std::optional<Eigen::Quaterniond>& orientation) {
    if (orientation)
      world_->moveAnchor(anchor, position, *orientation);
    else
      world_->moveAnchor(anchor, position);
  };
  const auto aim = [&](const std::string& body, const Vec3& target) {
    world_->setTarget(body, target);
    targets_[body] = target;
  };
  for (const ScheduledInput& input : inputs_.due(step_end))
  {
    const double stamp = (input.stamp - epoch_).toSec();
    if (input.kind == ScheduledInput::Kind::Anchor)
    {
      warnIfRodEndJumps(input);
      if (max_input_interval_ > 0.0)
      {
        glides_[input.anchor].add(stamp, input.position, input.orientation, max_input_interval_);
        given.push_back(input.anchor);
      }
      else
        move(input.anchor, input.position, input.orientation);
      continue;
    }
    if (max_input_interval_ > 0.0)
    {
      // A target after a pause starts a move of its own, set at once: the body's dynamics approach it, with
      // the creature's anticipation (creature.h), which a glide would spread into nothing.
      target_glides_[input.body].addAfterPauseAtOnce(stamp, input.position, max_input_interval_);
      aimed.push_back(input.body);
    }
    else
      aim(input.body, input.position);
  }
  // Every anchor and target whose commanded pose changes in this step goes where its glide is at the
  // step's end.
  for (const auto& [anchor, glide] : glides_)
    if (glide.movingAfter(start) || std::find(given.begin(), given.end(), anchor) != given.end())
      move(anchor, glide.positionAt(end), glide.orientationAt(end));
  for (const auto& [body, glide] : target_glides_)
    if (glide.movingAfter(start) || std::find(aimed.begin(), aimed.end(), body) != aimed.end())
      aim(body, glide.positionAt(end));
}

void SimNode::warnIfRodEndJumps(const ScheduledInput& input) const
{
  // A rod's bend stiffens without bound only up to a fold (rods.h): an end moved past its neighbour within
  // one linearised sub-step can fold its last segment back, which unfolds only slowly.
  const Model& model = world_->model();
  const Anchor& anchor = model.anchors[static_cast<std::size_t>(input.anchor)];
  const StationIndex at = findRodStation(model, anchor.node);
  if (!at)
    return;
  const int substeps = world_->settings().substeps;
  const double segment = model.rods[static_cast<std::size_t>(at.rod)].segment_length;
  const double jump = (input.position - world_->state().position.col(anchor.node)).norm();
  if (jump <= segment * substeps)
    return;
  ROS_WARN_THROTTLE(5.0,
                    "%s: anchor '%s' of rod '%s' moves %.3g m in one step, more than a segment (%.3g m) per sub-step: "
                    "its end may fold back on itself; move it in smaller steps or set physics.substeps >= %d",
                    name_.c_str(), anchor.name.c_str(), anchor.body.c_str(), jump, segment,
                    static_cast<int>(std::ceil(jump / segment)));
}

std::string SimNode::tfFrame(const std::string& frame, const std::string& source)
{
  if (frame.empty() || frame[0] != '/')
    return frame;
  // Not quoted: the name is checked (length, control characters) only after this.
  if (slash_warned_.insert(source).second)
    ROS_WARN("%s: a frame name with a leading slash is taken without it (tf2 refuses the slash of tf1); "
             "warned once for this source", source.c_str());
  return frame.substr(std::min(frame.find_first_not_of('/'), frame.size()));
}

bool SimNode::toSceneFrame(const geometry_msgs::PoseStamped& pose, const std::string& topic, Vec3& position,
                           std::optional<Eigen::Quaterniond>* orientation)
{
  if (!pose.header.frame_id.empty() && pose.header.frame_id[0] == '/')
  {
    geometry_msgs::PoseStamped relative = pose;
    relative.header.frame_id = tfFrame(pose.header.frame_id, topic);  // no slash left: no further turn here
    return toSceneFrame(relative, topic, position, orientation);
  }
  std::string why;
  std::optional<Eigen::Quaterniond> unused;
  std::optional<Eigen::Quaterniond>& turn = orientation ? *orientation : unused;
  // Finite but absurd (x = 1e30): a body dragged there diverges, publishes 1e30 m and stays there.
  const auto inWorkspace = [&]() {
    why = outsideWorkspace(position);
    if (why.empty())
      return true;
    ROS_WARN_THROTTLE(5.0, "%s: pose dropped: %s", topic.c_str(), why.c_str());
    return false;
  };
  if (!RosConverter::fromPose(pose.pose, position, turn, why))
  {
    ROS_WARN_THROTTLE(5.0, "%s: pose dropped: %s", topic.c_str(), why.c_str());
    return false;
  }
  if (pose.header.frame_id.empty())
  {
    ROS_WARN_THROTTLE(5.0, "%s: pose dropped: empty header.frame_id", topic.c_str());
    return false;
  }
  why = badName("header.frame_id", pose.header.frame_id);
  if (!why.empty())
  {
    ROS_WARN_THROTTLE(5.0, "%s: pose dropped: %s", topic.c_str(), why.c_str());
    return false;
  }
  if (pose.header.frame_id == scene_.frame_id)
    return inWorkspace();  // no lookup: the same with or without tf data
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
    if (!turn)
      in_scene.pose.orientation = pose.pose.orientation;  // all zeros: no orientation given, none to transform
    if (!RosConverter::fromPose(in_scene.pose, position, turn, why))
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
  return inWorkspace();
}

std::string SimNode::outsideWorkspace(const Vec3& position) const
{
  const double distance = position.stableNorm();  // no overflow to infinity at 1e300
  if (distance <= workspace_radius_)
    return std::string();
  char text[128];
  std::snprintf(text, sizeof text, "%g m from the origin of the scene frame, beyond ~workspace_radius = %g m",
                distance, workspace_radius_);
  return text;
}

std::optional<RigidPose> SimNode::framePose(const std::string& frame, const ros::Time& stamp, std::string* why,
                                            std::optional<ros::Time>* newest)
{
  std::string unused;
  std::string& reason = why ? *why : unused;
  geometry_msgs::TransformStamped transform;
  if (newest)
    newest->reset();
  try
  {
    try
    {
      transform = tf_buffer_.lookupTransform(scene_.frame_id, frame, stamp);
    }
    catch (const tf2::ExtrapolationException&)
    {
      // Past the latest transform (still on its way): the latest. Before the earliest, the frame did not
      // exist yet at `stamp`: none, as when tf has nothing. Not the latest either: which transforms a
      // catch-up step finds in the buffer depends on when its tick runs, so a replay would see another one.
      transform = tf_buffer_.lookupTransform(scene_.frame_id, frame, ros::Time(0));
      if (transform.header.stamp >= stamp)
        throw tf2::LookupException("its first transform is stamped after this step");
      if (newest)
        *newest = transform.header.stamp;
    }
    if (newest && stamp.isZero())
      *newest = transform.header.stamp;  // the latest was asked for
  }
  catch (const tf2::TransformException& e)
  {
    reason = "no transform from '" + frame + "' to '" + scene_.frame_id + "'";
    // At start-up the frame's publisher (robot_state_publisher, a driver) may come up a little later: a
    // frame still missing after kFrameGraceSeconds of simulated time is worth a warning.
    if ((stamp - epoch_).toSec() < kFrameGraceSeconds)
      ROS_DEBUG_THROTTLE(1.0, "%s: waiting for a transform from '%s' to '%s': %s", name_.c_str(), frame.c_str(),
                         scene_.frame_id.c_str(), e.what());
    else
      ROS_WARN_THROTTLE(5.0, "%s: no transform from '%s' to '%s' yet: %s", name_.c_str(), frame.c_str(),
                        scene_.frame_id.c_str(), e.what());
    return std::nullopt;
  }
  const std::optional<RigidPose> pose = RosConverter::toRigidPose(transform.transform);
  if (!pose)
  {
    reason = "the transform from '" + frame + "' to '" + scene_.frame_id + "' is not finite or has a zero rotation";
    ROS_WARN_THROTTLE(5.0, "%s: %s", name_.c_str(), reason.c_str());
    return std::nullopt;
  }
  reason = outsideWorkspace(pose->position);
  if (!reason.empty())
  {
    reason = "tf frame '" + frame + "' is " + reason;
    ROS_WARN_THROTTLE(5.0, "%s: %s: ignored", name_.c_str(), reason.c_str());
    return std::nullopt;
  }
  return pose;
}

std::optional<Vec3> SimNode::frameOrigin(const std::string& frame, const ros::Time& stamp, std::string* why)
{
  const std::optional<RigidPose> pose = framePose(frame, stamp, why);
  return pose ? std::optional<Vec3>(pose->position) : std::nullopt;
}

std::optional<RigidPose> SimNode::followedPose(const std::string& frame, double t, FrameGlide& follower)
{
  std::optional<ros::Time> newest;
  const std::optional<RigidPose> pose = framePose(frame, rosTime(t), nullptr, &newest);
  if (!pose)
    return std::nullopt;
  if (follower.pauses != pauses_)
    follower = FrameGlide{ InputGlide(), pauses_ };
  InputGlide& glide = follower.glide;
  // world_->time() is the step's start: a late frame's newest transform glides in from there.
  const double start = world_->time();
  std::optional<RigidPose> latest = pose;
  if (!newest)
  {
    if (glide.onFrame(t, pose->position, pose->orientation))
      return pose;
    latest = framePose(frame, ros::Time(0), nullptr, &newest);  // off the frame: it glides on its transforms
  }
  if (latest && newest)
    glide.followNewest(start, (*newest - epoch_).toSec(), latest->position, latest->orientation, max_input_interval_);
  return RigidPose{ glide.positionAt(t), *glide.orientationAt(t) };
}

void SimNode::followFrame(int anchor, const std::string& frame)
{
  // The path is asked for the step's end: the frame's pose at that ROS time, interpolated by tf.
  const auto glide = std::make_shared<FrameGlide>(FrameGlide{ InputGlide(), pauses_ });
  world_->followPath(anchor, [this, frame, glide](double t) -> std::optional<Vec3> {
    const std::optional<RigidPose> pose = followedPose(frame, t, *glide);
    return pose ? std::optional<Vec3>(pose->position) : std::nullopt;
  });
}

void SimNode::followFrame(const ColliderPlacement& collider)
{
  // The scene's pose of the collider is relative to its frame.
  const RigidPose local{ collider.position, collider.orientation };
  const std::string frame = collider.frame;
  const auto glide = std::make_shared<FrameGlide>(FrameGlide{ InputGlide(), pauses_ });
  world_->followColliderPath(collider.name, [this, frame, local, glide](double t) -> std::optional<RigidPose> {
    const std::optional<RigidPose> origin = followedPose(frame, t, *glide);
    if (!origin)
      return std::nullopt;
    return compose(*origin, local);
  });
}

bool SimNode::onAttach(Attach::Request& request, Attach::Response& response)
{
  const auto refuse = [&](const std::string& why) {
    response.success = false;
    response.message = why;
    ROS_WARN("%s: attach refused: %s", name_.c_str(), why.c_str());
    return true;
  };
  request.frame = tfFrame(request.frame, private_nh_.resolveName("attach"));
  if (request.frame.empty())
    return refuse("no frame given");
  for (const std::string& why : { badName("frame name", request.frame), badName("body name", request.body) })
    if (!why.empty())
      return refuse(why);
  const std::vector<BodyRange>& bodies = world_->model().bodies;
  if (!request.body.empty() && std::none_of(bodies.begin(), bodies.end(), [&](const BodyRange& body) {
        return body.name == request.body;
      }))
    return refuse("no body '" + request.body + "' in the scene");
  if (!(request.radius > 0.0 && std::isfinite(request.radius)))
    return refuse("radius must be a finite number > 0 [m], not " + formatNumber(request.radius));
  for (const Anchor& anchor : world_->model().anchors)
    if (anchor.name == request.frame && world_->isAttached(*world_->findAnchor(anchor.body, anchor.name)))
      return refuse("frame '" + request.frame + "' already holds a node of '" + anchor.body + "'");
  std::string unusable;
  const std::optional<Vec3> origin = frameOrigin(request.frame, ros::Time(0), &unusable);
  if (!origin)
    return refuse(unusable);
  const std::optional<int> node = world_->nearestFreeNode(*origin, request.body, request.radius);
  if (!node)
    return refuse("no free node" + (request.body.empty() ? std::string() : " of '" + request.body + "'") + " within " +
                  formatNumber(request.radius) + " m of '" + request.frame + "'");
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
  const auto refuse = [&](const std::string& why) {
    response.success = false;
    response.message = why;
    ROS_WARN("%s: detach refused: %s", name_.c_str(), why.c_str());
    return true;
  };
  request.frame = tfFrame(request.frame, private_nh_.resolveName("detach"));
  if (request.frame.empty())
    return refuse("no frame given");
  const std::string why = badName("frame name", request.frame);
  if (!why.empty())
    return refuse(why);
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
  return refuse("frame '" + request.frame + "' holds nothing");
}

bool SimNode::onGrasp(Grasp::Request& request, Grasp::Response& response)
{
  const auto refuse = [&](const std::string& why) {
    response.success = false;
    response.message = why;
    ROS_WARN("%s: grasp refused: %s", name_.c_str(), why.c_str());
    return true;
  };
  request.frame = tfFrame(request.frame, private_nh_.resolveName("grasp"));
  if (request.frame.empty())
    return refuse("no frame given");
  if (request.body.empty())
    return refuse("no body given");
  for (const std::string& why : { badName("frame name", request.frame), badName("body name", request.body) })
    if (!why.empty())
      return refuse(why);
  if (!(request.max_force >= 0.0 && std::isfinite(request.max_force)))
    return refuse("max_force must be a finite number >= 0 [N] (0: no limit), not " + formatNumber(request.max_force));
  std::string unusable;
  const std::optional<RigidPose> pose = framePose(request.frame, ros::Time(0), &unusable);
  if (!pose)
    return refuse(unusable);
  const double max_force = request.max_force > 0.0 ? request.max_force : std::numeric_limits<double>::infinity();
  try
  {
    world_->grasp(request.frame, request.body, *pose, request.radius, max_force);
  }
  catch (const std::invalid_argument& e)
  {
    return refuse(e.what());
  }
  const std::string frame = request.frame;
  const auto glide = std::make_shared<FrameGlide>(FrameGlide{ InputGlide(), pauses_ });
  world_->followGraspPath(frame, [this, frame, glide](double t) { return followedPose(frame, t, *glide); });
  const GraspedNodes& grasp = world_->grasps().back();
  const int first = world_->model().bodies[grasp.body].first;
  for (const int node : grasp.nodes)
    response.nodes.push_back(node - first);
  response.success = true;
  response.message = "'" + request.frame + "' holds " + std::to_string(grasp.nodes.size()) + " node(s) of '" +
                     request.body + "'" +
                     (request.max_force > 0.0 ? " up to " + formatNumber(request.max_force) + " N" : std::string());
  ROS_INFO("%s: %s", name_.c_str(), response.message.c_str());
  return true;
}

bool SimNode::onRelease(Detach::Request& request, Detach::Response& response)
{
  request.frame = tfFrame(request.frame, private_nh_.resolveName("release"));
  const std::string why = request.frame.empty() ? "no frame given" : badName("frame name", request.frame);
  if (!why.empty() || !world_->release(request.frame))
  {
    response.success = false;
    response.message = !why.empty() ? why : "frame '" + request.frame + "' holds no grasp";
    ROS_WARN("%s: release refused: %s", name_.c_str(), response.message.c_str());
    return true;
  }
  response.success = true;
  response.message = "'" + request.frame + "' released its grasp";
  ROS_INFO("%s: %s", name_.c_str(), response.message.c_str());
  return true;
}

}  // namespace soft_body_sim
