#include "soft_body_sim/core/contact.h"

#include <cmath>

#include "shape_contacts.h"
#include "soft_body_sim/core/collisions.h"

namespace soft_body_sim
{
void preparePlacement(ColliderPlacement& at)
{
  const auto check = [&at](bool ok, const std::string& reason) {
    if (!ok)
      throw std::invalid_argument("collider '" + at.name + "': " + reason);
  };
  check(at.position.allFinite() && at.velocity.allFinite() && at.angular_velocity.allFinite(),
        "position, velocity and angular_velocity must be finite");
  check(at.orientation.coeffs().allFinite() && at.orientation.norm() > 1e-12,
        "orientation must be a finite, non-zero quaternion");
  check(at.friction >= 0.0 && std::isfinite(at.friction), "friction must be >= 0");
  check(at.restitution >= 0.0 && at.restitution <= 1.0, "restitution must be in [0, 1]");
  at.orientation.normalize();
}

namespace
{
template <typename Shape>
void addShapes(std::vector<std::unique_ptr<ColliderKind>>& kinds, const std::vector<Shape>& shapes, int nodes)
{
  if (!shapes.empty())
    kinds.push_back(std::make_unique<ShapeContacts<Shape>>(shapes, nodes));
}
}  // namespace

std::vector<std::unique_ptr<ColliderKind>> makeColliderKinds(const Model& model)
{
  std::vector<std::unique_ptr<ColliderKind>> kinds;
  if (!model.colliders.planes.empty())
    kinds.push_back(std::make_unique<PlaneContacts>(model.colliders.planes, model.nodeCount()));
  addShapes(kinds, model.colliders.spheres, model.nodeCount());
  addShapes(kinds, model.colliders.capsules, model.nodeCount());
  addShapes(kinds, model.colliders.boxes, model.nodeCount());
  addShapes(kinds, model.colliders.cylinders, model.nodeCount());
  return kinds;
}

}  // namespace soft_body_sim
