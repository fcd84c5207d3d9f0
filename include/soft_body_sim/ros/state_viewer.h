// The state viewer: a recording's markers rebuilt from its `~state` and the scene file, for rviz (play.launch).
// It never steps: each SimState's positions, rods' twists and colliders' poses are drawn as the simulator
// draws its own (RosConverter::toMarkers), so a bag needs no markers (record.launch).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <ros/ros.h>
#include <visualization_msgs/MarkerArray.h>

#include "soft_body_sim/SimState.h"
#include "soft_body_sim/core/scene_def.h"
#include "soft_body_sim/core/world.h"
#include "soft_body_sim/ros/ros_converter.h"

namespace soft_body_sim
{
/// Subscribes to `state` (soft_body_sim/SimState) and publishes `markers` and `force_markers`
/// (visualization_msgs/MarkerArray), all relative to `nh`, from the scene file in `~scene` of `private_nh`
/// (and the arrows' `~force_scale` [m/N], as the simulator's).
class StateViewer
{
public:
  StateViewer(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh);

  /// Loads `~scene` (and the robot's colliders from its URDF parameter if the scene has them), then
  /// subscribes and advertises. Throws std::runtime_error, naming the parameter or file, if it cannot.
  void initialize();

  /// The markers of `message` drawn on the scene's bodies, and the forces on their holders; false (and
  /// why) if its bodies are not the scene's (names and node counts, in order) or a position is not finite.
  bool draw(const SimState& message, visualization_msgs::MarkerArray& markers,
            visualization_msgs::MarkerArray& force_markers, std::string& why) const;

private:
  void onState(const SimState& message);

  ros::NodeHandle nh_;
  ros::NodeHandle private_nh_;
  std::string scene_path_;
  SceneDef scene_;
  std::unique_ptr<World> world_;         ///< the scene's model and controllers; never stepped
  std::vector<ColliderPose> colliders_;  ///< every shape of the scene, in the simulator's drawing order
  ros::Subscriber subscriber_;
  ros::Publisher publisher_;
  ros::Publisher force_publisher_;
  double force_scale_ = RosConverter::kForceScale;
};

}  // namespace soft_body_sim
