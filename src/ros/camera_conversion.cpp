// RosConverter: a camera's frame as sensor_msgs images, its CameraInfo and its organised point cloud.
#include <cstring>
#include <limits>

#include <sensor_msgs/image_encodings.h>
#include <sensor_msgs/point_cloud2_iterator.h>

#include "soft_body_sim/core/sensing/depth_camera.h"
#include "soft_body_sim/ros/ros_converter.h"

namespace soft_body_sim
{
namespace
{
/// An image of `image`'s size with `bytes_per_pixel` bytes a pixel, its samples copied from `data`.
sensor_msgs::Image imageOf(const CameraImage& image, const std_msgs::Header& header, const std::string& encoding,
                           std::size_t bytes_per_pixel, const void* data)
{
  sensor_msgs::Image out;
  out.header = header;
  out.width = static_cast<std::uint32_t>(image.width);
  out.height = static_cast<std::uint32_t>(image.height);
  out.encoding = encoding;
  out.is_bigendian = 0;  // samples in this machine's (little-endian) order, as every ROS driver here
  out.step = static_cast<std::uint32_t>(bytes_per_pixel * static_cast<std::size_t>(image.width));
  out.data.resize(static_cast<std::size_t>(out.step) * static_cast<std::size_t>(image.height));
  std::memcpy(out.data.data(), data, out.data.size());
  return out;
}
}  // namespace

sensor_msgs::CameraInfo RosConverter::toCameraInfo(const CameraIntrinsics& k, const std_msgs::Header& header)
{
  sensor_msgs::CameraInfo info;
  info.header = header;
  info.width = static_cast<std::uint32_t>(k.width);
  info.height = static_cast<std::uint32_t>(k.height);
  info.distortion_model = "plumb_bob";
  info.D.assign(5, 0.0);
  info.K = { k.fx, 0.0, k.cx, 0.0, k.fy, k.cy, 0.0, 0.0, 1.0 };
  info.R = { 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0 };
  info.P = { k.fx, 0.0, k.cx, 0.0, 0.0, k.fy, k.cy, 0.0, 0.0, 0.0, 1.0, 0.0 };
  return info;
}

sensor_msgs::Image RosConverter::toColorImage(const CameraImage& image, const std_msgs::Header& header)
{
  return imageOf(image, header, sensor_msgs::image_encodings::RGB8, 3, image.color.data());
}

sensor_msgs::Image RosConverter::toDepthMillimetres(const CameraImage& image, const std_msgs::Header& header)
{
  const std::vector<std::uint16_t> millimetres = depthMillimetres(image);
  return imageOf(image, header, sensor_msgs::image_encodings::TYPE_16UC1, 2, millimetres.data());
}

sensor_msgs::Image RosConverter::toDepthMetres(const CameraImage& image, const std_msgs::Header& header)
{
  return imageOf(image, header, sensor_msgs::image_encodings::TYPE_32FC1, 4, image.depth.data());
}

sensor_msgs::Image RosConverter::toMask(const CameraImage& image, const std_msgs::Header& header)
{
  return imageOf(image, header, sensor_msgs::image_encodings::TYPE_16UC1, 2, image.mask.data());
}

sensor_msgs::PointCloud2 RosConverter::toPointCloud(const CameraImage& image, const CameraIntrinsics& k,
                                                    const std_msgs::Header& header)
{
  sensor_msgs::PointCloud2 cloud;
  cloud.header = header;
  cloud.height = static_cast<std::uint32_t>(image.height);
  cloud.width = static_cast<std::uint32_t>(image.width);
  cloud.is_dense = false;  // NaN where there is no return
  cloud.is_bigendian = false;
  sensor_msgs::PointCloud2Modifier modifier(cloud);
  modifier.setPointCloud2Fields(4, "x", 1, sensor_msgs::PointField::FLOAT32, "y", 1, sensor_msgs::PointField::FLOAT32,
                                "z", 1, sensor_msgs::PointField::FLOAT32, "rgb", 1, sensor_msgs::PointField::FLOAT32);
  sensor_msgs::PointCloud2Iterator<float> x(cloud, "x"), y(cloud, "y"), z(cloud, "z");
  sensor_msgs::PointCloud2Iterator<std::uint8_t> rgb(cloud, "rgb");
  const float none = std::numeric_limits<float>::quiet_NaN();
  for (int v = 0; v < image.height; ++v)
    for (int u = 0; u < image.width; ++u, ++x, ++y, ++z, ++rgb)
    {
      const std::size_t pixel = static_cast<std::size_t>(v) * static_cast<std::size_t>(image.width) + static_cast<std::size_t>(u);
      const float depth = image.depth[pixel];
      const bool hit = depth == depth;  // not NaN
      *x = hit ? static_cast<float>((u - k.cx) / k.fx * depth) : none;
      *y = hit ? static_cast<float>((v - k.cy) / k.fy * depth) : none;
      *z = hit ? depth : none;
      // PCL's packing: the float's bytes are b, g, r, 0 on a little-endian machine.
      rgb[0] = image.color[3 * pixel + 2];
      rgb[1] = image.color[3 * pixel + 1];
      rgb[2] = image.color[3 * pixel];
      rgb[3] = 0;
    }
  return cloud;
}

}  // namespace soft_body_sim
