#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCore>

#include "integrator_kit.h"
#include "soft_body_sim/core/forces.h"

namespace soft_body_sim
{
namespace
{
using Matrix3 = Eigen::Matrix3d;

/// Backward Euler, v_{n+1} = v_n + h M^-1 f(x_n + h v_{n+1}, v_{n+1}), x_{n+1} = x_n + h v_{n+1},
/// solved by Newton's method as in Baraff & Witkin 1998 ("Large steps in cloth simulation"):
/// each iteration linearises f about (x_lin, v_k) and solves
///   (M - h D - h^2 K) dv = h f(x_lin, v_k) + h K (x_n + h v_k - x_lin) - M (v_k - v_n)
/// with K = df/dx, D = df/dv, by sparse conjugate gradients. The first iteration linearises at
/// x_lin = x_n (exactly Baraff & Witkin's step); later ones at x_lin = x_n + h v_k.
/// K's transverse term k (1 - L/l)(I - u u^T) is dropped when the spring is compressed (Choi & Ko
/// 2002) so that the matrix stays symmetric positive definite; the damping force's dependence on x is
/// neglected, as in Baraff & Witkin. Unconditionally stable on a linear spring; first order.
/// Pressure cells (jelly) enter f with F_k = p dA/dx_k and K with its Gauss-Newton part
///   K_kl = -(d^2E/dA^2) dA/dx_k dA/dx_l^T,
/// dropping p d^2A/dx_k dx_l, which is indefinite (A is bilinear in the positions) and vanishes at
/// rest; the kept part is the one that stiffens without bound as the cell is squeezed.
class ImplicitEuler final : public Integrator
{
public:
  /// CG stops at a relative residual of 1e-12: far below the scheme's O(h) error, and without it
  /// Eigen iterates to machine precision (up to 2n sweeps).
  ImplicitEuler() { solver_.setTolerance(1e-12); }

  void step(const Model& model, State& state, double h, int iterations) override
  {
    const int n = model.nodeCount();
    start_x_ = state.position;
    start_v_ = state.velocity;
    for (int k = 0; k < iterations; ++k)
    {
      const NodeArray& v_k = state.velocity;
      // x_lin and the offset x_n + h v_k - x_lin at which K acts (nonzero only on the first iteration).
      linear_x_ = start_x_;
      offset_.setZero(3, n);
      for (int i = 0; i < n; ++i)
      {
        if (!model.isFree(i))
          continue;
        if (k == 0)
          offset_.col(i) = h * v_k.col(i);
        else
          linear_x_.col(i) += h * v_k.col(i);
      }
      assemble(model, linear_x_, v_k, h);
      solver_.compute(matrix_);
      delta_v_ = solver_.solve(rhs_);
      for (int i = 0; i < n; ++i)
        if (model.isFree(i))
          state.velocity.col(i) += delta_v_.segment<3>(3 * i);
    }
    for (int i = 0; i < n; ++i)
      if (model.isFree(i))
        state.position.col(i) = start_x_.col(i) + h * state.velocity.col(i);
    constraints_.apply(model, state, h, iterations);
  }

private:
  /// Fills matrix_ = M - h D - h^2 K and rhs_ (see the class comment) at (x, v).
  void assemble(const Model& model, const NodeArray& x, const NodeArray& v, double h)
  {
    const int n = model.nodeCount();
    force_.setZero(3, n);
    accumulateSpringForces(model, x, v, force_);
    if (!model.cells.empty())
      accumulatePressureForces(model, x, force_);
    triplets_.clear();
    rhs_.resize(3 * n);
    for (int i = 0; i < n; ++i)
    {
      if (!model.isFree(i))
      {
        // Pinned: dv = 0, an identity row.
        rhs_.segment<3>(3 * i).setZero();
        addBlock(i, i, Matrix3::Identity());
        continue;
      }
      const double m = model.mass[i];
      const Vec3 f = force_.col(i) + m * model.gravity - m * model.drag * v.col(i);
      rhs_.segment<3>(3 * i) = h * f - m * (v.col(i) - start_v_.col(i));
      addBlock(i, i, (m * (1.0 + h * model.drag)) * Matrix3::Identity());
    }
    for (const Spring& s : model.springs)
    {
      Vec3 u;
      double length;
      if (!springAxis(x, s.a, s.b, u, length))
        continue;
      const Matrix3 uu = u * u.transpose();
      const double transverse = std::max(0.0, 1.0 - s.rest_length / length);
      // -df_a/dx_a of the spring (clamped, see above) and -df_a/dv_a of its dashpot.
      const Matrix3 stiffness = s.stiffness * (uu + transverse * (Matrix3::Identity() - uu));
      const Matrix3 block = h * h * stiffness + h * s.damping * uu;
      const Vec3 k_offset = -stiffness * (offset_.col(s.a) - offset_.col(s.b));
      const bool a_free = model.isFree(s.a);
      const bool b_free = model.isFree(s.b);
      if (a_free)
      {
        rhs_.segment<3>(3 * s.a) += h * k_offset;
        addBlock(s.a, s.a, block);
      }
      if (b_free)
      {
        rhs_.segment<3>(3 * s.b) -= h * k_offset;
        addBlock(s.b, s.b, block);
      }
      if (a_free && b_free)
      {
        addBlock(s.a, s.b, -block);
        addBlock(s.b, s.a, -block);
      }
    }
    for (const PressureCell& cell : model.cells)
      addCell(model, cell, x, h);
    matrix_.resize(3 * n, 3 * n);
    matrix_.setFromTriplets(triplets_.begin(), triplets_.end());
  }

  /// The cell's share of matrix_ (h^2 S g_k g_l^T, S = d^2E/dA^2, g_k = dA/dx_k) and of rhs_
  /// (h K offset, with (K offset)_k = -S g_k sum_l g_l . offset_l) on its free corners.
  void addCell(const Model& model, const PressureCell& cell, const NodeArray& x, double h)
  {
    Vec3 g[4];
    const double stiffness = cellGas(cell, cellArea(cell, x, g)).stiffness;
    double g_dot_offset = 0.0;
    for (int k = 0; k < 4; ++k)
      g_dot_offset += g[k].dot(offset_.col(cell.nodes[k]));
    for (int k = 0; k < 4; ++k)
    {
      const int row = cell.nodes[k];
      if (!model.isFree(row))
        continue;
      rhs_.segment<3>(3 * row) -= (h * stiffness * g_dot_offset) * g[k];
      for (int l = 0; l < 4; ++l)
        if (model.isFree(cell.nodes[l]))
          addBlock(row, cell.nodes[l], (h * h * stiffness) * g[k] * g[l].transpose());
    }
  }

  void addBlock(int row, int col, const Matrix3& block)
  {
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        triplets_.emplace_back(3 * row + r, 3 * col + c, block(r, c));
  }

  NodeArray start_x_, start_v_, linear_x_, offset_, force_;
  std::vector<Eigen::Triplet<double>> triplets_;
  Eigen::SparseMatrix<double> matrix_;
  Eigen::VectorXd rhs_, delta_v_;
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper> solver_;
  ConstraintPass constraints_;
};
}  // namespace

std::unique_ptr<Integrator> makeImplicitEuler() { return std::make_unique<ImplicitEuler>(); }

}  // namespace soft_body_sim
