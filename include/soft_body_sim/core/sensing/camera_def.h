// A simulated RGB-D camera as a scene declares it (`cameras:`): where it is, its image, its range, its noise.
// Plain data; the renderer is DepthCamera (depth_camera.h), the ROS topics the node's.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace soft_body_sim
{
/// Depth noise of a structured-light or stereo camera: Gaussian, its standard deviation growing with the
/// square of the depth, sigma(z) = depth_stddev (z / 1 m)^2.
struct DepthNoise
{
  double depth_stddev = 0.0;  ///< [m] at 1 m, >= 0
  std::uint64_t seed = 1;     ///< the same seed gives the same noise in every frame number: replays stay exact
};

struct CameraDef
{
  std::string name;   ///< its topics ~<name>/...; tf frames <name>_link, <name>_color_optical_frame
  std::string frame;  ///< a tf frame it rides on (the ROS node; its pose below is relative to it); empty: none
  /// [m] of <name>_link in the scene frame (or in `frame`); it looks along the link's +x with +z up (REP 103)
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  ///< of <name>_link (normalised where used)
  int width = 640;                ///< [px] > 0
  int height = 480;               ///< [px] > 0
  double horizontal_fov = 69.4;   ///< [deg] in (0, 180)
  double rate = 30.0;             ///< [Hz] frames per simulated second, > 0
  double min_range = 0.1;         ///< [m] nearer: no depth return, >= 0
  double max_range = 10.0;        ///< [m] farther: no depth return, > min_range
  Eigen::Vector3d background = Eigen::Vector3d::Constant(0.2);  ///< rgb in [0, 1] where nothing is hit
  std::optional<DepthNoise> noise;  ///< none: exact depth
};

/// The pinhole model of a camera's images, without distortion (sensor_msgs/CameraInfo's K):
/// fx = fy = (width / 2) / tan(horizontal_fov / 2), cx = (width - 1) / 2, cy = (height - 1) / 2.
/// Pixel (u, v) (column, row; u = 0 the left edge's pixel centre) sees along the optical frame's
/// ((u - cx) / fx, (v - cy) / fy, 1): z forward, x right, y down (REP 103's optical frame).
struct CameraIntrinsics
{
  int width = 0;
  int height = 0;
  double fx = 0.0, fy = 0.0;  ///< [px]
  double cx = 0.0, cy = 0.0;  ///< [px]

  static CameraIntrinsics of(const CameraDef& camera);
};

/// The rotation from <name>_link (x forward, z up) to <name>_color_optical_frame (z forward, x right,
/// y down): the optical frame's axes in the link's frame.
Eigen::Quaterniond linkToOptical();

/// Checks a camera as a scene declares it; throws DefinitionError naming the key at fault.
void checkCamera(const CameraDef& camera);

}  // namespace soft_body_sim
