#include "soft_body_sim/core/contact/contact_stage.h"

#include "core/contact/shape_contacts.h"
#include "core/contact/planes.h"
#include "soft_body_sim/core/contact/mesh_field.h"

namespace soft_body_sim
{
namespace
{
template <typename Shape>
void addShapes(std::vector<std::unique_ptr<ColliderKind>>& kinds, const std::vector<Shape>& shapes, const Model& model)
{
  if (!shapes.empty())
    kinds.push_back(
        std::make_unique<ShapeContacts<Shape>>(shapes, model.nodeCount(), !model.contact_triangles.empty()));
}
}  // namespace

std::vector<std::unique_ptr<ColliderKind>> makeColliderKinds(const Model& model)
{
  std::vector<std::unique_ptr<ColliderKind>> kinds;
  if (!model.colliders.planes.empty())
    kinds.push_back(std::make_unique<PlaneContacts>(model.colliders.planes, model.nodeCount()));
  addShapes(kinds, model.colliders.spheres, model);
  addShapes(kinds, model.colliders.capsules, model);
  addShapes(kinds, model.colliders.boxes, model);
  addShapes(kinds, model.colliders.cylinders, model);
  if (!model.colliders.meshes.empty())
  {
    // Their distance fields reach as far out as the thickest node needs.
    std::vector<Mesh> meshes = model.colliders.meshes;
    buildMeshFields(meshes, model.nodeCount() > 0 ? model.contact_radius.maxCoeff() : 0.0);
    addShapes(kinds, meshes, model);
  }
  return kinds;
}

}  // namespace soft_body_sim
