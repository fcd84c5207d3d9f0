// CameraDef's pinhole model, its optical frame and its checks (camera_def.h).
#include "soft_body_sim/core/sensing/camera_def.h"

#include <cmath>

#include "soft_body_sim/core/definition_error.h"

namespace soft_body_sim
{
CameraIntrinsics CameraIntrinsics::of(const CameraDef& camera)
{
  CameraIntrinsics k;
  k.width = camera.width;
  k.height = camera.height;
  k.fx = k.fy = 0.5 * camera.width / std::tan(0.5 * camera.horizontal_fov * M_PI / 180.0);
  k.cx = 0.5 * (camera.width - 1);
  k.cy = 0.5 * (camera.height - 1);
  return k;
}

Eigen::Quaterniond linkToOptical()
{
  Eigen::Matrix3d axes;
  axes.col(0) = -Eigen::Vector3d::UnitY();  // optical x: right, the link's -y
  axes.col(1) = -Eigen::Vector3d::UnitZ();  // optical y: down, the link's -z
  axes.col(2) = Eigen::Vector3d::UnitX();   // optical z: forward, the link's x
  return Eigen::Quaterniond(axes);
}

void checkCamera(const CameraDef& camera)
{
  const std::string what = "camera '" + camera.name + "'";
  requireDefinition(!camera.name.empty(), "a camera", { "name" }, "name must not be empty");
  requireDefinition(camera.position.allFinite(), what, { "position" }, "position must be finite");
  requireDefinition(camera.orientation.coeffs().allFinite() && camera.orientation.norm() > 1e-12, what,
                    { "orientation" }, "orientation must be a finite, non-zero quaternion [x, y, z, w]");
  // An image of 16384 x 16384 is 268 million rays a frame: a typo, not a camera.
  requireDefinition(camera.width > 0 && camera.width <= 16384, what, { "width" }, "width must be from 1 to 16384 px");
  requireDefinition(camera.height > 0 && camera.height <= 16384, what, { "height" },
                    "height must be from 1 to 16384 px");
  requireDefinition(camera.horizontal_fov > 0.0 && camera.horizontal_fov < 180.0, what, { "horizontal_fov" },
                    "horizontal_fov must be between 0 and 180 degrees (exclusive)");
  requireDefinition(camera.rate > 0.0 && std::isfinite(camera.rate), what, { "rate" }, "rate must be a finite number > 0 [Hz]");
  requireDefinition(camera.min_range >= 0.0 && std::isfinite(camera.min_range), what, { "min_range" },
                    "min_range must be a finite number >= 0 [m]");
  requireDefinition(camera.max_range > camera.min_range && std::isfinite(camera.max_range), what,
                    { "max_range", "min_range" }, "max_range must be finite and greater than min_range");
  requireDefinition((camera.background.array() >= 0.0).all() && (camera.background.array() <= 1.0).all(), what,
                    { "background" }, "background is [r, g, b], each from 0 to 1");
  if (camera.noise)
    requireDefinition(camera.noise->depth_stddev >= 0.0 && std::isfinite(camera.noise->depth_stddev), what,
                      { "noise.depth_stddev", "noise" }, "noise.depth_stddev must be a finite number >= 0 [m]");
}

}  // namespace soft_body_sim
