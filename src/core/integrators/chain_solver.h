// A direct solve of XPBD's linearised system for rows that form chains (private to the core library).
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "integrator_kit.h"

namespace soft_body_sim
{
/// The rows of an XPBD solve split into chains, solved directly, and the rest, swept by Gauss-Seidel.
///
/// XPBD's linearised system (Macklin, Mueller, Chentanez 2016, eqs. 12 and 26) over all rows is
///   ((I + Gamma) J W J^T + alpha~) dlambda = -C - alpha~ lambda - Gamma J (x - x_prev),
/// where (J W J^T)_ij = sum over nodes k of w_k gradC_i(k) . gradC_j(k): two rows couple only through a
/// free node they share (w = 0 at a pinned one). When every free node joins at most two rows and the
/// rows so coupled form no cycle, each connected set of rows is a path, and in path order its matrix is
/// tridiagonal. If the path also ends in a free node (a chain hanging from at most one support, or
/// none), its rows are independent in any shape, and the system is solved exactly in O(n) by the
/// Thomas algorithm, with no fill-in (Deul, Kugelstadt, Weiler, Bender 2018, "Direct Position-Based
/// Solver for Stiff Rods": tree-structured systems; a path is the simplest tree). Gauss-Seidel, which moves the end of a chain by w_end / (w_end + w_next) of
/// each correction, cannot carry a heavy end mass; the direct solve does at any mass ratio. It is used
/// where that is needed, on chains whose masses differ by a factor of 10 or more; even chains, whose
/// load Gauss-Seidel carries, keep its sweep and its robustness to rows turning fast.
struct RowPartition
{
  std::vector<std::uint32_t> swept;        ///< rows left to Gauss-Seidel, in model order
  std::vector<std::uint32_t> chain_rows;   ///< the rows of every chain, each in path order, one after another
  std::vector<std::uint32_t> chain_starts; ///< chain c is chain_rows[chain_starts[c], chain_starts[c + 1])
};

/// Splits rows (given by their end nodes, ends[r] = {a, b}) into chains of two or more rows with a free
/// end and a mass ratio of 10 or more, each listed from that end, and the rest. A chain of one row is
/// left to the sweep: for a single row the Gauss-Seidel update is the exact solve. Depends on which
/// nodes are free: recompute it when a node is pinned or released.
RowPartition partitionRows(const std::vector<std::pair<int, int>>& ends, const Eigen::VectorXd& inverse_mass);

/// How contacts hold the nodes of the chains in their solve (chain_contacts.h), per node of the model.
struct NodeHolds
{
  enum Kind : std::uint8_t
  {
    kFree,   ///< not held
    kSlide,  ///< held on a surface: it moves only in the surface's tangent plane
    kStick,  ///< held in place (moving with the surface)
  };
  std::vector<std::uint8_t> kind;
  NodeArray normal;    ///< the surface's unit normal at a kSlide node
  NodeArray slip;      ///< the unit direction a kSlide node slips in, in its tangent plane
  std::vector<double> friction;  ///< the kinetic friction coefficient at a kSlide node
  /// h^2 f [kg m] of the part of a kSlide node's kinetic friction f that does not come from the rows (the
  /// friction of its own inertia and weight pressing it on), taken into the first Newton step of its
  /// sub-step: x += W~ h^2 f with the rows' dlambda that answer it in the same linear solve.
  NodeArray push;
};

/// One Newton step of XPBD on a chain, with the chain's geometric stiffness.
///
/// Linearised at the predicted positions, the system above treats the turning of the rows explicitly:
/// in the zig-zag mode, each light node of a chain of tension T pushed sideways by d (its neighbours by
/// -d) is moved back by 4 a d in one step, a = h^2 T / (m l). With the velocity x' - x this leaves,
/// d_{n+1} = (1 - 4 a)(2 d_n - d_{n-1}), which grows once a > 1/3: a heavy end mass swinging on light
/// nodes blows up (Tournier, Nesme, Gilles, Faure 2015, "Stable constrained dynamics": the missing
/// geometric stiffness). A lumped approximation of the geometric stiffness added to the mass matrix (the
/// remedy of Andrews, Teichmann, Kry 2017, "Geometric stiffness for real-time constrained multibody
/// dynamics", for heavy loads on cables) keeps the system tridiagonal:
///   M~_k = m_k I + sum over the chain's rows at node k of 2 h^2 T / l (I - u u^T),
///   ((I + Gamma) J W~ J^T + alpha~) dlambda = -C - alpha~ lambda - Gamma J (x - x_prev),
///   x += W~ J^T dlambda,  W~ = M~^-1.
/// A row's geometric stiffness h^2 T / l [P -P; -P P] (P = I - u u^T, 0 in compression) is lumped onto
/// its nodes by absolute row sums, 2 h^2 T / l P on each. That bounds it from above (Gershgorin): the
/// zig-zag mode becomes d_{n+1} = (2 d_n - d_{n-1}) / (1 + 4 a), damped for any a (lumping the diagonal
/// blocks alone, 1 + 2 a, still grows once a > 1). Along a row P u = 0: a straight chain, and so its
/// statics, is unchanged; what it costs is inertia against sideways motion of nodes whose tension
/// impulse h^2 T / l rivals their mass.
///
/// T is this sub-step's tension, known only after the solve: the step uses the last sub-step's, and if
/// the solve finds more than twice that in any row (a slack chain jerked taut by its end mass: measured,
/// a heavy inextensible chain gained energy without bound from such snaps), it is repeated from the same
/// positions with the larger of the two. A steady or slowly changing load costs one solve.
class ChainSolver
{
public:
  void reserve(std::size_t rows);

