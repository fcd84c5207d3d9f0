#include "soft_body_sim/ros/state_viewer.h"

int main(int argc, char** argv)
{
  ros::init(argc, argv, "soft_body_sim_viewer");
  soft_body_sim::StateViewer viewer(ros::NodeHandle(), ros::NodeHandle("~"));
  try
  {
    viewer.initialize();
  }
  catch (const std::exception& e)
  {
    ROS_FATAL("%s", e.what());
    return 1;
  }
  ros::spin();
  return 0;
}
