// Drag in rviz: one interactive marker per anchor and per target, on ~handles. Moving a handle publishes
// the pose on the anchor's or target's own topic, exactly as another node would, so a drag goes through
// the same input path (stamp scheduling, tf) and rosbag records it with the other inputs.
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <string>

#include <interactive_markers/interactive_marker_server.h>
#include <ros/ros.h>

#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
class AnchorHandles
{
public:
  /// @param topic_ns the server's namespace (resolved), e.g. /soft_body_sim/handles
  /// @param frame_id the scene's fixed frame, in which handles are placed and report their poses
  AnchorHandles(const std::string& topic_ns, const std::string& frame_id);

  /// Adds a handle `name` at `position` [m] that publishes its poses (PoseStamped) on `topic`. A feedback
  /// pose that is not finite is dropped with a throttled warning and the handle stays where it was.
  void add(const std::string& name, const std::string& topic, const Vec3& position);

  /// Moves handle `name` to where the simulation has it, unless it is being dragged; call applyChanges()
  /// after a batch.
  void follow(const std::string& name, const Vec3& position);
  void applyChanges();

private:
  struct Handle
  {
    ros::Publisher publisher;
    Vec3 shown = Vec3::Zero();     ///< [m] where the handle was last placed
    ros::WallTime dragged_until;   ///< a drag in progress: the simulation does not move the handle
  };

  void onFeedback(const visualization_msgs::InteractiveMarkerFeedbackConstPtr& feedback);

  std::string frame_id_;
  std::string server_topic_;  ///< the server's namespace, for log lines
  ros::NodeHandle nh_;
  interactive_markers::InteractiveMarkerServer server_;
  std::mutex mutex_;  ///< feedback arrives on the server's queue, follow() on the simulation's
  std::map<std::string, Handle> handles_;
  bool changed_ = false;
};

}  // namespace soft_body_sim
