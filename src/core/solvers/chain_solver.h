// A direct solve of XPBD's linearised system for rows that form chains (private to the core library).
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "core/integrators/integrator_kit.h"

namespace soft_body_sim
{
/// The rows of an XPBD solve split into chains, solved directly, and the rest, swept by Gauss-Seidel.
///
/// XPBD's linearised system (Macklin, Mueller, Chentanez 2016, eqs. 12 and 26) over all rows is
///   ((I + Gamma) J W J^T + alpha~) dlambda = -C - alpha~ lambda - Gamma J (x - x_prev),
/// where (J W J^T)_ij = sum over nodes k of w_k gradC_i(k) . gradC_j(k): two rows couple only through a
/// free node they share (w = 0 at a pinned one). When every free node joins at most two rows and the
/// rows so coupled form no cycle, each connected set of rows is a path, and in path order its matrix is
/// tridiagonal, solved exactly in O(n) by the Thomas algorithm, with no fill-in (Deul, Kugelstadt, Weiler,
/// Bender 2018, "Direct Position-Based Solver for Stiff Rods": tree-structured systems; a path is the
/// simplest tree). Gauss-Seidel moves the end of a chain by w_end / (w_end + w_next) of each correction
/// and cannot carry a heavy end mass; on an even chain pinned at both ends its error at rest grows like
/// g h^2 N^2 / (pi^2 sweeps) (the inextensible hanging chain of the work-precision report needed 32
/// sub-steps of 10 ms at 51 nodes and 128 at 201 for 1 mm; solved directly, 2 and 8, 2e-7 m at rest).
/// So every chain is solved directly but an even one (masses within a factor of 10) with a free end:
/// swinging at large steps, its rows turn fast and the linearised step runs away where the sweep stays
/// finite (measured: a 1 m, 0.1 kg inextensible rope released from horizontal, pinned at one end,
/// gained 1e7 J within 0.3 s at 51 nodes and h = 5 ms, and at 201 nodes and h = 2.5 ms; it was stable
/// and 3000 times less stretched than by the sweep at a quarter of those steps). Gauss-Seidel's error on
/// such a rope is its stretch, not a bias at rest: it keeps the sweep.
struct RowPartition
{
  std::vector<std::uint32_t> swept;        ///< rows left to Gauss-Seidel, in model order
  std::vector<std::uint32_t> chain_rows;   ///< the rows of every chain, each in path order, one after another
  std::vector<std::uint32_t> chain_starts; ///< chain c is chain_rows[chain_starts[c], chain_starts[c + 1])
  std::vector<std::uint8_t> chain_heavy;   ///< per chain: 1 if its masses differ by a factor of 10 or more
};

/// Splits rows (given by their end nodes, ends[r] = {a, b}) into chains of two or more rows, heavy ones
/// listed from a free end if they have one, even ones only if pinned at both ends, and the rest. A chain of one row is left to the sweep: for a single row
/// the Gauss-Seidel update is the exact solve. Depends on which nodes are free: recompute it when a node
/// is pinned or released.
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

