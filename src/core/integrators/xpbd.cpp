#include "integrator_kit.h"

namespace soft_body_sim
{
namespace
{
/// Extended position-based dynamics (Macklin, Mueller, Chentanez 2016), one call per sub-step as in
/// "Small steps in physics simulation" (Macklin et al. 2019) and Ten Minute Physics:
///   preSolve:  v = v / (1 + h drag) + h g,  x_prev = x,  x += h v
///              (drag implicit on the carried velocity only, so it stays stable for any h drag and
///              cannot scale gravity down at rest, where the constraints cancel h g every sub-step)
///   solve:     `iterations` Gauss-Seidel sweeps over springs (compliance 1/k, damping c) and
///              distance constraints (their own compliance), lambda accumulated per sub-step
///   postSolve: v = (x - x_prev) / h
class Xpbd final : public Integrator
{
public:
  void step(const Model& model, State& state, double h, int iterations) override
  {
    preSolve(model, state, h);
    solve(model, state.position, h, iterations);
    postSolve(model, state, h);
  }

private:
  void preSolve(const Model& model, State& state, double h)
  {
    previous_ = state.position;
    const double drag_factor = 1.0 / (1.0 + h * model.drag);
    for (int i = 0; i < model.nodeCount(); ++i)
    {
      if (!model.isFree(i))
        continue;
      state.velocity.col(i) = state.velocity.col(i) * drag_factor + h * model.gravity;
      state.position.col(i) += h * state.velocity.col(i);
    }
  }

  void solve(const Model& model, NodeArray& x, double h, int iterations)
  {
    const double inverse_h2 = 1.0 / (h * h);
    rows_.clear();
    for (const Spring& s : model.springs)
    {
      const double alpha_tilde = inverse_h2 / s.stiffness;
      rows_.push_back({ s.a, s.b, s.rest_length, alpha_tilde, alpha_tilde * s.damping * h });
    }
    for (const DistanceConstraint& c : model.constraints)
      rows_.push_back({ c.a, c.b, c.rest_length, c.compliance * inverse_h2, 0.0 });
    lambda_.setZero(static_cast<Eigen::Index>(rows_.size()));
    for (int iteration = 0; iteration < iterations; ++iteration)
      for (std::size_t k = 0; k < rows_.size(); ++k)
        solveDistance(rows_[k], model.inverse_mass, previous_, x, lambda_[static_cast<Eigen::Index>(k)]);
  }

  void postSolve(const Model& model, State& state, double h)
  {
    for (int i = 0; i < model.nodeCount(); ++i)
      if (model.isFree(i))
        state.velocity.col(i) = (state.position.col(i) - previous_.col(i)) / h;
  }

  NodeArray previous_;
  std::vector<ConstraintRow> rows_;
  Eigen::VectorXd lambda_;
};
}  // namespace

std::unique_ptr<Integrator> makeXpbd() { return std::make_unique<Xpbd>(); }

}  // namespace soft_body_sim
