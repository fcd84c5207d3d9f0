#include "core/elements/distance_constraints.h"

#include "core/integrators/integrator_kit.h"

namespace soft_body_sim
{
void projectConstraints(const Model& model, double h, int iterations, const NodeArray& x_prev, NodeArray& x,
                        Eigen::VectorXd& lambda)
{
  if (model.constraints.empty())
    return;
  lambda.setZero(static_cast<Eigen::Index>(model.constraints.size()));
  const double inverse_h2 = 1.0 / (h * h);
  for (int iteration = 0; iteration < iterations; ++iteration)
  {
    for (std::size_t k = 0; k < model.constraints.size(); ++k)
    {
      const DistanceConstraint& c = model.constraints[k];
      const ConstraintRow row{ c.a, c.b, c.rest_length, c.compliance * inverse_h2, 0.0 };
      projectDistance(sweepRow(row, model.inverse_mass), model.inverse_mass, x_prev, x,
                      lambda[static_cast<Eigen::Index>(k)]);
    }
  }
}

}  // namespace soft_body_sim
