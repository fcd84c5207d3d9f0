// A scene's camera in the node: it renders the world as it was at each of its frames (DepthCamera) on a
// thread of its own, off the physics step, and publishes what a RealSense driver publishes, all with the
// frame's stamp and frame_id <name>_color_optical_frame:
//   ~<name>/color/image_raw (rgb8) and color/camera_info,
//   ~<name>/aligned_depth_to_color/image_raw (16UC1 mm) and aligned_depth_to_color/camera_info,
//   ~<name>/depth/image_rect (32FC1 m), ~<name>/depth/points (organised XYZRGB), ~<name>/mask (16UC1).
// The step only copies the state (its positions) and hands it over: a frame still rendering when the next
// is due makes that one wait, and one still waiting is replaced by the newer (counted in dropped()). With
// no subscriber to any of its topics it renders nothing.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <image_transport/image_transport.h>
#include <ros/ros.h>

#include "soft_body_sim/core/sensing/depth_camera.h"

namespace soft_body_sim
{
class CameraPublisher
{
public:
  /// Advertises camera `def`'s topics under `private_nh` (~<name>/...).
  CameraPublisher(const CameraDef& def, const Model& model, const ros::NodeHandle& private_nh);
  ~CameraPublisher();
  CameraPublisher(const CameraPublisher&) = delete;
  CameraPublisher& operator=(const CameraPublisher&) = delete;

  const CameraDef& def() const { return def_; }
  /// The number of the frame due at simulated time t [s] (frame n at n / rate, from t = 0) if one is due
  /// and anyone listens to any of the camera's topics; it is then taken (shoot). Frames due before it are
  /// skipped.
  std::optional<std::uint64_t> due(double t);
  /// Hands frame `frame` (due) to the render thread, stamped `stamp`: the nodes at `state`, the colliders
  /// at `colliders`, the camera's link at `link` in the scene frame.
  void shoot(std::uint64_t frame, const State& state, const std::vector<ColliderPose>& colliders,
             const RigidPose& link, const ros::Time& stamp);
  /// Frames someone listened for that were skipped, since the start: the render thread was busy (a frame
  /// still waiting replaced by the next) or a tick took more than a frame's period.
  std::uint64_t dropped() const;
  /// From simulated time 0 again (a reset).
  void restart() { frame_ = 0; }

private:
  struct Job
  {
    State state;
    std::vector<ColliderPose> colliders;
    RigidPose link;
    ros::Time stamp;
    std::uint64_t frame = 0;
  };
  /// True if anyone listens to any of its topics.
  bool watched() const;
  void run();
  void publish(const CameraImage& image, const ros::Time& stamp) const;

  CameraDef def_;
  DepthCamera camera_;
  CameraImage image_;  ///< the render thread's frame, its buffers reused
  std::uint64_t frame_ = 0;  ///< the next frame's number
  image_transport::ImageTransport transport_;
  image_transport::CameraPublisher color_, aligned_depth_;
  image_transport::Publisher depth_, mask_;
  ros::Publisher points_;

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::optional<Job> pending_;
  bool stop_ = false;
  std::uint64_t dropped_ = 0;
  std::thread worker_;
};

}  // namespace soft_body_sim
