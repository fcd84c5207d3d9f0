#include "soft_body_sim/core/colliders.h"

#include <algorithm>
#include <cmath>

namespace soft_body_sim
{
namespace
{
/// Outward distance from a ball of `radius` about the origin, with the +z normal at the centre.
SurfaceDistance ball(const Eigen::Vector3d& p, double radius)
{
  SurfaceDistance s;
  const double r = p.norm();
  s.normal = r > 0.0 ? Eigen::Vector3d(p / r) : Eigen::Vector3d::UnitZ();
  s.distance = r - radius;
  s.closest = radius * s.normal;
  return s;
}
}  // namespace

SurfaceDistance surfaceDistance(const Sphere& sphere, const Eigen::Vector3d& local)
{
  return ball(local, sphere.radius);
}

SurfaceDistance surfaceDistance(const Capsule& capsule, const Eigen::Vector3d& local)
{
  const double half = 0.5 * capsule.length;
  const Eigen::Vector3d axis_point(0.0, 0.0, std::clamp(local.z(), -half, half));
  SurfaceDistance s = ball(local - axis_point, capsule.radius);
  if (local.z() > -half && local.z() < half && s.normal == Eigen::Vector3d::UnitZ() && !(s.distance > -capsule.radius))
    s.normal = Eigen::Vector3d::UnitX();  // on the axis: any radial direction; +z would point along it
  s.closest = axis_point + capsule.radius * s.normal;
  return s;
}

SurfaceDistance surfaceDistance(const Box& box, const Eigen::Vector3d& local)
{
  const Eigen::Vector3d half = 0.5 * box.size;
  const Eigen::Vector3d q = local.cwiseAbs() - half;  // > 0 along the axes where the point is outside
  SurfaceDistance s;
  if ((q.array() > 0.0).any())
  {
    const Eigen::Vector3d outside = q.cwiseMax(0.0);
    s.distance = outside.norm();
    s.closest = local.cwiseMax(-half).cwiseMin(half);
    s.normal = (local - s.closest) / s.distance;
    return s;
  }
  // Inside: out through the nearest face.
  int axis = 0;
  q.maxCoeff(&axis);
  s.distance = q[axis];
  s.normal = Eigen::Vector3d::Zero();
  s.normal[axis] = local[axis] < 0.0 ? -1.0 : 1.0;
  s.closest = local;
  s.closest[axis] = s.normal[axis] * half[axis];
  return s;
}

}  // namespace soft_body_sim
