#include "integrator_kit.h"
#include "soft_body_sim/core/forces.h"

namespace soft_body_sim
{
namespace
{
/// One XPBD update of a pressure cell (jelly) as a compliant area constraint whose energy is the
/// cell's gas, E = p0 A0 e(a) with a = A / A0 (see CellGas). XPBD's implicit position update
/// M (x - x~) = h^2 F = -h^2 p0 e'(a) dA/dx^T becomes, with lambda = -h^2 p0 e'(a),
///   x - x~ = M^-1 dA/dx^T lambda,   e'(a) + alpha~ lambda = 0,   alpha~ = 1 / (h^2 p0),
/// and one Newton step on the second equation along the first (dA/dx held fixed, as in XPBD) gives
///   dlambda = -(e'(a) + alpha~ lambda) / (e''(a) W / A0 + alpha~),   W = sum_k w_k |dA/dx_k|^2,
///   x_k += w_k dA/dx_k dlambda.
/// For the quadratic e = (a - 1)^2 / 2 this is the usual XPBD area constraint C = A - A0 with
/// compliance A0 / p0; the gas's e'' = 1/a^2 makes the step stiffen as the cell is squeezed.
/// e'(a) = -p / p0 and e''(a) = S A0 / p0 in terms of CellGas's pressure p and stiffness S.
void solveCell(const PressureCell& cell, const Eigen::VectorXd& inverse_mass, double h, NodeArray& x,
               double& lambda)
{
  if (!(cell.pressure > 0.0))
    return;
  Vec3 g[4];
  const CellGas gas = cellGas(cell, cellArea(cell, x, g));
  double w = 0.0;
  for (int k = 0; k < 4; ++k)
    w += inverse_mass[cell.nodes[k]] * g[k].squaredNorm();
  const double alpha_tilde = 1.0 / (h * h * cell.pressure);
  const double denominator = gas.stiffness * w / cell.pressure + alpha_tilde;
  if (w < 1e-300 || denominator < 1e-300)
    return;
  const double delta_lambda = (gas.pressure / cell.pressure - alpha_tilde * lambda) / denominator;
  lambda += delta_lambda;
  for (int k = 0; k < 4; ++k)
    x.col(cell.nodes[k]) += (inverse_mass[cell.nodes[k]] * delta_lambda) * g[k];
}

/// Extended position-based dynamics (Macklin, Mueller, Chentanez 2016), one call per sub-step as in
/// "Small steps in physics simulation" (Macklin et al. 2019) and Ten Minute Physics:
///   preSolve:  v = v / (1 + h drag) + h g,  x_prev = x,  x += h v
///              (drag implicit on the carried velocity only, so it stays stable for any h drag and
///              cannot scale gravity down at rest, where the constraints cancel h g every sub-step)
///   solve:     `iterations` Gauss-Seidel sweeps over springs (compliance 1/k, damping c),
///              distance constraints (their own compliance) and pressure cells (see solveCell),
///              lambda accumulated per sub-step
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
    cell_lambda_.setZero(static_cast<Eigen::Index>(model.cells.size()));
    for (int iteration = 0; iteration < iterations; ++iteration)
    {
      for (std::size_t k = 0; k < rows_.size(); ++k)
        solveDistance(rows_[k], model.inverse_mass, previous_, x, lambda_[static_cast<Eigen::Index>(k)]);
      for (std::size_t k = 0; k < model.cells.size(); ++k)
        solveCell(model.cells[k], model.inverse_mass, h, x, cell_lambda_[static_cast<Eigen::Index>(k)]);
    }
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
  Eigen::VectorXd cell_lambda_;
};
}  // namespace

std::unique_ptr<Integrator> makeXpbd() { return std::make_unique<Xpbd>(); }

}  // namespace soft_body_sim
