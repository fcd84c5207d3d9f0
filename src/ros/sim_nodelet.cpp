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
  /// What SimNode::initialize throws (a scene that fails to load, a bad parameter) is logged and thrown
  /// on: nodelet's Loader::load catches it, drops the nodelet and fails the load, so that `nodelet load`
  /// exits non-zero and a launch requiring it stops, as the node does.
  void onInit() override
  {
    node_ = std::make_unique<SimNode>(getNodeHandle(), getPrivateNodeHandle(), getName());
    try
    {
      node_->initialize();
    }
    catch (const std::exception& e)
    {
      // Debian's nodelet (1.10) says only "Failed to initialize nodelet NAME", at debug level.
      NODELET_FATAL("%s", e.what());
      throw;
    }
  }

  std::unique_ptr<SimNode> node_;
};

}  // namespace soft_body_sim

PLUGINLIB_EXPORT_CLASS(soft_body_sim::SimNodelet, nodelet::Nodelet)
