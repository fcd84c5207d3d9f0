#include "soft_body_sim/ros/sim_node.h"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <ros/names.h>
#include <std_msgs/Time.h>

#include "ros/node_parameters.h"
#include "soft_body_sim/SimState.h"
#include "soft_body_sim/core/contact/mesh_field.h"
#include "soft_body_sim/core/format_number.h"
#include "soft_body_sim/ros/robot_colliders.h"
#include "soft_body_sim/scene/scene_loader.h"

namespace soft_body_sim
{
namespace
{
/// `t` rounded down to a whole millisecond: simulated time 0 then has a short decimal form that a
/// double parameter (~start_time) carries exactly to the nanosecond.
ros::Time floorToMillisecond(const ros::Time& t) { return ros::Time(t.sec, t.nsec / 1000000 * 1000000); }

ros::Time fromMilliseconds(double seconds)
{
  const long long ms = std::llround(seconds * 1e3);
  return ros::Time(static_cast<uint32_t>(ms / 1000), static_cast<uint32_t>(ms % 1000) * 1000000u);
}
}  // namespace

SimNode::SimNode(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh, const std::string& name)
  : nh_(nh), private_nh_(private_nh), name_(name), tf_listener_(tf_buffer_)
{
}

void SimNode::initialize()
{
  const std::optional<std::string> scene = readParam<std::string>(private_nh_, "scene", "the path of a scene file");
  if (!scene)
    throw std::runtime_error(private_nh_.resolveName("scene") + ": parameter not set (the scene file to load)");
  scene_path_ = *scene;
  scene_ = loadSceneFile(scene_path_);
  if (scene_.robot_colliders)
    addRobotColliders();
  rate_ = readParam<double>(private_nh_, "rate", "a finite number > 0 [Hz]", finitePositive).value_or(scene_.rate);
  // Below one tick's period, so that a tick leaves time for the callbacks (services, inputs) before the next.
  tick_budget_ =
      readParam<double>(private_nh_, "tick_budget", "a finite number > 0 [s]", finitePositive).value_or(0.8 / rate_);
  workspace_radius_ = readParam<double>(private_nh_, "workspace_radius", "a finite number > 0 [m]", finitePositive)
                          .value_or(workspace_radius_);
  status_period_ =
      readParam<double>(private_nh_, "status_period", "a finite number >= 0 [s]", finiteNonNegative).value_or(0.0);
  const double state_rate =
      readParam<double>(private_nh_, "state_rate", "a finite number >= 0 [Hz]", finiteNonNegative).value_or(0.0);
  state_period_ = state_rate > 0.0 ? 1.0 / state_rate : 0.0;
  force_scale_ = readParam<double>(private_nh_, "force_scale", "a finite number > 0 [m/N]", finitePositive)
                     .value_or(force_scale_);
  const double start_time = readParam<double>(private_nh_, "start_time", "a ROS time in seconds (> 0), or 0",
                                              [](const double& t) { return t == 0.0 || (t > 0.0 && t < 4e9); })
                                .value_or(0.0);
  if (start_time != 0.0)
    start_time_ = fromMilliseconds(start_time);
  buildWorldFromScene();
  for (int node = 0; node < world_->model().nodeCount(); ++node)
    if (!outsideWorkspace(world_->state().position.col(node)).empty())
      throw std::runtime_error(private_nh_.resolveName("workspace_radius") + ": the scene's node " +
                               std::to_string(node) + " lies outside it: " +
                               outsideWorkspace(world_->state().position.col(node)));

  markers_publisher_ = private_nh_.advertise<visualization_msgs::MarkerArray>("markers", 1);
  force_markers_publisher_ = private_nh_.advertise<visualization_msgs::MarkerArray>("force_markers", 1);
  state_publisher_ = private_nh_.advertise<SimState>("state", 10);
  start_time_publisher_ = private_nh_.advertise<std_msgs::Time>("start_time", 1, true);
  subscribeInputs();
  addHandles();
  addCameras();
  startReconfigure();
  diagnostics_ = std::make_unique<diagnostic_updater::Updater>(nh_, private_nh_, name_);
  diagnostics_->setHardwareID("none");  // a simulation: no device
  diagnostics_->add("simulation", this, &SimNode::diagnose);
  reset_service_ = private_nh_.advertiseService("reset", &SimNode::onReset, this);
  pause_service_ = private_nh_.advertiseService("pause", &SimNode::onPause, this);
  attach_service_ = private_nh_.advertiseService("attach", &SimNode::onAttach, this);
  detach_service_ = private_nh_.advertiseService("detach", &SimNode::onDetach, this);
  grasp_service_ = private_nh_.advertiseService("grasp", &SimNode::onGrasp, this);
  release_service_ = private_nh_.advertiseService("release", &SimNode::onRelease, this);
  save_state_service_ = private_nh_.advertiseService("save_state", &SimNode::onSaveState, this);
  load_state_service_ = private_nh_.advertiseService("load_state", &SimNode::onLoadState, this);
  timer_ = nh_.createTimer(ros::Duration(1.0 / rate_), &SimNode::onTimer, this);
  ROS_INFO("%s: scene %s, %d nodes in %zu bodies, %s at dt = %g s, publishing at %g Hz in frame '%s'", name_.c_str(),
           scene_path_.c_str(), world_->model().nodeCount(), world_->model().bodies.size(),
           integratorName(world_->integrator()).c_str(), world_->settings().dt, rate_, scene_.frame_id.c_str());
}

void SimNode::addRobotColliders()
{
  const RobotCollidersDef& robot = *scene_.robot_colliders;
  const std::optional<std::string> urdf =
      readParam<std::string>(nh_, robot.param, "a robot's URDF (" + scene_path_ + ": robot_colliders.param)");
  if (!urdf)
    throw std::runtime_error(scene_path_ + ": robot_colliders.param: the parameter '" + nh_.resolveName(robot.param) +
                             "' is not set (it should hold the robot's URDF)");
  std::vector<std::string> skipped;
  try
  {
    soft_body_sim::addRobotColliders(*urdf, robot, scene_.colliders, skipped);
  }
  catch (const std::invalid_argument& e)
  {
    throw std::runtime_error(scene_path_ + ": " + e.what());
  }
  for (const std::string& collision : skipped)
    ROS_WARN("%s: robot collision %s left out", name_.c_str(), collision.c_str());
  // The robot's meshes get their fields once here, as the scene's own did at load time: a reset reuses them.
  buildMeshFields(scene_.colliders.meshes, maxContactRadius(scene_));
}

void SimNode::buildWorldFromScene()
{
  world_ = std::make_unique<World>(buildWorld(scene_));
  // Live tuning outlives a reset: the sliders keep showing what is in force.
  if (sim_reconfigure_)
    applySimConfig(sim_reconfigure_->config());
  for (const auto& [body, server] : body_reconfigure_)
    applyBodyConfig(body, server->config());
  followFrames();
  restartAtWorldTime();
}

void SimNode::followFrames()
{
  const std::vector<Anchor>& anchors = world_->model().anchors;
  for (std::size_t k = 0; k < anchors.size(); ++k)
  {
    const int anchor = static_cast<int>(k);
    if (!anchors[k].frame.empty())
      followFrame(anchor, anchors[k].frame);
    else if (world_->isAttached(anchor))
      followFrame(anchor, anchors[k].name);  // ~attach names the anchor by its frame
  }
  for (const ColliderPlacement* at : placements(world_->model().colliders))
    if (!at->frame.empty())
      followFrame(*at);
  for (const GraspedNodes& grasp : world_->grasps())
  {
    const std::string frame = grasp.name;
    const auto glide = std::make_shared<FrameGlide>(FrameGlide{ InputGlide(), pauses_ });
    world_->followGraspPath(frame, [this, frame, glide](double t) { return followedPose(frame, t, *glide); });
  }
}

void SimNode::restartAtWorldTime()
{
  max_steps_per_tick_ = std::max(1L, std::lround(std::ceil(2.0 / (rate_ * world_->settings().dt))));
  next_state_time_ = world_->time();
  targets_.clear();
  inputs_.clear();
  glides_.clear();
  target_glides_.clear();
  for (const std::unique_ptr<CameraPublisher>& camera : cameras_)
    camera->restart();
}

void SimNode::addCameras()
{
  if (scene_.cameras.empty())
    return;
  camera_frames_ = std::make_unique<tf2_ros::StaticTransformBroadcaster>();
  std::vector<geometry_msgs::TransformStamped> frames;
  const auto transform = [&](const std::string& parent, const std::string& child, const RigidPose& pose) {
    geometry_msgs::TransformStamped t;
    t.header.stamp = ros::Time::now();
    t.header.frame_id = parent;
    t.child_frame_id = child;
    t.transform.translation.x = pose.position.x();
    t.transform.translation.y = pose.position.y();
    t.transform.translation.z = pose.position.z();
    t.transform.rotation = RosConverter::toPose(pose).orientation;
    frames.push_back(t);
  };
  for (const CameraDef& camera : scene_.cameras)
  {
    cameras_.push_back(std::make_unique<CameraPublisher>(camera, world_->model(), private_nh_));
    transform(camera.frame.empty() ? scene_.frame_id : camera.frame, camera.name + "_link",
              RigidPose{ camera.position, camera.orientation.normalized() });
    transform(camera.name + "_link", camera.name + "_color_optical_frame", RigidPose{ Vec3::Zero(), linkToOptical() });
  }
  camera_frames_->sendTransform(frames);
}

void SimNode::shootCameras()
{
  const double t = world_->time();
  const ros::Time stamp = rosTime(t);
  for (const std::unique_ptr<CameraPublisher>& camera : cameras_)
  {
    const std::optional<std::uint64_t> frame = camera->due(t);
    if (!frame)
      continue;
    const State& state = world_->state();
    if (!state.position.allFinite())
      continue;  // publish() says so
    const CameraDef& def = camera->def();
    RigidPose link{ def.position, def.orientation.normalized() };
    if (!def.frame.empty())
    {
      const std::optional<RigidPose> pose = framePose(def.frame, stamp);  // warns (throttled) if there is none
      if (!pose)
        continue;
      link = compose(*pose, link);
    }
    camera->shoot(*frame, state, world_->colliderPoses(), link, stamp);
  }
}

void SimNode::onTimer(const ros::TimerEvent&)
{
  const ros::Time now = ros::Time::now();
  if (now.isZero())
    return;  // /use_sim_time and no /clock yet
  if (!started_)
  {
    epoch_ = start_time_ ? *start_time_ : floorToMillisecond(now);
    if (now < epoch_)
      return;  // ~start_time has not come yet
    last_tick_ = epoch_;
    started_ = true;
    ROS_INFO("%s: simulated time 0 is ROS time %.3f", name_.c_str(), epoch_.toSec());
  }
  const double elapsed = std::max(0.0, (now - last_tick_).toSec());
  last_tick_ = now;
  if (paused_)
  {
    epoch_ += ros::Duration(elapsed);  // simulated time stands still while ROS time goes on
    ++pauses_;
  }
  else
  {
    noteHeldNodes();
    advance(now, elapsed);
  }
  if (!paused_ && epoch_ != published_epoch_)
  {
    std_msgs::Time message;
    message.data = published_epoch_ = epoch_;
    start_time_publisher_.publish(message);
  }
  watchDivergence();
  watchGrasps();
  publish();
  diagnostics_->update();
  if (status_period_ > 0.0 && (now - last_status_).toSec() >= status_period_)
    printStatus(now);
}

void SimNode::printStatus(const ros::Time& now)
{
  last_status_ = now;
  ROS_INFO("%s: t = %.1f s simulated%s, real-time factor %.2f, %.1f us per physics step", name_.c_str(),
           world_->time(), paused_ ? " (paused)" : "", statistics_.real_time_factor,
           1e6 * statistics_.wall_seconds_per_step);
}

void SimNode::advance(const ros::Time& now, double elapsed)
{
  // Whole steps up to now: the simulated instant epoch_ + time() never passes the ROS clock, and timer
  // jitter only changes how many steps a tick takes, not where they fall (the 1e-9 absorbs round-off).
  const double dt = world_->settings().dt;
  long steps = static_cast<long>(std::floor(((now - epoch_).toSec() - world_->time()) / dt + 1e-9));
  // Under /use_sim_time the clock (rosbag play) waits for nobody, and a replay must take every step.
  if (steps > max_steps_per_tick_ && !ros::Time::isSimTime())
  {
    ROS_WARN_THROTTLE(5.0, "%s: falling behind real time: %.3f s of simulation dropped this tick", name_.c_str(),
                      (steps - max_steps_per_tick_) * dt);
    epoch_ += ros::Duration((steps - max_steps_per_tick_) * dt);  // the dropped time
    steps = max_steps_per_tick_;
  }
  // The budget is checked between steps (a step cannot be cut short): one step always runs, so that a
  // step dearer than the budget still moves simulated time on, a tick at a time.
  const auto start = std::chrono::steady_clock::now();
  const auto deadline = start + std::chrono::duration<double>(tick_budget_);
  long taken = 0;
  // Cameras take their frames between steps, at the first step's end at or past each frame's instant
  // (exactly at n / rate when dt divides the period), whatever the ticks' timing; and at t = 0.
  shootCameras();
  for (; taken < steps; ++taken)
  {
    if (taken > 0 && std::chrono::steady_clock::now() > deadline)
      break;
    applyDueInputs(rosTime(world_->time() + dt));
    world_->step();
    shootCameras();
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (taken > 0)
    statistics_.wall_seconds_per_step = wall / static_cast<double>(taken);
  // The steps not taken stay due: the next tick takes them. A passing slow tick (the machine busy for a
  // moment) is caught up without moving the start time, which would make the run unreplayable; a node
  // that cannot keep real time reaches the two ticks' cap above, which drops the backlog beyond it, and
  // under /use_sim_time (no cap) a replay takes every step, only later.
  if (taken < steps)
    warnOverBudget(steps, taken, wall);
  steps = taken;
  // Whole steps per tick alternate (e.g. 3 and 4 steps of 5 ms in 16.7 ms ticks): the real-time factor
  // is taken over windows of at least half a second.
  window_elapsed_ += elapsed;
  window_simulated_ += static_cast<double>(std::max(0L, steps)) * dt;
  if (window_elapsed_ >= 0.5)
  {
    statistics_.real_time_factor = window_simulated_ / window_elapsed_;
    window_elapsed_ = window_simulated_ = 0.0;
  }
}

void SimNode::warnOverBudget(long steps, long taken, double wall) const
{
  const double dt = world_->settings().dt;
  // The pace of this tick's stepping: simulated seconds per wall second.
  const double factor = static_cast<double>(taken) * dt / wall;
  ROS_WARN_THROTTLE(5.0,
                    "%s: a tick ran out of ~tick_budget = %g s after %ld of %ld steps (real-time factor %.3g): the "
                    "rest follow in the next ticks%s",
                    name_.c_str(), tick_budget_, taken, steps, factor,
                    ros::Time::isSimTime() ? ", behind /clock; slow the clock down to keep pace" :
                                             "; beyond two ticks' worth behind, time is dropped: lower substeps or "
                                             "iterations, raise dt, or run under /use_sim_time with a slower clock");
}

void SimNode::publish()
{
  const ros::Time stamp = rosTime(world_->time());
  const State& state = world_->state();
  if (!state.position.allFinite() || !state.velocity.allFinite())
  {
    ROS_ERROR_THROTTLE(5.0, "%s: the simulation holds non-finite values; nothing published (~reset restarts it)",
                       name_.c_str());
    return;
  }
  const std::vector<Holder> holders = RosConverter::holders(*world_);
  markers_publisher_.publish(RosConverter::toMarkers(*world_, scene_.frame_id, stamp));
  force_markers_publisher_.publish(RosConverter::toForceMarkers(holders, force_scale_, scene_.frame_id, stamp));
  // At ~state_rate, on average: at the first tick from each 1 / ~state_rate on, none twice within a tick.
  if (world_->time() >= next_state_time_)
  {
    state_publisher_.publish(RosConverter::toState(*world_, scene_.frame_id, stamp, statistics_, holders, slips_));
    slips_.clear();
    next_state_time_ += state_period_;
    if (next_state_time_ <= world_->time())
      next_state_time_ = world_->time() + state_period_;
  }
  publishWrenches(holders, stamp);
  publishColliderWrenches(stamp);
  for (std::size_t k = 0; k < handle_names_.size(); ++k)
    if (!handle_names_[k].empty())
      handles_->follow(handle_names_[k], state.position.col(world_->model().anchors[k].node));
  for (const auto& [body, handle] : target_handles_)
    if (const auto target = targets_.find(body); target != targets_.end())
      handles_->follow(handle, target->second);
  handles_->applyChanges();
}

void SimNode::publishWrenches(const std::vector<Holder>& holders, const ros::Time& stamp)
{
  std::map<std::string, ros::Publisher> publishers;
  for (const Holder& holder : holders)
  {
    const std::string topic = world_->model().bodies[holder.body].name + "/" + holder.name + "/wrench";
    std::string why;
    if (!ros::names::validate(topic, why))
    {
      // A tf frame may be named what a topic may not (an ~attach or ~grasp frame "hand-1").
      ROS_WARN_THROTTLE(60.0, "%s: no wrench topic for '%s': %s (its wrench is in ~state)", name_.c_str(),
                        holder.name.c_str(), why.c_str());
      continue;
    }
    auto found = wrench_publishers_.find(topic);
    ros::Publisher publisher = found != wrench_publishers_.end()
                                   ? found->second
                                   : private_nh_.advertise<geometry_msgs::WrenchStamped>(topic, 10);
    publisher.publish(RosConverter::toWrench(holder.wrench, scene_.frame_id, stamp));
    publishers.emplace(topic, publisher);
  }
  wrench_publishers_.swap(publishers);  // the topics of holders gone are no longer advertised
}

void SimNode::publishColliderWrenches(const ros::Time& stamp)
{
  for (const ColliderWrench& collider : world_->colliderWrenches())
  {
    auto found = collider_wrench_publishers_.find(collider.name);
    if (found == collider_wrench_publishers_.end())
    {
      const std::string topic = "colliders/" + collider.name + "/wrench";
      std::string why;
      if (!ros::names::validate(topic, why))
      {
        // A URDF link may be named what a topic may not ("link-1").
        ROS_WARN_THROTTLE(60.0, "%s: no wrench topic for collider '%s': %s (its wrench is in ~state)",
                          name_.c_str(), collider.name.c_str(), why.c_str());
        continue;
      }
      found = collider_wrench_publishers_
                  .emplace(collider.name, private_nh_.advertise<geometry_msgs::WrenchStamped>(topic, 10))
                  .first;
    }
    found->second.publish(RosConverter::toWrench(collider.wrench, scene_.frame_id, stamp));
  }
}

bool SimNode::onReset(std_srvs::Empty::Request&, std_srvs::Empty::Response&)
{
  buildWorldFromScene();
  if (started_)
    epoch_ = last_tick_;
  slips_.clear();
  ROS_INFO("%s: reset to the initial scene (attached and grasped nodes released; live tuning kept)", name_.c_str());
  return true;
}

bool SimNode::onSaveState(StateFile::Request& request, StateFile::Response& response)
{
  response.time = world_->time();
  const std::string bytes = world_->snapshot().toBytes();
  // Into a file beside it first, then renamed over it: a reader never sees half a snapshot.
  const std::string partial = request.path + ".partial";
  {
    std::ofstream file(partial, std::ios::binary | std::ios::trunc);
    file.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    file.close();
    std::error_code error;
    if (!file || (std::filesystem::rename(partial, request.path, error), error))
    {
      std::filesystem::remove(partial, error);
      response.success = false;
      response.message = "cannot write '" + request.path + "': " + std::strerror(errno);
      ROS_WARN("%s: save_state refused: %s", name_.c_str(), response.message.c_str());
      return true;
    }
  }
  response.success = true;
  response.message = "saved t = " + formatNumber(response.time) + " s (" + std::to_string(bytes.size()) +
                     " bytes) to '" + request.path + "'";
  ROS_INFO("%s: %s", name_.c_str(), response.message.c_str());
  return true;
}

bool SimNode::onLoadState(StateFile::Request& request, StateFile::Response& response)
{
  const auto refuse = [&](const std::string& why) {
    response.success = false;
    response.time = world_->time();
    response.message = "'" + request.path + "': " + why;
    ROS_WARN("%s: load_state refused: %s", name_.c_str(), response.message.c_str());
    return true;
  };
  std::error_code error;
  if (!std::filesystem::is_regular_file(request.path, error))
    return refuse(error ? error.message() : "not a regular file");
  const std::uintmax_t size = std::filesystem::file_size(request.path, error);
  if (error)
    return refuse(error.message());
  if (size > kMaxStateFileBytes)
    return refuse(std::to_string(size) + " bytes, more than the " + std::to_string(kMaxStateFileBytes) +
                  " a snapshot of the largest scene takes");
  std::ifstream file(request.path, std::ios::binary);
  std::string bytes(static_cast<std::size_t>(size), '\0');
  if (!file.read(bytes.data(), static_cast<std::streamsize>(size)))
    return refuse(std::string("cannot read it: ") + std::strerror(errno));
  try
  {
    world_->restore(WorldSnapshot::fromBytes(std::move(bytes)));
  }
  catch (const std::invalid_argument& e)
  {
    return refuse(e.what());
  }
  // Simulated time goes on from the moment, at the ROS time of now.
  if (started_)
    epoch_ = last_tick_ - ros::Duration(world_->time());
  slips_.clear();
  followFrames();
  restartAtWorldTime();
  if (sim_reconfigure_)
    sim_reconfigure_->update(RosConverter::toSimConfig(*world_));
  for (const auto& [body, server] : body_reconfigure_)
  {
    BodyConfig config = server->config();
    const BodyScaling scaling = world_->bodyScaling(body);
    config.stiffness_scale = scaling.stiffness;
    config.damping_scale = scaling.damping;
    config.pressure_scale = scaling.pressure;
    server->update(config);
  }
  response.success = true;
  response.time = world_->time();
  response.message = "loaded t = " + formatNumber(response.time) + " s from '" + request.path + "'";
  ROS_INFO("%s: %s", name_.c_str(), response.message.c_str());
  return true;
}

bool SimNode::onPause(std_srvs::SetBool::Request& request, std_srvs::SetBool::Response& response)
{
  paused_ = request.data;
  response.success = true;
  response.message = paused_ ? "paused" : "running";
  return true;
}

}  // namespace soft_body_sim
