#include "soft_body_sim/core/constraints.h"

#include "soft_body_sim/core/forces.h"

namespace soft_body_sim
{
void solveDistance(const ConstraintRow& row, const Eigen::VectorXd& inverse_mass, const NodeArray& x_prev,
                   NodeArray& x, double& lambda)
{
  const double w_a = inverse_mass[row.a];
  const double w_b = inverse_mass[row.b];
  const double denominator = (1.0 + row.gamma) * (w_a + w_b) + row.alpha_tilde;
  Vec3 u;
  double length;
  if (w_a + w_b == 0.0 || denominator < 1e-300 || !springAxis(x, row.a, row.b, u, length))
    return;
  const double c = length - row.rest_length;
  // gradC . (x - x_prev): the constraint's rate over this (sub)step times h, for the damping term.
  const double c_rate_h = u.dot((x.col(row.a) - x_prev.col(row.a)) - (x.col(row.b) - x_prev.col(row.b)));
  const double delta_lambda = (-c - row.alpha_tilde * lambda - row.gamma * c_rate_h) / denominator;
  lambda += delta_lambda;
  x.col(row.a) += (w_a * delta_lambda) * u;
  x.col(row.b) -= (w_b * delta_lambda) * u;
}

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
      solveDistance(row, model.inverse_mass, x_prev, x, lambda[static_cast<Eigen::Index>(k)]);
    }
  }
}

}  // namespace soft_body_sim
