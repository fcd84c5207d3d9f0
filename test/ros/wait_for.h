// Polling helper of the gtest rostests: spins the node's callbacks until a condition holds.
#pragma once

#include <functional>

#include <ros/ros.h>

namespace soft_body_sim
{
/// Spins callbacks every 2 ms until `condition` holds (true) or `timeout` [s] of wall time passes (false).
inline bool waitFor(const std::function<bool()>& condition, double timeout)
{
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout);
  while (ros::ok() && ros::WallTime::now() < end)
  {
    ros::spinOnce();
    if (condition())
      return true;
    ros::WallDuration(0.002).sleep();
  }
  return false;
}

}  // namespace soft_body_sim
