#include <cstdint>
#include <utility>
#include <vector>

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

  /// The world calls this after changing the model (stiffness, masses, an attached node) as well as
  /// the state: rebuild the rows at the next sweep.
  void invalidate() override { rows_h_ = 0.0; }

private:
  void preSolve(const Model& model, State& state, double h)
  {
    previous_.resize(3, model.nodeCount());  // no allocation after the first sub-step
    const double drag_factor = 1.0 / (1.0 + h * model.drag);
    for (int i = 0; i < model.nodeCount(); ++i)
    {
      previous_.col(i) = state.position.col(i);
      if (!model.isFree(i))
        continue;
      state.velocity.col(i) = state.velocity.col(i) * drag_factor + h * model.gravity;
      state.position.col(i) += h * state.velocity.col(i);
    }
  }

  void solve(const Model& model, NodeArray& x, double h, int iterations)
  {
    const std::size_t spring_count = model.springs.size();
    const std::size_t row_count = spring_count + model.constraints.size();
    if (order_.size() != row_count || coloured_nodes_ != model.nodeCount())
    {
      colourRows(model);
      rows_h_ = 0.0;
    }
    rows_.resize(row_count);  // sized once: no allocation after the first sub-step
    lambda_.setZero(static_cast<Eigen::Index>(row_count));
    cell_lambda_.setZero(static_cast<Eigen::Index>(model.cells.size()));
    for (int iteration = 0; iteration < iterations; ++iteration)
    {
      if (iteration == 0 && h != rows_h_)
      {
        // Rows are stale (new h, or invalidate(): the model may have been retuned): the first sweep
        // writes them as it goes.
        const double inverse_h2 = 1.0 / (h * h);
        for (std::size_t k = 0; k < row_count; ++k)
        {
          const std::size_t r = order_[k];
          ConstraintRow row;
          if (r < spring_count)
          {
            const Spring& s = model.springs[r];
            const double alpha_tilde = inverse_h2 / s.stiffness;
            row = ConstraintRow{ s.a, s.b, s.rest_length, alpha_tilde, alpha_tilde * s.damping * h };
          }
          else
          {
            const DistanceConstraint& c = model.constraints[r - spring_count];
            row = ConstraintRow{ c.a, c.b, c.rest_length, c.compliance * inverse_h2, 0.0 };
          }
          rows_[k] = sweepRow(row, model.inverse_mass);
          projectDistance(rows_[k], model.inverse_mass, previous_, x, lambda_[static_cast<Eigen::Index>(k)]);
        }
        rows_h_ = h;
      }
      else
      {
        for (std::size_t k = 0; k < row_count; ++k)
          projectDistance(rows_[k], model.inverse_mass, previous_, x, lambda_[static_cast<Eigen::Index>(k)]);
      }
      for (std::size_t k = 0; k < model.cells.size(); ++k)
        solveCell(model.cells[k], model.inverse_mass, h, x, cell_lambda_[static_cast<Eigen::Index>(k)]);
    }
  }

  /// The sweep order: springs and constraints (row r < springs.size() is spring r, the others the
  /// constraints in turn) grouped by a greedy edge colouring, so that no two rows of a colour share a
  /// node. In model order, consecutive rows of a rope or a cloth row share a node, so each update waits
  /// for its predecessor's square root and divisions (~90 cycles); within a colour the processor
  /// overlaps them. Gauss-Seidel in this order converges as fast as in model order (both are
  /// consistent orderings; for a chain, red-black and lexicographic have the same spectral radius).
  void colourRows(const Model& model)
  {
    const std::size_t spring_count = model.springs.size();
    const std::size_t row_count = spring_count + model.constraints.size();
    const auto ends = [&](std::size_t r) {
      return r < spring_count ? std::pair<int, int>(model.springs[r].a, model.springs[r].b)
                              : std::pair<int, int>(model.constraints[r - spring_count].a,
                                                    model.constraints[r - spring_count].b);
    };
    constexpr int kColours = 64;
    std::vector<std::uint64_t> used(static_cast<std::size_t>(model.nodeCount()), 0);
    std::vector<std::uint8_t> colour(row_count);
    std::size_t start[kColours + 1] = {};
    for (std::size_t r = 0; r < row_count; ++r)
    {
      const auto [a, b] = ends(r);
      const std::uint64_t taken = used[static_cast<std::size_t>(a)] | used[static_cast<std::size_t>(b)];
      // The first free colour; a node with 64 rows shares the last one (still correct, only slower).
      int c = 0;
      while (c < kColours - 1 && (taken >> c) & 1u)
        ++c;
      colour[r] = static_cast<std::uint8_t>(c);
      used[static_cast<std::size_t>(a)] |= std::uint64_t{ 1 } << c;
      used[static_cast<std::size_t>(b)] |= std::uint64_t{ 1 } << c;
      ++start[c + 1];
    }
    for (int c = 0; c < kColours; ++c)
      start[c + 1] += start[c];
    order_.resize(row_count);
    for (std::size_t r = 0; r < row_count; ++r)
      order_[start[colour[r]]++] = static_cast<std::uint32_t>(r);
    coloured_nodes_ = model.nodeCount();
  }

  void postSolve(const Model& model, State& state, double h)
  {
    // One division per sub-step, not three per node.
    const double inverse_h = 1.0 / h;
    for (int i = 0; i < model.nodeCount(); ++i)
      if (model.isFree(i))
        state.velocity.col(i) = (state.position.col(i) - previous_.col(i)) * inverse_h;
  }

  NodeArray previous_;
  std::vector<std::uint32_t> order_;  ///< sweep order of the rows (see colourRows)
  int coloured_nodes_ = -1;
  std::vector<SweepRow> rows_;        ///< the rows in sweep order, valid for h = rows_h_
  double rows_h_ = 0.0;               ///< [s]; 0 = rows not built
  Eigen::VectorXd lambda_;
  Eigen::VectorXd cell_lambda_;
};
}  // namespace

std::unique_ptr<Integrator> makeXpbd() { return std::make_unique<Xpbd>(); }

}  // namespace soft_body_sim
