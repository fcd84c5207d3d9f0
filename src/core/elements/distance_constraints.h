// Distance-constraint projection (XPBD), shared by xpbd and by the constraint pass of the other schemes.
#pragma once

#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
/// One row of an XPBD update of C = |x_a - x_b| - rest_length (Macklin, Mueller, Chentanez 2016, eqs. 18
/// and 26), solved by projectDistance (integrators/integrator_kit.h):
///   dlambda = (-C - alpha~ lambda - gamma gradC.(x - x_prev)) / ((1 + gamma)(w_a + w_b) + alpha~),
///   x_a += w_a dlambda u,  x_b -= w_b dlambda u,
/// with alpha~ = compliance / h^2 and gamma = alpha~ beta h (beta [N s/m] the constraint's damping).
/// `lambda` accumulates over the iterations of one (sub)step. Coincident or both-pinned pairs are skipped.
struct ConstraintRow
{
  int a;
  int b;
  double rest_length;
  double alpha_tilde;  ///< compliance / h^2 [1/kg]
  double gamma;        ///< alpha~ * damping * h [-]
};

/// Projects every DistanceConstraint of the model `iterations` times (Gauss-Seidel) for a (sub)step of h [s].
/// `lambda` is scratch of size constraints.size().
void projectConstraints(const Model& model, double h, int iterations, const NodeArray& x_prev, NodeArray& x,
                        Eigen::VectorXd& lambda);

}  // namespace soft_body_sim