  void carry(StateArchive& archive) { archive(kind, normal, slip, friction, push); }
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
/// A chain that sags is not straight: lumped, the stiffness also resists a translation, which the exact
/// one does not (its rows' blocks [P -P; -P P] sum to zero), and at rest every node moves by -h^2 g per
/// sub-step: the lumped term alone shifts the rest state by O(h^2) (measured on the hanging chain of
/// the work-precision report: 5.5e-4 m at 51 nodes and h = 1.25 ms, 2e-3 m at 201 nodes and h = 0.6 ms).
/// On an even chain the difference, per row h^2 T / l P (c_a + c_b) on each of its nodes, is applied as a
/// known force at the correction c = x - x~ of the last sub-step (like kinetic friction's push): at rest c repeats, and the
/// rest state is exactly XPBD's (error 2e-7 m at both sizes); the zig-zag mode, which the difference
/// does not contain, keeps its implicit damping.
///
/// T is this sub-step's tension, known only after the solve: the step uses the last sub-step's, and if
/// the solve finds more than twice that in any row (a slack chain jerked taut by its end mass: measured,
/// a heavy inextensible chain gained energy without bound from such snaps), it is repeated from the same
/// positions with the larger of the two. A steady or slowly changing load costs one solve.
///
/// Where rows turn fast the one linearised step is less robust than Gauss-Seidel's nonlinear projections,
/// also between two supports. Measured on the hanging chain released from a V, with the load
/// h^2 T / (m l) of its last sub-step's tensions: every run whose load stayed below 0.66 converged (51
/// nodes at h = 5 ms, 201 at 1.25 ms); at 51 nodes and h = 10 ms (0.76 from the start) and at 201 and
/// 2.5 ms (0.74), it grew past 1 and then ran away to NaN within a few sub-steps. So an even chain whose
/// load at any free node exceeds 1 is refused (solve() returns kLoaded) and left to the sweep. A heavy
/// chain, which the sweep cannot carry, is always solved directly (hard case 2: stable at a load of ~2
/// while straight).
///
/// Pinned at both ends, a nearly straight chain's system is nearly singular, and a step that must bend
/// it (a chain released straight and 20 % compressed between its supports) moves nodes by many rest
/// lengths. Measured on 21 nodes of 0.01 kg, 1 m between supports 0.8 m apart, released straight: at
/// h = 1 ms the direct solve blew up (a guard event) and stretched its chain to 94 m at h = 4.2 ms. So a
/// step of such a chain that would move any node by more than one rest length is refused for that
/// sub-step (kSingular) and the sweep takes it: it settles at its length, 1.00000 m, within 2.6 % on the
/// way. The same bound makes a heavy chain between two supports (a 10 kg node in the middle) mostly
/// swept, as before: measured, the sweep stretches it by 12 % (h = 1 ms) to 160 % (h = 4.2 ms); solved
/// directly at 4.2 ms it hung 0.2995 m deep (0.3 m for massless arms), but blew up at 1 ms. For a step
/// refused once the sweep is no worse than before this solve existed; the load refusal (kLoaded) is kept
/// until the rows are ordered again, because switching back and forth between the two is worse than
/// either (Xpbd::solveChains).
class ChainSolver
{
public:
  void reserve(std::size_t rows);

  /// One Newton step on the chain `rows` (count consecutive rows in path order, count <= the reserved
  /// size) for a sub-step of h [s], with `tension` [N] per row from the last sub-step (repeated once
  /// with this one's if that was too small, see above), unless it is an even chain loaded beyond its
  /// stable range or a nearly singular step (see above): then it says which and changes nothing. Builds the tridiagonal system
  /// at the current positions, solves it, and applies
  ///   lambda_i += dlambda_i,  x_a += W~_a u_i dlambda_i,  x_b -= W~_b u_i dlambda_i
  /// to every row at once. A row that cannot move (both ends pinned or stuck, or coincident ends) keeps
  /// dlambda = 0 and decouples from its neighbours. `holds` (null: none) restrict the nodes held by
  /// contacts: W~ of a stuck node is 0, of a sliding one P W~ P with P = I - n n^T; with `push`, their
  /// kinetic friction acts in this step, and with `correction` (null: none; per node of the model, the
  /// last sub-step's x - x~ [m]) the lumped stiffness's difference from the exact one (see above).
  /// `heavy`: the chain's masses differ by 10 or more (RowPartition::chain_heavy).
  enum Outcome
  {
    kSolved,
    kSingular,  ///< refused for this sub-step: nearly singular, a node would move too far (see above)
    kLoaded,    ///< refused: an even chain loaded beyond its stable range (see above)
  };

  Outcome solve(const SweepRow* rows, std::size_t count, const Eigen::VectorXd& inverse_mass, const NodeArray& x_prev,
                double h, const double* tension, bool heavy, const NodeHolds* holds, const NodeArray* correction,
                bool push, NodeArray& x, double* lambda);

private:
  using Matrix3 = Eigen::Matrix3d;

  /// The step itself, with the geometric stiffness of the tensions in estimate_.
  bool newtonStep(const SweepRow* rows, std::size_t count, const Eigen::VectorXd& inverse_mass, const NodeArray& x_prev,
                  double h, const NodeHolds* holds, const NodeArray* correction, bool push, bool bounded,
                  NodeArray& x, double* lambda);

  /// The row's direction, right-hand side and lumped geometric stiffness at the current positions.
  void evaluateRow(const SweepRow& row, std::size_t i, const NodeArray& x_prev, double h, const NodeArray& x,
                   double lambda);

  /// Row i's step of the Thomas algorithm's forward elimination.
  void eliminate(std::size_t i, std::size_t count);

