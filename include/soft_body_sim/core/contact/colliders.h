// What the bodies collide with, as the scene declares it: plain data, held whole in Model::colliders and
// copied whole from SceneDef. Each kind of collider is resolved by its own ColliderKind (contact_stage.h),
// which checks and prepares its shapes when the world is built and keeps their live poses.
#pragma once

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "soft_body_sim/core/state_archive.h"

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
  std::string name{};  ///< names its wrench (World::colliderWrenches, about `point`); empty: none reported
  Eigen::Vector3d color = Eigen::Vector3d::Constant(0.8);  ///< rgb in [0, 1], as a camera sees it

  void carry(StateArchive& archive) { archive(point, normal, restitution, friction, name, color); }
};

/// Where a rigid collider is and how it moves, and its surface. Its pose moves at constant `velocity`
/// and `angular_velocity` (about its own origin) unless the caller sets it (a tf frame,
/// World::followColliderPath).
struct ColliderPlacement
{
  std::string name;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();                 ///< [m] of its origin
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();    ///< of its local axes (unit)
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();                 ///< [m/s]
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();         ///< [rad/s], in the scene frame
  double friction = 0.0;     ///< Coulomb coefficient [-], >= 0
  double restitution = 0.0;  ///< normal speed kept after a bounce, in [0, 1]
  std::string frame;         ///< a tf frame the ROS node makes it follow (pose relative to it); empty = none
  Eigen::Vector3d color = Eigen::Vector3d::Constant(0.6);  ///< rgb in [0, 1], as rviz and a camera see it

  void carry(StateArchive& archive)
  {
    archive(name, position, orientation, velocity, angular_velocity, friction, restitution, frame, color);
  }
};

/// A ball of `radius` [m] about its origin.
struct Sphere
{
  ColliderPlacement at;
  double radius = 0.1;  ///< [m], > 0

  void carry(StateArchive& archive) { archive(at, radius); }
};

/// A segment of `length` [m] along its local z axis, centred on its origin, thickened by `radius` [m]
/// (hemispheres at z = +-length / 2).
struct Capsule
{
  ColliderPlacement at;
  double radius = 0.05;  ///< [m], > 0
  double length = 0.5;   ///< [m] between the end centres, >= 0

  void carry(StateArchive& archive) { archive(at, radius, length); }
};

/// A solid cylinder of `radius` [m] and `length` [m] along its local z axis, centred on its origin (flat
/// caps at z = +-length / 2), as URDF's <cylinder>.
struct Cylinder
{
  ColliderPlacement at;
  double radius = 0.05;  ///< [m], > 0
  double length = 0.5;   ///< [m], > 0

  void carry(StateArchive& archive) { archive(at, radius, length); }
};

/// A box of full extents `size` [m] along its local x, y, z, centred on its origin.
struct Box
{
  ColliderPlacement at;
  Eigen::Vector3d size = Eigen::Vector3d::Constant(0.1);  ///< [m], each > 0

  void carry(StateArchive& archive) { archive(at, size); }
};

struct TriangleMesh;
class MeshField;

/// A rigid triangle mesh read from a file (mesh_field.h), in its local frame: the file's coordinates
/// times `scale`. It must be closed (watertight) for inside and outside to mean something. Contact
/// queries its signed distance field, built when the world is built.
struct Mesh
{
  ColliderPlacement at;
  std::string uri;  ///< the file as rviz loads it: the scene's package:// or file://, a plain path as file:// and absolute
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();  ///< per local axis [-], each > 0
  double voxel_size = 0.0;  ///< [m] edge of the distance field's voxels, > 0; 0 = defaultVoxelSize
  std::shared_ptr<const TriangleMesh> triangles;  ///< readTriangleMesh of the file, scale applied
  std::shared_ptr<const MeshField> field;  ///< built from `triangles` by buildMeshFields (makeColliderKinds)

  /// The file, placement and scale; the triangles and field are made from them.
  void carry(StateArchive& archive) { archive(at, uri, scale, voxel_size); }
};

/// Every collider of a scene, by kind. A scene without any has no contact stage at all.
struct Colliders
{
  std::vector<Plane> planes;
  std::vector<Sphere> spheres;
  std::vector<Capsule> capsules;
  std::vector<Box> boxes;
  std::vector<Cylinder> cylinders;
  std::vector<Mesh> meshes;

  void carry(StateArchive& archive) { archive(planes, spheres, capsules, boxes, cylinders, meshes); }
};

/// Every shape's placement, in the order of Colliders' vectors (spheres, capsules, boxes, cylinders,
/// meshes): for the callers that treat all shapes alike (which follow a tf frame).
inline std::vector<const ColliderPlacement*> placements(const Colliders& colliders)
{
  std::vector<const ColliderPlacement*> all;
  for (const Sphere& s : colliders.spheres)
    all.push_back(&s.at);
  for (const Capsule& c : colliders.capsules)
    all.push_back(&c.at);
  for (const Box& b : colliders.boxes)
    all.push_back(&b.at);
  for (const Cylinder& c : colliders.cylinders)
    all.push_back(&c.at);
  for (const Mesh& m : colliders.meshes)
    all.push_back(&m.at);
  return all;
}

/// Checks a collider as a scene declares it: a finite pose and motion, a non-zero orientation (any
/// length: it is normalised where it is used), friction >= 0, restitution in [0, 1] and positive
/// extents (a capsule's length may be 0); a mesh: its triangles read, a positive scale, a voxel_size >= 0
/// that spans its bounding box with at most kMaxFieldVoxels (mesh_field.h). Throws DefinitionError naming
/// the keys at fault.
void checkCollider(const Sphere& sphere);
void checkCollider(const Capsule& capsule);
void checkCollider(const Box& box);
void checkCollider(const Cylinder& cylinder);
void checkCollider(const Mesh& mesh);

/// The nearest point of a shape's surface to a point, in the shape's local frame.
struct SurfaceDistance
{
  double distance = 0.0;                            ///< [m] signed: > 0 outside, < 0 inside
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< unit outward normal there
  Eigen::Vector3d closest = Eigen::Vector3d::Zero();  ///< the surface point [m]; point = closest + distance normal
};

/// `local` is a point in the shape's local frame [m]. Where the normal is not unique (the centre of a
/// sphere, the axis of a capsule, equidistant box faces) one of the candidates is returned.
SurfaceDistance surfaceDistance(const Sphere& sphere, const Eigen::Vector3d& local);
SurfaceDistance surfaceDistance(const Capsule& capsule, const Eigen::Vector3d& local);
SurfaceDistance surfaceDistance(const Box& box, const Eigen::Vector3d& local);
SurfaceDistance surfaceDistance(const Cylinder& cylinder, const Eigen::Vector3d& local);
/// A mesh's from its distance field (MeshField::distance, which states its accuracy); needs `field`.
SurfaceDistance surfaceDistance(const Mesh& mesh, const Eigen::Vector3d& local);

/// The radius [m] of a ball about the shape's origin that holds it.
inline double boundingRadius(const Sphere& sphere) { return sphere.radius; }
inline double boundingRadius(const Capsule& capsule) { return 0.5 * capsule.length + capsule.radius; }
inline double boundingRadius(const Box& box) { return 0.5 * box.size.norm(); }
inline double boundingRadius(const Cylinder& c) { return std::hypot(c.radius, 0.5 * c.length); }
double boundingRadius(const Mesh& mesh);

}  // namespace soft_body_sim