  /// One Newton step on the chain `rows` (count consecutive rows in path order, count <= the reserved
  /// size) for a sub-step of h [s], with `tension` [N] per row from the last sub-step (repeated once
  /// with this one's if that was too small, see above): builds the tridiagonal system at the current
  /// positions, solves it, and applies
  ///   lambda_i += dlambda_i,  x_a += W~_a u_i dlambda_i,  x_b -= W~_b u_i dlambda_i
  /// to every row at once. A row that cannot move (both ends pinned or stuck, or coincident ends) keeps
  /// dlambda = 0 and decouples from its neighbours. `holds` (null: none) restrict the nodes held by
  /// contacts: W~ of a stuck node is 0, of a sliding one P W~ P with P = I - n n^T; with `push`, their
  /// kinetic friction acts in this step.
  void solve(const SweepRow* rows, std::size_t count, const Eigen::VectorXd& inverse_mass, const NodeArray& x_prev,
             double h, const double* tension, const NodeHolds* holds, bool push, NodeArray& x, double* lambda);

private:
  using Matrix3 = Eigen::Matrix3d;

  /// The step itself, with the geometric stiffness of the tensions in estimate_.
  void newtonStep(const SweepRow* rows, std::size_t count, const Eigen::VectorXd& inverse_mass, const NodeArray& x_prev,
                  double h, const NodeHolds* holds, bool push, NodeArray& x, double* lambda);

  /// Puts the chain's nodes and lambdas back where solve() found them.
  void restart(const SweepRow* rows, std::size_t count, NodeArray& x, double* lambda) const;

  /// W~ at `node`, one of the nodes of row i.
  Matrix3 mobility(const SweepRow* rows, std::size_t count, std::size_t i, int node,
                   const Eigen::VectorXd& inverse_mass, const NodeHolds* holds) const;

  NodeArray start_a_;             ///< each row's node a before the step, for a repeat [m]
  NodeArray start_b_;             ///< ... and its node b
  std::vector<double> start_lambda_;
  std::vector<double> estimate_;  ///< the tension T_i the geometric stiffness uses [N]
  NodeArray direction_;           ///< u_i, zero for a row that cannot move
  std::vector<double> geometric_;  ///< the lumped geometric stiffness 2 h^2 T_i / l_i [kg]
  std::vector<Matrix3> mobility_a_;  ///< W~ at each row's node a [1/kg]
  std::vector<Matrix3> mobility_b_;  ///< ... and at its node b
  std::vector<double> diagonal_;
  std::vector<double> coupling_;        ///< (J W~ J^T)_{i,i+1}
  std::vector<double> coupling_below_;  ///< (J W~ J^T)_{i+1,i}: the same unless kinetic friction acts there
  std::vector<double> rhs_;
  std::vector<double> upper_;     ///< the Thomas algorithm's modified super-diagonal c'_i
  std::vector<double> delta_;     ///< its modified right-hand side d'_i, then dlambda_i
};

}  // namespace soft_body_sim
