#include "soft_body_sim/ros/sim_node.h"

int main(int argc, char** argv)
{
  ros::init(argc, argv, "soft_body_sim");
  soft_body_sim::SimNode node(ros::NodeHandle(), ros::NodeHandle("~"));
  try
  {
    node.initialize();
  }
  catch (const std::exception& e)
  {
    ROS_FATAL("%s", e.what());
    return 1;
  }
  ros::spin();
  return 0;
}
