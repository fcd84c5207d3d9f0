// A robot's <collision> elements as colliders (the scene's `robot_colliders:`), through ROS's urdf
// package: every box, sphere and cylinder becomes a collider on its link's tf frame, in the pose of the
// collision's origin. ROS-side (liburdf), unit-tested without a master.
#pragma once

#include <string>
#include <vector>

#include "soft_body_sim/core/scene_def.h"

namespace soft_body_sim
{
/// Appends to `colliders` one collider per <collision> of `urdf_xml` (box, sphere, cylinder), named
/// after its link ("<link>", or "<link>/<k>" for the k-th of several), following the link's frame, with
/// `robot`'s friction and restitution. Meshes are not supported yet: each is left out and named in
/// `skipped`. Throws std::invalid_argument, saying why, if the XML is no URDF, if it has no collision
/// that becomes a collider, or if a name is already a collider's.
void addRobotColliders(const std::string& urdf_xml, const RobotCollidersDef& robot, Colliders& colliders,
                       std::vector<std::string>& skipped);

}  // namespace soft_body_sim
