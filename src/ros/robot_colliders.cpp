#include "soft_body_sim/ros/robot_colliders.h"

#include <memory>
#include <set>
#include <stdexcept>

#include <urdf/model.h>

#include "soft_body_sim/core/definition_error.h"
#include "soft_body_sim/core/contact/mesh_field.h"
#include "soft_body_sim/scene/mesh_uri.h"
#include "soft_body_sim/core/format_number.h"

namespace soft_body_sim
{
void addRobotColliders(const std::string& urdf_xml, const RobotCollidersDef& robot, Colliders& colliders,
                       std::vector<std::string>& skipped)
{
  urdf::Model model;
  if (!model.initString(urdf_xml))
    throw std::invalid_argument("robot_colliders: the parameter '" + robot.param + "' holds no valid URDF");
  std::set<std::string> names;
  for (const ColliderPlacement* at : placements(colliders))
    names.insert(at->name);
  for (const Plane& plane : colliders.planes)
    if (!plane.name.empty())
      names.insert(plane.name);
  int added = 0;
  for (const auto& [link_name, link] : model.links_)
  {
    const std::vector<urdf::CollisionSharedPtr>& collisions = link->collision_array;
    for (std::size_t k = 0; k < collisions.size(); ++k)
    {
      const urdf::Collision& collision = *collisions[k];
      ColliderPlacement at;
      at.name = collisions.size() == 1 ? link_name : link_name + "/" + std::to_string(k);
      at.frame = link_name;
      at.position = Vec3(collision.origin.position.x, collision.origin.position.y, collision.origin.position.z);
      double x = 0.0, y = 0.0, z = 0.0, w = 1.0;
      collision.origin.rotation.getQuaternion(x, y, z, w);
      at.orientation = Eigen::Quaterniond(w, x, y, z).normalized();
      at.friction = robot.friction;
      at.restitution = robot.restitution;
      if (!names.insert(at.name).second)
        throw std::invalid_argument("robot_colliders: the collider name '" + at.name + "' of link '" + link_name +
                                    "' is already taken");
      const urdf::GeometrySharedPtr& geometry = collision.geometry;
      if (!geometry)
        continue;
      if (const auto box = std::dynamic_pointer_cast<urdf::Box>(geometry))
        colliders.boxes.push_back(Box{ at, Vec3(box->dim.x, box->dim.y, box->dim.z) });
      else if (const auto sphere = std::dynamic_pointer_cast<urdf::Sphere>(geometry))
        colliders.spheres.push_back(Sphere{ at, sphere->radius });
      else if (const auto cylinder = std::dynamic_pointer_cast<urdf::Cylinder>(geometry))
        colliders.cylinders.push_back(Cylinder{ at, cylinder->radius, cylinder->length });
      else if (const auto file = std::dynamic_pointer_cast<urdf::Mesh>(geometry))
      {
        Mesh mesh;
        mesh.at = at;
        mesh.uri = file->filename;
        mesh.scale = Vec3(file->scale.x, file->scale.y, file->scale.z);
        try
        {
          // A URDF's relative mesh paths have no folder to be relative to: the working directory's.
          if (!(mesh.scale.minCoeff() > 0.0))
            throw std::invalid_argument("scale " + formatNumber(mesh.scale.x()) + " " +
                                        formatNumber(mesh.scale.y()) + " " + formatNumber(mesh.scale.z()) +
                                        " is not > 0 in every axis");
          const std::string path = resolveMeshUri(mesh.uri, "");
          mesh.triangles = std::make_shared<const TriangleMesh>(readTriangleMesh(path, mesh.scale));
          mesh.uri = drawableMeshUri(mesh.uri, path);
        }
        catch (const std::invalid_argument& e)
        {
          skipped.push_back(at.name + " (mesh '" + mesh.uri + "': " + e.what() + ")");
          continue;
        }
        colliders.meshes.push_back(mesh);
      }
      else
      {
        skipped.push_back(at.name + " (an unknown geometry)");
        continue;
      }
      ++added;
    }
  }
  if (added == 0)
    throw std::invalid_argument("robot_colliders: the URDF '" + model.getName() + "' on '" + robot.param +
                                "' has no box, sphere, cylinder or readable mesh <collision>");
}

}  // namespace soft_body_sim
