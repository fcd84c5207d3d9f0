// RosConverter: poses and transforms in (checked), poses out.
#include "soft_body_sim/ros/ros_converter.h"

namespace soft_body_sim
{
geometry_msgs::Pose RosConverter::toPose(const Vec3& position)
{
  geometry_msgs::Pose pose;
  pose.position.x = position.x();
  pose.position.y = position.y();
  pose.position.z = position.z();
  pose.orientation.w = 1.0;
  return pose;
}

geometry_msgs::Pose RosConverter::toPose(const RigidPose& rigid)
{
  geometry_msgs::Pose pose;
  pose.position = toPoint(rigid.position);
  pose.orientation.x = rigid.orientation.x();
  pose.orientation.y = rigid.orientation.y();
  pose.orientation.z = rigid.orientation.z();
  pose.orientation.w = rigid.orientation.w();
  return pose;
}

bool RosConverter::fromPose(const geometry_msgs::Pose& pose, Vec3& position, std::string& why)
{
  const Vec3 p = toVec3(pose.position);
  const Eigen::Vector4d q(pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w);
  if (!p.allFinite())
  {
    why = "position is not finite";
    return false;
  }
  if (!q.allFinite())
  {
    why = "orientation is not finite";
    return false;
  }
  position = p;
  return true;
}

bool RosConverter::fromPose(const geometry_msgs::Pose& pose, Vec3& position,
                            std::optional<Eigen::Quaterniond>& orientation, std::string& why)
{
  if (!fromPose(pose, position, why))
    return false;
  const Eigen::Quaterniond q(pose.orientation.w, pose.orientation.x, pose.orientation.y, pose.orientation.z);
  orientation.reset();
  if (q.norm() > 1e-12)
    orientation = q.normalized();
  return true;
}

namespace
{
/// A rigid pose at `position` turned by (w, x, y, z) made unit; nullopt if any is not finite or the
/// rotation is zero.
std::optional<RigidPose> rigidPose(const Vec3& position, double w, double x, double y, double z)
{
  RigidPose pose{ position, Eigen::Quaterniond(w, x, y, z) };
  if (!pose.position.allFinite() || !pose.orientation.coeffs().allFinite() || !(pose.orientation.norm() > 1e-12))
    return std::nullopt;
  pose.orientation.normalize();
  return pose;
}
}  // namespace

std::optional<RigidPose> RosConverter::toRigidPose(const geometry_msgs::Transform& transform)
{
  const geometry_msgs::Quaternion& q = transform.rotation;
  return rigidPose(toVec3(transform.translation), q.w, q.x, q.y, q.z);
}

std::optional<RigidPose> RosConverter::toRigidPose(const geometry_msgs::Pose& pose)
{
  const geometry_msgs::Quaternion& q = pose.orientation;
  return rigidPose(toVec3(pose.position), q.w, q.x, q.y, q.z);
}

}  // namespace soft_body_sim
