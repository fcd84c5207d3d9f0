// A camera's frames as PNG files, for datasets without ROS (`simulate --images DIR`): libpng, Debian's
// libpng-dev.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "soft_body_sim/core/sensing/depth_camera.h"

namespace soft_body_sim
{
/// Writes `<directory>/<camera>_color_<frame>.png` (8-bit rgb), `<camera>_depth_<frame>.png` (16-bit grey,
/// depthMillimetres) and `<camera>_mask_<frame>.png` (16-bit grey, CameraImage::mask), the frame number
/// zero-padded to six digits so that names sort in time. Throws std::runtime_error naming a file it cannot
/// write.
void writeCameraImages(const std::string& directory, const std::string& camera, std::uint64_t frame,
                       const CameraImage& image);

/// Reads a 16-bit grey PNG that writeCameraImages wrote (for tests and tools): its width, height and
/// samples row by row. Throws std::runtime_error if it cannot.
struct GreyImage16
{
  int width = 0, height = 0;
  std::vector<std::uint16_t> samples;
};
GreyImage16 readGreyPng16(const std::string& path);

}  // namespace soft_body_sim
