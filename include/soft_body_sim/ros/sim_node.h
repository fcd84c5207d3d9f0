// The ROS node over the core: a timer advances the World in fixed steps and publishes markers and
// state; anchor and target poses arrive on topics in any tf frame; services reset and pause.
#pragma once

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include <geometry_msgs/PoseStamped.h>
#include <ros/ros.h>
#include <std_srvs/Empty.h>
#include <std_srvs/SetBool.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include "soft_body_sim/core/scene_def.h"
#include "soft_body_sim/ros/ros_converter.h"

namespace soft_body_sim
{
class SimNode
{
public:
  /// @param nh the node's namespace handle; @param private_nh its private (~) handle
  SimNode(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh);

  /// Loads the scene named by ~scene with the package's loader, then creates the topics, services and
  /// the timer. Throws SceneError (or std::runtime_error) with one clear line if it cannot start.
  void initialize();

private:
  void onTimer(const ros::TimerEvent& event);
  /// Advances the accumulator by `elapsed` [s] of ROS time in fixed steps, at most max_steps_per_tick_.
  void advance(double elapsed);
  /// Publishes markers and state stamped `stamp`, the ROS time of the simulated instant.
  void publish(const ros::Time& stamp);
  void printStatus(const ros::Time& now);

  /// The pose's position in the scene frame; false (with a throttled warning naming `topic` and the
  /// reason) if it is not finite or its frame cannot be transformed.
  bool toSceneFrame(const geometry_msgs::PoseStamped& pose, const std::string& topic, Vec3& position);
  void subscribeInputs();

  bool onReset(std_srvs::Empty::Request& request, std_srvs::Empty::Response& response);
  bool onPause(std_srvs::SetBool::Request& request, std_srvs::SetBool::Response& response);

  ros::NodeHandle nh_;
  ros::NodeHandle private_nh_;
  SceneDef scene_;
  std::unique_ptr<World> world_;
  double rate_ = 60.0;          ///< [Hz] of the timer
  double status_period_ = 0.0;  ///< [s] between status lines on the console; 0 = none
  long max_steps_per_tick_ = 1;  ///< catch-up cap: two ticks' worth of steps

  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  ros::Publisher markers_publisher_;
  ros::Publisher state_publisher_;
  std::vector<ros::Subscriber> subscribers_;
  ros::ServiceServer reset_service_;
  ros::ServiceServer pause_service_;
  ros::Timer timer_;

  ros::Time last_tick_;
  /// The ROS time of simulated time 0: the first tick, moved on by pauses, dropped catch-up and resets,
  /// so that epoch_ + world time stamps each output with its simulated instant.
  ros::Time epoch_;
  ros::Time last_status_;
  double accumulator_ = 0.0;  ///< [s] of ROS time not yet simulated
  double window_elapsed_ = 0.0;    ///< [s] of ROS time in the current real-time-factor window
  double window_simulated_ = 0.0;  ///< [s] simulated in it
  bool paused_ = false;
  StepStatistics statistics_;
};

}  // namespace soft_body_sim
