#include "soft_body_sim/core/reactions.h"

#include "soft_body_sim/core/forces.h"

namespace soft_body_sim
{
void internalPulls(const Model& model, const NodeArray& x, const InternalForces& forces, NodeArray& pull)
{
  const Eigen::VectorXd& tension = forces.tension;
  pull.setZero(3, model.nodeCount());
  const auto add = [&](int a, int b, double t) {
    Vec3 u;
    double length;
    if (!springAxis(x, a, b, u, length))
      return;
    pull.col(a) -= t * u;
    pull.col(b) += t * u;
  };
  for (std::size_t k = 0; k < model.springs.size(); ++k)
    add(model.springs[k].a, model.springs[k].b, tension[static_cast<Eigen::Index>(k)]);
  for (std::size_t k = 0; k < model.constraints.size(); ++k)
    add(model.constraints[k].a, model.constraints[k].b,
        tension[static_cast<Eigen::Index>(model.springs.size() + k)]);
  Vec3 gradient[4];
  for (std::size_t k = 0; k < model.cells.size(); ++k)
  {
    cellArea(model.cells[k], x, gradient);
    for (int corner = 0; corner < 4; ++corner)
      pull.col(model.cells[k].nodes[corner]) += forces.pressure[static_cast<Eigen::Index>(k)] * gradient[corner];
  }
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
