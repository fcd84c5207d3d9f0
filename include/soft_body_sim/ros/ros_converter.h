// Every conversion between the core and ROS messages, in one place (as grid_map's
// GridMapRosConverter): markers and state out, poses in, reconfigure configs both ways. Plain functions
// of plain data, unit-tested without a ROS master. One class, a source file per kind of message:
// src/ros/marker_conversion.cpp, state_conversion.cpp, pose_conversion.cpp, reconfigure_conversion.cpp,
// camera_conversion.cpp.
#pragma once

#include <string>
#include <vector>

#include <optional>

#include <geometry_msgs/Point.h>
#include <geometry_msgs/Pose.h>
#include <geometry_msgs/Transform.h>
#include <geometry_msgs/Vector3.h>
#include <geometry_msgs/WrenchStamped.h>
#include <ros/time.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_msgs/Header.h>
#include <visualization_msgs/MarkerArray.h>

#include "soft_body_sim/BodyConfig.h"
#include "soft_body_sim/SimConfig.h"
#include "soft_body_sim/SimState.h"
#include "soft_body_sim/core/sensing/depth_camera.h"
#include "soft_body_sim/core/world.h"

namespace soft_body_sim
{
/// Step statistics reported with the state.
struct StepStatistics
{
  double real_time_factor = 0.0;       ///< simulated seconds per wall second over the last tick [-]
  double wall_seconds_per_step = 0.0;  ///< wall time of one physics step [s]
  unsigned divergence_events = 0;      ///< catches of the divergence guard since the node started
};

/// What holds a body, an anchor or a grasp, and the wrench the body exerts on it.
struct Holder
{
  std::size_t body = 0;  ///< index into Model::bodies
  std::string name;      ///< the anchor's name or the grasp's frame
  Vec3 origin = Vec3::Zero();  ///< [m] the anchor's node or the grasp frame's origin: the torque's point
  Wrench wrench;
};

class RosConverter
{
public:
  // --- rviz markers (marker_conversion.cpp) ---

  /// One namespace per body (its name): id 0 a SPHERE_LIST of its nodes in node order, id 1 a
  /// LINE_LIST of its springs and constraints, ids 2.. a LINE_STRIP per curve of its controller (limbs);
  /// and namespace "colliders": each sphere, capsule and box in its current pose (a capsule as a
  /// CYLINDER with two SPHERE caps).
  /// Non-finite positions are never published: such a node is left out of the markers. A marker
  /// without points (a body without springs) is sent with action DELETE.
  static visualization_msgs::MarkerArray toMarkers(const World& world, const std::string& frame_id,
                                                   const ros::Time& stamp);
  /// The same of a model in `state`, its bodies' `controllers` and the colliders in `colliders`' poses
  /// (World::colliderPoses): what a world shows, drawn from a recorded state (state_viewer.h).
  static visualization_msgs::MarkerArray toMarkers(const Model& model, const State& state,
                                                   const std::vector<BodyController>& controllers,
                                                   const std::vector<ColliderPose>& colliders,
                                                   const std::string& frame_id, const ros::Time& stamp);
  /// The forces on the holders (see holders()): a DELETEALL (arrows of holders gone disappear), then in
  /// namespace "forces" per holder k, id k, an ARROW from its origin along the force the body exerts on
  /// it, force_scale [m/N] long.
  /// [m/N] the force arrows' length per newton unless ~force_scale says otherwise.
  static constexpr double kForceScale = 0.02;
  static visualization_msgs::MarkerArray toForceMarkers(const std::vector<Holder>& holders, double force_scale,
                                                        const std::string& frame_id, const ros::Time& stamp);

  // --- the state and the holders' wrenches (state_conversion.cpp) ---

  /// The state: per body its name, positions [m], velocities [m/s], integrator, what the divergence guard
  /// did to it, its holders (`holders`, see holders()) and their wrenches, its links' tensions and the
  /// `slips` of its grasps; the step statistics; and the named colliders' wrenches (World::colliderWrenches).
  static SimState toState(const World& world, const std::string& frame_id, const ros::Time& stamp,
                          const StepStatistics& statistics, const std::vector<Holder>& holders = {},
                          const std::vector<GraspSlip>& slips = {});
  /// Every anchor (model order), then every grasp, with the wrench its body exerts on it.
  static std::vector<Holder> holders(const World& world);
  static geometry_msgs::WrenchStamped toWrench(const Wrench& wrench, const std::string& frame_id, const ros::Time& stamp);

  // --- poses and points (pose_conversion.cpp) ---

