// What an element kind's blocks of implicit Euler's Newton system see, and what they give (private to the
// core library). Backward Euler solves, per Newton iteration (implicit_euler.cpp),
//   (M - h D - h^2 K) dv = h f(x_lin, v_k) + h K offset - M (v_k - v_n),   offset = x_n + h v_k - x_lin,
// K = df/dx, D = df/dv. Each element kind adds its share: its forces and K offset to the right-hand side,
// its blocks of A = M - h D - h^2 K (BlockSystem), kept symmetric positive semi-definite (each kind says
// how: clamped, Gauss-Newton, projected).
//
// A kind's ImplicitBlocks (element_kinds.h) has
//   analyze(model, system)         its node pairs into the pattern (system.addPair), once per model
//   assemble(point, system)        its share of rhs, its diagonal blocks, its condition estimate
//   multiply(model, p, out)        out += its blocks (all but the diagonal ones it put in system.diagonal()) p
//   addToPreconditioner(model, d)  d[i] += its diagonal blocks that it keeps apart from system.diagonal()
//   write(model, solver)           its blocks into a direct solver (addDiagonal, addOffDiagonal by slot)
// Contact holds (collider_holds.h, surface_holds.h) have the same shape.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "core/solvers/block_system.h"
#include "soft_body_sim/core/elements/tetrahedra.h"
#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
/// The point a Newton iteration linearises at.
struct NewtonPoint
{
  const Model& model;
  const NodeArray& x;             ///< x_lin [m]: x_n on the first iteration, x_n + h v_k on the others
  const NodeArray& v;             ///< v_k [m/s]
  const Eigen::VectorXd& twist;   ///< the rods' twists (State::twist)
  const NodeArray& offset;        ///< x_n + h v_k - x_lin [m], at which K acts (0 at pinned nodes)
  double h;                       ///< [s]
};

/// A kind the Newton system leaves out: it acts after the solve (distance constraints, projected by the
/// constraint pass, integrator_kit.h).
struct NoImplicitBlocks
{
  void analyze(const Model&, BlockSystem&) {}
  void assemble(const NewtonPoint&, BlockSystem&) {}
  void multiply(const Model&, const NodeArray&, NodeArray&) const {}
  void addToPreconditioner(const Model&, std::vector<Eigen::Matrix3d>&) const {}
  template <class Solver>
  void write(const Model&, Solver&) const
  {
  }
};

}  // namespace soft_body_sim
