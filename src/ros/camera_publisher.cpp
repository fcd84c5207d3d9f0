// CameraPublisher: a camera's frames rendered on their own thread and published (camera_publisher.h).
#include "soft_body_sim/ros/camera_publisher.h"

#include <cmath>

#include <sys/resource.h>
#include <unistd.h>

#include "soft_body_sim/ros/ros_converter.h"

namespace soft_body_sim
{
namespace
{
/// The render thread's nice value (0 is the default, 19 the least favoured).
constexpr int kRenderNice = 10;
}  // namespace

CameraPublisher::CameraPublisher(const CameraDef& def, const Model& model, const ros::NodeHandle& private_nh)
  : def_(def), camera_(def, model), transport_(private_nh)
{
  ros::NodeHandle nh = private_nh;
  color_ = transport_.advertiseCamera(def.name + "/color/image_raw", 1);
  aligned_depth_ = transport_.advertiseCamera(def.name + "/aligned_depth_to_color/image_raw", 1);
  depth_ = transport_.advertise(def.name + "/depth/image_rect", 1);
  mask_ = transport_.advertise(def.name + "/mask", 1);
  points_ = nh.advertise<sensor_msgs::PointCloud2>(def.name + "/depth/points", 1);
  worker_ = std::thread([this] { run(); });
}

CameraPublisher::~CameraPublisher()
{
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  worker_.join();
}

bool CameraPublisher::watched() const
{
  return color_.getNumSubscribers() > 0 || aligned_depth_.getNumSubscribers() > 0 || depth_.getNumSubscribers() > 0 ||
         mask_.getNumSubscribers() > 0 || points_.getNumSubscribers() > 0;
}

std::uint64_t CameraPublisher::dropped() const
{
  std::lock_guard<std::mutex> lock(mutex_);
  return dropped_;
}

std::optional<std::uint64_t> CameraPublisher::due(double t)
{
  if (t + 1e-9 / def_.rate < static_cast<double>(frame_) / def_.rate)
    return std::nullopt;
  // The frame due now; any due before it (a step longer than a frame's period) are skipped.
  const std::uint64_t frame = static_cast<std::uint64_t>(std::floor(t * def_.rate + 1e-9));
  const std::uint64_t skipped = frame - std::min(frame, frame_);
  frame_ = frame + 1;
  if (!watched())
    return std::nullopt;
  std::lock_guard<std::mutex> lock(mutex_);
  dropped_ += skipped;
  return frame;
}

void CameraPublisher::shoot(std::uint64_t frame, const State& state, const std::vector<ColliderPose>& colliders,
                            const RigidPose& link, const ros::Time& stamp)
{
  std::lock_guard<std::mutex> lock(mutex_);
  dropped_ += pending_ ? 1 : 0;
  pending_ = Job{ state, colliders, link, stamp, frame };
  wake_.notify_one();
}

void CameraPublisher::run()
{
  // Below the physics step in the scheduler's favour (Linux: a thread's own nice value): on a busy
  // machine a frame comes late or is dropped (counted), rather than a step.
  setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), kRenderNice);
  for (;;)
  {
    Job job;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this] { return stop_ || pending_; });
      if (stop_)
        return;
      job = std::move(*pending_);
      pending_.reset();
    }
    camera_.render(job.state, job.colliders, job.link, job.frame, image_);
    publish(image_, job.stamp);
  }
}

void CameraPublisher::publish(const CameraImage& image, const ros::Time& stamp) const
{
  std_msgs::Header header;
  header.stamp = stamp;
  header.frame_id = def_.name + "_color_optical_frame";
  const sensor_msgs::CameraInfo info = RosConverter::toCameraInfo(camera_.intrinsics(), header);
  color_.publish(RosConverter::toColorImage(image, header), info);
  aligned_depth_.publish(RosConverter::toDepthMillimetres(image, header), info);
  depth_.publish(RosConverter::toDepthMetres(image, header));
  mask_.publish(RosConverter::toMask(image, header));
  points_.publish(RosConverter::toPointCloud(image, camera_.intrinsics(), header));
}

}  // namespace soft_body_sim
