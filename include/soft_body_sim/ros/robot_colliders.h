// A robot's <collision> elements as colliders (the scene's `robot_colliders:`), through ROS's urdf
// package: every box, sphere, cylinder and mesh becomes a collider on its link's tf frame, in the pose of
// the collision's origin. ROS-side (liburdf), unit-tested without a master.
#pragma once

#include <string>
#include <vector>

#include "soft_body_sim/core/scene_def.h"

namespace soft_body_sim
{
/// Appends to `colliders` one collider per <collision> of `urdf_xml` (box, sphere, cylinder, mesh with
/// its scale: its file resolved by resolveMeshUri and its triangles read, the field left to
/// buildMeshFields), named after its link ("<link>", or "<link>/<k>" for the k-th of several), following
/// the link's frame, with `robot`'s friction and restitution. A mesh that cannot be read (or has a
/// non-positive scale) is left out and named in `skipped` with the file and the reason. Throws
/// std::invalid_argument, saying why, if the XML is no URDF, if it has no collision that becomes a
/// collider, or if a name is already a collider's.
void addRobotColliders(const std::string& urdf_xml, const RobotCollidersDef& robot, Colliders& colliders,
                       std::vector<std::string>& skipped);

}  // namespace soft_body_sim
