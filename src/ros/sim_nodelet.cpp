// The simulator as a nodelet, for in-process use next to a controller (zero-copy messages): the same
// SimNode as soft_body_sim_node, on the nodelet's handles, whose callbacks run one at a time.
#include <memory>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include "soft_body_sim/ros/sim_node.h"

namespace soft_body_sim
{
class SimNodelet : public nodelet::Nodelet
{
private:
  void onInit() override
  {
    node_ = std::make_unique<SimNode>(getNodeHandle(), getPrivateNodeHandle(), getName());
    try
    {
      node_->initialize();
    }
    catch (const std::exception& e)
    {
      // A nodelet cannot stop its manager: say why it does nothing, and do nothing.
      NODELET_FATAL("%s", e.what());
      node_.reset();
    }
  }

  std::unique_ptr<SimNode> node_;
};

}  // namespace soft_body_sim

PLUGINLIB_EXPORT_CLASS(soft_body_sim::SimNodelet, nodelet::Nodelet)
