// The contact stage of a step: after each sub-step's integration, every kind of collider the scene
// declares pushes the free nodes out of its shapes and changes their velocities (bounce, friction).
// Planes are the first kind (collisions.h). A new kind (sphere, capsule, box, mesh) is one class in its
// own file, its data in Model, one line in makeColliderKinds (contact.cpp) and its reader: nothing in
// World. A scene that declares no colliders has no kinds here and pays nothing.
#pragma once

#include <memory>
#include <vector>

#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
/// One kind of collider, over all of its shapes in the model.
class ColliderKind
{
public:
  virtual ~ColliderKind() = default;
  /// After a sub-step of h [s]: resolves the contacts of every free node with this kind's shapes. True if
  /// it touched any node (the integrators' caches of the state are then stale).
  virtual bool resolve(const Model& model, State& state, double h) = 0;
};

/// The kinds of collider that `model` declares, in the order they resolve.
std::vector<std::unique_ptr<ColliderKind>> makeColliderKinds(const Model& model);

class ContactStage
{
public:
  explicit ContactStage(const Model& model) : kinds_(makeColliderKinds(model)) {}

  /// Every kind in turn; true if any touched a node.
  bool resolve(const Model& model, State& state, double h)
  {
    bool touched = false;
    for (const std::unique_ptr<ColliderKind>& kind : kinds_)
      touched = kind->resolve(model, state, h) || touched;
    return touched;
  }

private:
  std::vector<std::unique_ptr<ColliderKind>> kinds_;
};

}  // namespace soft_body_sim
