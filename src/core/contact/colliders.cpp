#include "soft_body_sim/core/contact/colliders.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "soft_body_sim/core/definition_error.h"
#include "soft_body_sim/core/contact/mesh_field.h"
#include "soft_body_sim/core/format_number.h"

namespace soft_body_sim
{
namespace
{
void checkPlacement(const ColliderPlacement& at)
{
  const std::string what = "collider '" + at.name + "'";
  requireDefinition(at.position.allFinite(), what, { "position" }, "position must be finite");
  requireDefinition(at.velocity.allFinite(), what, { "velocity" }, "velocity must be finite");
  requireDefinition(at.angular_velocity.allFinite(), what, { "angular_velocity" }, "angular_velocity must be finite");
  requireDefinition(at.orientation.coeffs().allFinite() && at.orientation.norm() > 1e-12, what, { "orientation" },
                    "orientation must be a finite quaternion, not the zero quaternion");
  requireDefinition(at.friction >= 0.0 && std::isfinite(at.friction), what, { "friction" }, "friction must be >= 0");
  requireDefinition(at.restitution >= 0.0 && at.restitution <= 1.0, what, { "restitution" },
                    "restitution must be in [0, 1]");
}

void checkRadius(const ColliderPlacement& at, double radius)
{
  requireDefinition(radius > 0.0 && std::isfinite(radius), "collider '" + at.name + "'", { "radius" },
                    "radius must be > 0");
}

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

void checkCollider(const Sphere& sphere)
{
  checkPlacement(sphere.at);
  checkRadius(sphere.at, sphere.radius);
}

void checkCollider(const Capsule& capsule)
{
  checkPlacement(capsule.at);
  checkRadius(capsule.at, capsule.radius);
  requireDefinition(capsule.length >= 0.0 && std::isfinite(capsule.length), "collider '" + capsule.at.name + "'",
                    { "length" }, "length must be >= 0");
}

void checkCollider(const Box& box)
{
  checkPlacement(box.at);
  requireDefinition(box.size.allFinite() && box.size.minCoeff() > 0.0, "collider '" + box.at.name + "'", { "size" },
                    "every extent of size must be > 0");
}

void checkCollider(const Cylinder& cylinder)
{
  checkPlacement(cylinder.at);
  checkRadius(cylinder.at, cylinder.radius);
  requireDefinition(cylinder.length > 0.0 && std::isfinite(cylinder.length), "collider '" + cylinder.at.name + "'",
                    { "length" }, "length must be > 0");
}

void checkCollider(const Mesh& mesh)
{
  checkPlacement(mesh.at);
  const std::string what = "collider '" + mesh.at.name + "'";
  requireDefinition(mesh.scale.allFinite() && mesh.scale.minCoeff() > 0.0, what, { "scale" },
                    "every factor of scale must be > 0");
  requireDefinition(mesh.triangles && !mesh.triangles->triangles.empty(), what, { "mesh" },
                    "no triangles were read from '" + mesh.uri + "'");
  requireDefinition(mesh.voxel_size >= 0.0 && std::isfinite(mesh.voxel_size), what, { "voxel_size" },
                    "voxel_size must be > 0 (or 0: the default, the largest extent / 100)");
  const double voxel = fieldVoxelSize(mesh);
  const double voxels = fieldVoxels(*mesh.triangles, voxel, 0.0);
  requireDefinition(voxels <= kMaxFieldVoxels, what, { "voxel_size" },
                    "voxel_size " + formatNumber(voxel) + " m spans the mesh's bounding box with " +
                        formatNumber(voxels) + " voxels, more than the " +
                        std::to_string(static_cast<long long>(kMaxFieldVoxels)) + " allowed; make it larger");
}

double boundingRadius(const Mesh& mesh) { return mesh.triangles ? mesh.triangles->boundingRadius() : 0.0; }

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

SurfaceDistance surfaceDistance(const Cylinder& cylinder, const Eigen::Vector3d& local)
{
  const double half = 0.5 * cylinder.length;
  const double r = std::hypot(local.x(), local.y());
  const Eigen::Vector3d radial = r > 0.0 ? Eigen::Vector3d(local.x() / r, local.y() / r, 0.0) : Eigen::Vector3d::UnitX();
  const double side = r - cylinder.radius;            // > 0 outside the mantle's radius
  const double cap = std::abs(local.z()) - half;      // > 0 beyond a cap's plane
  const Eigen::Vector3d axial(0.0, 0.0, local.z() < 0.0 ? -1.0 : 1.0);
  SurfaceDistance s;
  if (side > 0.0 && cap > 0.0)
  {
    // Nearest the rim where the mantle meets a cap.
    s.closest = cylinder.radius * radial + half * axial;
    s.distance = (local - s.closest).norm();
    s.normal = (local - s.closest) / s.distance;
  }
  else if (side > cap)
  {
    // Out through the mantle (outside beside it, or inside nearer to it than to a cap).
    s.distance = side;
    s.normal = radial;
    s.closest = Eigen::Vector3d(cylinder.radius * radial.x(), cylinder.radius * radial.y(), local.z());
  }
  else
  {
    s.distance = cap;
    s.normal = axial;
    s.closest = Eigen::Vector3d(local.x(), local.y(), half * axial.z());
  }
  return s;
}

SurfaceDistance surfaceDistance(const Mesh& mesh, const Eigen::Vector3d& local)
{
  return mesh.field->distance(local);
}

}  // namespace soft_body_sim
