#include "soft_body_sim/ros/anchor_handles.h"

#include <cmath>

#include <geometry_msgs/PoseStamped.h>
#include <visualization_msgs/InteractiveMarker.h>

#include "soft_body_sim/ros/ros_converter.h"

namespace soft_body_sim
{
namespace
{
constexpr double kHandleSize = 0.25;     // [m] scale of the arrows
constexpr double kSphereSize = 0.06;     // [m] the grip
constexpr double kDragHold = 0.5;        // [s] after a drag's last feedback the simulation leads again
constexpr double kMoveThreshold = 1e-4;  // [m] smaller motions are not sent to rviz

/// An arrow that moves along one axis. A control acts along the x axis of its orientation; as in the
/// interactive_markers tutorials, a quarter turn about x keeps x, about z turns x onto y, about y onto
/// the z line. @param q the quarter turn's axis: (1, 0, 0), (0, 0, 1) or (0, 1, 0)
visualization_msgs::InteractiveMarkerControl axisControl(const std::string& name, double qx, double qy, double qz)
{
  visualization_msgs::InteractiveMarkerControl control;
  control.name = name;
  control.interaction_mode = visualization_msgs::InteractiveMarkerControl::MOVE_AXIS;
  control.orientation.w = std::sqrt(0.5);
  control.orientation.x = qx * std::sqrt(0.5);
  control.orientation.y = qy * std::sqrt(0.5);
  control.orientation.z = qz * std::sqrt(0.5);
  return control;
}
}  // namespace

AnchorHandles::AnchorHandles(const std::string& topic_ns, const std::string& frame_id)
  : frame_id_(frame_id), server_topic_(topic_ns), server_(topic_ns)
{
}

void AnchorHandles::add(const std::string& name, const std::string& topic, const Vec3& position)
{
  visualization_msgs::InteractiveMarker marker;
  marker.header.frame_id = frame_id_;
  marker.name = name;
  marker.description = name;
  marker.scale = kHandleSize;
  marker.pose = RosConverter::toPose(position);

  // The grip: a sphere dragged in the view plane (MOVE_3D), plus an arrow per axis.
  visualization_msgs::InteractiveMarkerControl grip;
  grip.name = "move_3d";
  grip.interaction_mode = visualization_msgs::InteractiveMarkerControl::MOVE_3D;
  grip.always_visible = true;
  visualization_msgs::Marker sphere;
  sphere.type = visualization_msgs::Marker::SPHERE;
  sphere.scale.x = sphere.scale.y = sphere.scale.z = kSphereSize;
  sphere.color.r = sphere.color.g = sphere.color.b = 0.9f;
  sphere.color.a = 0.6f;
  sphere.pose.orientation.w = 1.0;
  grip.markers.push_back(sphere);
  marker.controls.push_back(grip);
  marker.controls.push_back(axisControl("move_x", 1, 0, 0));
  marker.controls.push_back(axisControl("move_y", 0, 0, 1));
  marker.controls.push_back(axisControl("move_z", 0, 1, 0));

  std::lock_guard<std::mutex> lock(mutex_);
  Handle& handle = handles_[name];
  handle.publisher = nh_.advertise<geometry_msgs::PoseStamped>(topic, 10);
  handle.shown = position;
  server_.insert(marker, [this](const visualization_msgs::InteractiveMarkerFeedbackConstPtr& feedback) {
    onFeedback(feedback);
  });
  changed_ = true;
}

void AnchorHandles::onFeedback(const visualization_msgs::InteractiveMarkerFeedbackConstPtr& feedback)
{
  if (feedback->event_type != visualization_msgs::InteractiveMarkerFeedback::POSE_UPDATE &&
      feedback->event_type != visualization_msgs::InteractiveMarkerFeedback::MOUSE_UP)
    return;
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = handles_.find(feedback->marker_name);
  if (it == handles_.end())
    return;
  Vec3 position;
  std::string why;
  if (!RosConverter::fromPose(feedback->pose, position, why))
  {
    // The server has already taken the pose for the handle's next update (processFeedback, before this
    // callback): put the handle back where it was, so that no client is sent the non-finite pose.
    ROS_WARN_THROTTLE(5.0, "%s: handle '%s' feedback dropped: %s", server_topic_.c_str(),
                      feedback->marker_name.c_str(), why.c_str());
    server_.setPose(feedback->marker_name, RosConverter::toPose(it->second.shown));
    changed_ = true;
    return;
  }
  geometry_msgs::PoseStamped pose;
  pose.header.frame_id = feedback->header.frame_id.empty() ? frame_id_ : feedback->header.frame_id;
  // Stamped now, as a node publishing on the topic would: the node schedules the input by this stamp
  // and a recorded drag replays at the same step.
  pose.header.stamp = ros::Time::now();
  pose.pose = feedback->pose;
  it->second.publisher.publish(pose);
  it->second.shown = position;
  it->second.dragged_until = ros::WallTime::now() + ros::WallDuration(kDragHold);
}

void AnchorHandles::follow(const std::string& name, const Vec3& position)
{
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = handles_.find(name);
  if (it == handles_.end() || ros::WallTime::now() < it->second.dragged_until ||
      (position - it->second.shown).norm() < kMoveThreshold || !position.allFinite())
    return;
  server_.setPose(name, RosConverter::toPose(position));
  it->second.shown = position;
  changed_ = true;
}

void AnchorHandles::applyChanges()
{
  std::lock_guard<std::mutex> lock(mutex_);
  if (!changed_)
    return;
  server_.applyChanges();
  changed_ = false;
}

}  // namespace soft_body_sim
