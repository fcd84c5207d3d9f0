#include "soft_body_sim/scene/mesh_uri.h"

#include <cstdlib>
#include <filesystem>
#include <stdexcept>

#include <ros/package.h>

namespace soft_body_sim
{
namespace
{
const std::string kPackageScheme = "package://", kFileScheme = "file://";

bool startsWith(const std::string& text, const std::string& prefix) { return text.rfind(prefix, 0) == 0; }
}  // namespace

std::string resolveMeshUri(const std::string& uri, const std::string& base_directory)
{
  if (startsWith(uri, kPackageScheme))
  {
    const std::string rest = uri.substr(kPackageScheme.size());
    const std::size_t slash = rest.find('/');
    const std::string package = rest.substr(0, slash);
    if (package.empty() || slash == std::string::npos || slash + 1 == rest.size())
      throw std::invalid_argument("'" + uri + "' is not package://PACKAGE/PATH");
    const std::string folder = ros::package::getPath(package);
    if (folder.empty())
    {
      const char* search = std::getenv("ROS_PACKAGE_PATH");
      throw std::invalid_argument("ROS package '" + package + "' of '" + uri + "' not found on ROS_PACKAGE_PATH (" +
                                  (search ? search : "unset") + ")");
    }
    return folder + rest.substr(slash);
  }
  if (startsWith(uri, kFileScheme))
    return uri.substr(kFileScheme.size());
  if (uri.find("://") != std::string::npos)
    throw std::invalid_argument("'" + uri + "': only package://, file:// and plain paths are meshes");
  if (uri.empty() || uri.front() == '/' || base_directory.empty())
    return uri;
  return base_directory + "/" + uri;
}

std::string drawableMeshUri(const std::string& uri, const std::string& path)
{
  if (startsWith(uri, kPackageScheme) || startsWith(uri, kFileScheme))
    return uri;
  return kFileScheme + std::filesystem::absolute(path).lexically_normal().string();
}

}  // namespace soft_body_sim
