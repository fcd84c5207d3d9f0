// Pieces shared by the integrator implementations (private to the core library).
#pragma once

#include <memory>

#include "soft_body_sim/core/constraints.h"
#include "soft_body_sim/core/integrator.h"

namespace soft_body_sim
{
/// The distance-constraint pass of the force-based schemes: after the force step, project the
/// constraints and add the projection's displacement / h to the velocities, so that the constraint
/// impulse is kept in the motion (position-based post-stabilisation). Costs nothing without constraints.
class ConstraintPass
{
public:
  void apply(const Model& model, State& state, double h, int iterations)
  {
    if (model.constraints.empty())
      return;
    unprojected_ = state.position;
    projectConstraints(model, h, iterations, unprojected_, state.position, lambda_);
    for (int i = 0; i < model.nodeCount(); ++i)
      if (model.isFree(i))
        state.velocity.col(i) += (state.position.col(i) - unprojected_.col(i)) / h;
  }

private:
  NodeArray unprojected_;
  Eigen::VectorXd lambda_;
};

std::unique_ptr<Integrator> makeExplicitEuler();
std::unique_ptr<Integrator> makeSemiImplicitEuler();
std::unique_ptr<Integrator> makeVerlet();
std::unique_ptr<Integrator> makeVelocityVerlet();
std::unique_ptr<Integrator> makeRk4();
std::unique_ptr<Integrator> makeImplicitEuler();
std::unique_ptr<Integrator> makeXpbd();

}  // namespace soft_body_sim