  /// newtonStep without contacts, in short passes along the chain (`correction` null: no known forces).
  bool freeStep(const SweepRow* rows, std::size_t count, const Eigen::VectorXd& inverse_mass, const NodeArray& x_prev,
                double h, const NodeArray* correction, bool bounded, NodeArray& x, double* lambda);

  /// W~ = M~^-1 at a node of the path without contacts, where
  ///   M~ = m I + g_l (I - u_l u_l^T) + g_r (I - u_r u_r^T)
  /// (g_l, g_r the lumped geometric stiffness of the rows to its left and right along the path, u_l, u_r
  /// their directions; g = 0 and u = 0 where there is no such row). M~ is c I - U G U^T with c = m + g_l + g_r,
  /// U = [u_l u_r], G = diag(g_l, g_r), and by the Woodbury identity
  ///   W~ = I / c + U K U^T,   K = 1 / (c D) [g_l (m + g_l), g_l g_r s; g_l g_r s, g_r (m + g_r)],
  ///   D = (m + g_l)(m + g_r) - g_l g_r s^2 > 0,   s = u_l . u_r:
  /// one division per node instead of a 3 x 3 inverse, and products with u_l and u_r in a few scalars.
  struct NodeMobility
  {
    double inverse;  ///< 1 / c [1/kg]
    double ll;       ///< K's entries [1/kg]
    double lr;
    double rr;
    double s;        ///< u_l . u_r

    Vec3 times(const Vec3& left, const Vec3& right, const Vec3& v) const
    {
      const double pl = left.dot(v);
      const double pr = right.dot(v);
      return inverse * v + (ll * pl + lr * pr) * left + (lr * pl + rr * pr) * right;
    }
    /// W~ (alpha u_l) and W~ (beta u_r).
    Vec3 leftTimes(const Vec3& left, const Vec3& right, double alpha) const
    {
      return alpha * ((inverse + ll + lr * s) * left + (lr + rr * s) * right);
    }
    Vec3 rightTimes(const Vec3& left, const Vec3& right, double beta) const
    {
      return beta * ((ll * s + lr) * left + (inverse + lr * s + rr) * right);
    }
    double leftLeft() const { return inverse + ll + s * (2.0 * lr + rr * s); }     ///< u_l . W~ u_l
    double rightRight() const { return inverse + rr + s * (2.0 * lr + ll * s); }   ///< u_r . W~ u_r
    double leftRight() const { return (inverse + ll + rr) * s + lr * (1.0 + s * s); }  ///< u_l . W~ u_r
  };

  /// W~ at a free node of inverse mass w [1/kg] (0: pinned) between rows of geometric stiffness left and
  /// right [kg] whose directions make s = u_l . u_r.
  static NodeMobility nodeMobility(double w, double left, double right, double s);

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
  std::vector<Matrix3> mobility_a_;  ///< W~ at each row's node a [1/kg], with contacts
  std::vector<Matrix3> mobility_b_;  ///< ... and at its node b
  std::vector<double> diagonal_;
  std::vector<double> coupling_;        ///< (J W~ J^T)_{i,i+1}
  std::vector<double> coupling_below_;  ///< (J W~ J^T)_{i+1,i}: the same unless kinetic friction acts there
  std::vector<double> rhs_;
  NodeArray lag_;                 ///< per row, h^2 T / l P (c_a + c_b) [kg m] (see newtonStep)
  NodeArray push_a_;              ///< the known displacement W~ h^2 f of each row's node a in the first step [m]
  NodeArray push_b_;              ///< ... and of its node b
  NodeArray step_a_;              ///< the displacement W~_a u dlambda of each row's node a [m]
  NodeArray step_b_;              ///< ... and of its node b
  std::vector<double> upper_;     ///< the Thomas algorithm's modified super-diagonal c'_i
  std::vector<double> delta_;     ///< its modified right-hand side d'_i, then dlambda_i
  std::vector<int> path_;         ///< the chain's nodes in path order: row i joins path_[i] and path_[i + 1]
  std::vector<std::uint8_t> a_leads_;  ///< per row: 1 if its node a is path_[i]
  std::vector<NodeMobility> node_mobility_;  ///< W~ per node of the path, without contacts
  NodeArray node_step_;           ///< per node of the path, W~ J^T dlambda, without contacts [m]
  NodeArray node_push_;           ///< per node of the path, its known displacement in the first step [m]
};

}  // namespace soft_body_sim
