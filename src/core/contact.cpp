#include "soft_body_sim/core/contact.h"

#include "soft_body_sim/core/collisions.h"

namespace soft_body_sim
{
std::vector<std::unique_ptr<ColliderKind>> makeColliderKinds(const Model& model)
{
  std::vector<std::unique_ptr<ColliderKind>> kinds;
  if (!model.colliders.planes.empty())
    kinds.push_back(std::make_unique<PlaneContacts>(model.colliders.planes, model.nodeCount()));
  return kinds;
}

}  // namespace soft_body_sim
