#include "soft_body_sim/ros/sim_node.h"

#include <cmath>

#include <tf2_geometry_msgs/tf2_geometry_msgs.h>

#include "soft_body_sim/SimState.h"
#include "soft_body_sim/scene/scene_loader.h"

namespace soft_body_sim
{
SimNode::SimNode(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh)
  : nh_(nh), private_nh_(private_nh), tf_listener_(tf_buffer_)
{
}

void SimNode::initialize()
{
  std::string path;
  if (!private_nh_.getParam("scene", path))
    throw std::runtime_error(private_nh_.resolveName("scene") + ": parameter not set (the scene file to load)");
  scene_ = loadSceneFile(path);
  rate_ = scene_.rate;
  if (private_nh_.getParam("rate", rate_) && !(rate_ > 0.0 && std::isfinite(rate_)))
    throw std::runtime_error(private_nh_.resolveName("rate") + ": must be a finite number > 0 [Hz]");
  private_nh_.param("status_period", status_period_, 0.0);
  world_ = std::make_unique<World>(buildWorld(scene_));
  const double dt = world_->settings().dt;
  max_steps_per_tick_ = std::max(1L, std::lround(std::ceil(2.0 / (rate_ * dt))));

  markers_publisher_ = private_nh_.advertise<visualization_msgs::MarkerArray>("markers", 1);
  state_publisher_ = private_nh_.advertise<SimState>("state", 10);
  subscribeInputs();
  reset_service_ = private_nh_.advertiseService("reset", &SimNode::onReset, this);
  pause_service_ = private_nh_.advertiseService("pause", &SimNode::onPause, this);
  timer_ = nh_.createTimer(ros::Duration(1.0 / rate_), &SimNode::onTimer, this);
  ROS_INFO("soft_body_sim: scene %s, %d nodes in %zu bodies, %s at dt = %g s, publishing at %g Hz in frame '%s'",
           path.c_str(), world_->model().nodeCount(), world_->model().bodies.size(),
           integratorName(world_->integrator()).c_str(), dt, rate_, scene_.frame_id.c_str());
}

void SimNode::subscribeInputs()
{
  for (std::size_t k = 0; k < world_->model().anchors.size(); ++k)
  {
    const Anchor& anchor = world_->model().anchors[k];
    const std::string topic = private_nh_.resolveName(anchor.body + "/" + anchor.name + "/pose");
    const int id = static_cast<int>(k);
    subscribers_.push_back(private_nh_.subscribe<geometry_msgs::PoseStamped>(
        topic, 10, [this, topic, id](const geometry_msgs::PoseStamped::ConstPtr& pose) {
          Vec3 position;
          if (toSceneFrame(*pose, topic, position))
            world_->moveAnchor(id, position);
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
          Vec3 position;
          if (toSceneFrame(*pose, topic, position))
            world_->setTarget(name, position);
        }));
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
  try
  {
    geometry_msgs::PoseStamped in_scene;
    tf_buffer_.transform(pose, in_scene, scene_.frame_id);
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

void SimNode::onTimer(const ros::TimerEvent&)
{
  const ros::Time now = ros::Time::now();
  if (last_tick_.isZero())
    last_tick_ = epoch_ = now;
  const double elapsed = std::max(0.0, (now - last_tick_).toSec());
  last_tick_ = now;
  if (paused_)
    epoch_ += ros::Duration(elapsed);  // simulated time stands still while ROS time goes on
  else
    advance(elapsed);
  publish(epoch_ + ros::Duration(world_->time()));
  if (status_period_ > 0.0 && (now - last_status_).toSec() >= status_period_)
    printStatus(now);
}

void SimNode::printStatus(const ros::Time& now)
{
  last_status_ = now;
  ROS_INFO("soft_body_sim: t = %.1f s simulated%s, real-time factor %.2f, %.1f us per physics step",
           world_->time(), paused_ ? " (paused)" : "", statistics_.real_time_factor,
           1e6 * statistics_.wall_seconds_per_step);
}

void SimNode::advance(double elapsed)
{
  const double dt = world_->settings().dt;
  accumulator_ += elapsed;
  // The accumulator makes the simulated time independent of timer jitter: whole steps only, the rest
  // carried to the next tick (the 1e-9 absorbs round-off in accumulator / dt).
  long steps = static_cast<long>(std::floor(accumulator_ / dt + 1e-9));
  if (steps > max_steps_per_tick_)
  {
    ROS_WARN_THROTTLE(5.0, "soft_body_sim: falling behind real time: %.3f s of simulation dropped this tick",
                      (steps - max_steps_per_tick_) * dt);
    epoch_ += ros::Duration(accumulator_ - max_steps_per_tick_ * dt);  // the dropped time
    steps = max_steps_per_tick_;
    accumulator_ = steps * dt;
  }
  const auto start = std::chrono::steady_clock::now();
  for (long n = 0; n < steps; ++n)
    world_->step();
  accumulator_ = std::max(0.0, accumulator_ - steps * dt);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (steps > 0)
    statistics_.wall_seconds_per_step = wall / static_cast<double>(steps);
  // Whole steps per tick alternate (e.g. 3 and 4 steps of 5 ms in 16.7 ms ticks): the real-time factor
  // is taken over windows of at least half a second.
  window_elapsed_ += elapsed;
  window_simulated_ += steps * dt;
  if (window_elapsed_ >= 0.5)
  {
    statistics_.real_time_factor = window_simulated_ / window_elapsed_;
    window_elapsed_ = window_simulated_ = 0.0;
  }
}

void SimNode::publish(const ros::Time& stamp)
{
  const State& state = world_->state();
  if (!state.position.allFinite() || !state.velocity.allFinite())
  {
    ROS_ERROR_THROTTLE(5.0, "soft_body_sim: the simulation holds non-finite values; nothing published");
    return;
  }
  markers_publisher_.publish(RosConverter::toMarkers(*world_, scene_.frame_id, stamp));
  state_publisher_.publish(RosConverter::toState(*world_, scene_.frame_id, stamp, statistics_));
}

bool SimNode::onReset(std_srvs::Empty::Request&, std_srvs::Empty::Response&)
{
  world_ = std::make_unique<World>(buildWorld(scene_));
  accumulator_ = 0.0;
  epoch_ = last_tick_;
  ROS_INFO("soft_body_sim: reset to the initial scene");
  return true;
}

bool SimNode::onPause(std_srvs::SetBool::Request& request, std_srvs::SetBool::Response& response)
{
  paused_ = request.data;
  accumulator_ = 0.0;
  response.success = true;
  response.message = paused_ ? "paused" : "running";
  return true;
}

}  // namespace soft_body_sim
