// Where a mesh file named in a scene or a URDF is on disk: the node and the headless simulator share it.
#pragma once

#include <string>

namespace soft_body_sim
{
/// The file path of a mesh `uri`: `package://PACKAGE/PATH` in the ROS package's folder (roslib's
/// ros::package::getPath, no master needed; the package must be on ROS_PACKAGE_PATH), `file://PATH`,
/// or a plain path, relative ones against `base_directory` (a scene file's folder; empty: the working
/// directory). Throws std::invalid_argument saying why if a package is not found or the URI has
/// another scheme.
std::string resolveMeshUri(const std::string& uri, const std::string& base_directory);

/// The URI that rviz loads a mesh by (a MESH_RESOURCE marker): `uri` itself if it is package:// or
/// file://, else file:// and the absolute form of `path` (what resolveMeshUri made of it), since rviz
/// knows neither the scene file's folder nor the node's working directory.
std::string drawableMeshUri(const std::string& uri, const std::string& path);

}  // namespace soft_body_sim
