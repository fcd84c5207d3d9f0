// What the bodies collide with, as the scene declares it: plain data, held whole in Model::colliders and
// copied whole from SceneDef. Each kind of collider is resolved by its own ColliderKind (contact.h),
// which checks and prepares its shapes when the world is built.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace soft_body_sim
{
/// A wall or floor: the half-space (x - point) . normal >= 0 is free space, nodes are pushed out of the
/// other side. Contacts bounce with `restitution` and slide with Coulomb `friction`.
struct Plane
{
  Eigen::Vector3d point = Eigen::Vector3d::Zero();    ///< a point on the plane [m]
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< normal pointing into free space (need not be unit; not 0)
  double restitution = 0.0;                           ///< normal speed kept after a bounce, in [0, 1]
  double friction = 0.0;                              ///< Coulomb coefficient [-], >= 0
};

/// Every collider of a scene, by kind. A scene without any has no contact stage at all.
struct Colliders
{
  std::vector<Plane> planes;
};

}  // namespace soft_body_sim
