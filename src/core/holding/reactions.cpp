#include "soft_body_sim/core/holding/reactions.h"

#include "core/elements/element_kinds.h"

namespace soft_body_sim
{
void internalPulls(const Model& model, const State& state, const InternalForces& forces, NodeArray& pull)
{
  pull.setZero(3, model.nodeCount());
  forEachKind([&](auto kind) { kind.addPulls(model, state, forces, pull); });
}

Wrench holdingWrench(const Model& model, const NodeArray& x, const NodeArray& pull, const std::vector<int>& nodes,
                     const Vec3& origin)
{
  Wrench wrench;
  for (const int node : nodes)
  {
    const Vec3 force = pull.col(node) + model.mass[node] * model.gravity;
    wrench.force += force;
    wrench.torque += (x.col(node) - origin).cross(force);
  }
  return wrench;
}

}  // namespace soft_body_sim