  /// The position [m] of a pose; false (and why) if any field of the pose is NaN or infinite.
  static bool fromPose(const geometry_msgs::Pose& pose, Vec3& position, std::string& why);
  /// fromPose, and its orientation made unit, or nullopt when it is all zeros (a message that sets only a
  /// position: an anchor holding a rod's end then keeps its orientation).
  static bool fromPose(const geometry_msgs::Pose& pose, Vec3& position, std::optional<Eigen::Quaterniond>& orientation,
                       std::string& why);

  /// A pose at `position` [m] with the identity orientation (anchors and handles have no orientation).
  static geometry_msgs::Pose toPose(const Vec3& position);
  /// A rigid pose as a message pose, as it is.
  static geometry_msgs::Pose toPose(const RigidPose& pose);
  /// The point of a message [m], as it is (not checked: see fromPose for inputs).
  static Vec3 toVec3(const geometry_msgs::Point& point) { return Vec3(point.x, point.y, point.z); }
  /// A translation [m], as it is.
  static Vec3 toVec3(const geometry_msgs::Vector3& vector) { return Vec3(vector.x, vector.y, vector.z); }
  /// A position [m] as a message point, as it is (the inverse of toVec3).
  static geometry_msgs::Point toPoint(const Vec3& p) { return xyzMessage<geometry_msgs::Point>(p); }
  /// A vector (a velocity [m/s], a force [N], a torque [N m]) as a message vector, as it is.
  static geometry_msgs::Vector3 toVector3(const Vec3& v) { return xyzMessage<geometry_msgs::Vector3>(v); }

  /// A transform as a rigid pose; nullopt if any field is not finite or the rotation is zero.
  static std::optional<RigidPose> toRigidPose(const geometry_msgs::Transform& transform);
  /// A pose as a rigid pose; nullopt if any field is not finite or the orientation is zero.
  static std::optional<RigidPose> toRigidPose(const geometry_msgs::Pose& pose);

  // --- camera images (camera_conversion.cpp) ---

  /// The camera's pinhole model (CameraIntrinsics) as its CameraInfo: K, P (no baseline), R the identity,
  /// no distortion ("plumb_bob", all zeros).
  static sensor_msgs::CameraInfo toCameraInfo(const CameraIntrinsics& intrinsics, const std_msgs::Header& header);
  /// The colour image, rgb8.
  static sensor_msgs::Image toColorImage(const CameraImage& image, const std_msgs::Header& header);
  /// The depth as 16UC1 millimetres, 0 = no return (as the RealSense driver's aligned depth).
  static sensor_msgs::Image toDepthMillimetres(const CameraImage& image, const std_msgs::Header& header);
  /// The depth as 32FC1 metres, NaN = no return (REP 118).
  static sensor_msgs::Image toDepthMetres(const CameraImage& image, const std_msgs::Header& header);
  /// The mask, 16UC1 (CameraImage::mask).
  static sensor_msgs::Image toMask(const CameraImage& image, const std_msgs::Header& header);
  /// The organised cloud (height x width) of the depth back-projected with the intrinsics, in the optical
  /// frame: fields x, y, z and rgb as float32 (rgb packed as PCL does, 0x00RRGGBB in a float's bits); NaN
  /// where there is no return.
  static sensor_msgs::PointCloud2 toPointCloud(const CameraImage& image, const CameraIntrinsics& intrinsics,
                                               const std_msgs::Header& header);

  // --- dynamic_reconfigure configs (reconfigure_conversion.cpp) ---

  /// The world's live physics as the node's reconfigure config (~): integrator, dt, substeps,
  /// iterations, gravity, drag.
  static SimConfig toSimConfig(const World& world);
  /// The integrator a config names; false (and why, quoting at most 32 characters of the name) if it
  /// names none.
  static bool integratorOf(const SimConfig& config, IntegratorType& integrator, std::string& why);
  static StepSettings stepSettingsOf(const SimConfig& config)
  {
    return StepSettings{ config.dt, config.substeps, config.iterations };
  }
  static Vec3 gravityOf(const SimConfig& config) { return Vec3(config.gravity_x, config.gravity_y, config.gravity_z); }
  /// A body's reconfigure config (~<body>) as its material factors.
  static BodyScaling toBodyScaling(const BodyConfig& config)
  {
    return BodyScaling{ config.stiffness_scale, config.damping_scale, config.pressure_scale };
  }

private:
  /// A message of three fields x, y, z (a point, a vector) holding `v`.
  template <typename Message>
  static Message xyzMessage(const Vec3& v)
  {
    Message out;
    out.x = v.x();
    out.y = v.y();
    out.z = v.z();
    return out;
  }
};

}  // namespace soft_body_sim
