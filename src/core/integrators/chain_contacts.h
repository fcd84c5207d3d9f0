// Contact inside XPBD's solve of the chains (private to the core library).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/solvers/chain_solver.h"

namespace soft_body_sim
{
/// A chain's nodes in path order, and between nodes[j] and nodes[j + 1] the row rows[j] (its place among
/// XPBD's chain rows, which follow the swept ones in its solve order).
struct ChainPath
{
  std::vector<int> nodes;
  std::vector<std::size_t> rows;

  void carry(StateArchive& archive) { archive(nodes, rows); }
};

/// Colliders holding the nodes of XPBD's chains (chain_solver.h) inside the chains' solve, with Coulomb
/// friction.
///
/// Why inside: a rope carrying a load over a collider (a cable over a pulley, the capstan) is held by
/// friction on its light nodes, and the load at its end feels that friction only through the rope's
/// tension. The contact stage after the solve (contact_stage.h) can stop a node only at the node's own mass;
/// the next solve, which carries the load, moves it on. Measured on a 42 g rope with 0.5 kg loads over
/// a capsule with friction 0.3: the loads ran as if the capsule were frictionless.
///
/// How: each sub-step, every free node of a chain whose predicted position is within its contact radius
/// of a surface (or, if it was held at the last sub-step, within a margin beyond it) is held
/// (NodeHolds). Consecutive held nodes of a chain form a run, which sticks or slides as a whole: an
/// inextensible rope on a convex surface cannot slip at one node and not at the next.
///  - A stuck run moves with the surface, and the solve treats its nodes as pinned. The tensions inside
///    it are statically indeterminate: they are taken to change geometrically from one end's to the
///    other's, the distribution that asks the same friction of every node of a uniformly curved wrap.
///  - A sliding run is put on the surface and moves only in its tangent planes, against kinetic
///    friction mu N opposite to its slip, with N the normal force of this very solve: the part the rows
///    press it on with is in the chain's linear system (ChainSolver::mobility), the rest (its own weight
///    and inertia) an external force in the chains' first Newton step (NodeHolds::push). (N from the last
///    solve instead feeds back: friction raises the tension on the tight side, which raises N, with a
///    gain near mu theta; measured, the loads stopped above the capstan bound.)
/// After a solve, the contact force on a held node is what keeps it where it is:
///    F = (m (x - x~) - J^T lambda) / h^2   (J^T lambda: the rows' impulses on it, times h),
/// whose normal part N must push (else the node is let go) and whose tangential part must lie within the
/// friction cone mu N at every node of a stuck run (else the run slides towards its more tense end); a
/// sliding run whose slip turns back sticks. Any change solves the chains again from the prediction, at
/// most kPasses times per sub-step (an active set). So a rope over a fixed cylinder holds while the
/// tensions at its ends differ by less than the capstan's e^(mu theta) (on the polygon of its nodes,
/// ((1 + mu tan(d / 2)) / (1 - mu tan(d / 2)))^n for n bends of d), and slides with that ratio otherwise.
class ChainContacts
{
public:
  /// Solves of one sub-step at most (the first and kPasses - 1 corrections).
  static constexpr int kPasses = 4;

  /// The chains (once per ordering of the rows).
  void setPaths(const Model& model, std::vector<ChainPath> paths);

  /// Before the solve of a sub-step of h [s] from `start` (the positions at its start), `x` being the
  /// prediction x~: finds the held nodes and moves them where their hold puts them. False if none is held.
  bool hold(const Model& model, const ContactQuery& contacts, const NodeArray& start, double h, NodeArray& x);

  /// After a solve, with the chains' rows in solve order and their multipliers `lambda` (ChainPath::rows index both):
  /// sets the tensions inside stuck runs, checks every run's contact forces (see the class comment) and
  /// changes the holds that violate them. True if any changed: the caller puts the chains' nodes back with
  /// place() and solves them again.
  bool check(const Model& model, const std::vector<SweepRow>& rows, double* lambda, const NodeArray& start, double h,
             const NodeArray& x);

  /// After the last check of a sub-step of h [s] (the chains at `x`): every node held in the last solve
  /// tells its collider the opposite of its contact force F times h (the class comment), at the surface
  /// point under it (ContactQuery::receive).
  void report(const Model& model, double h, const NodeArray& x, ContactQuery& contacts) const;

  /// Puts every free node of the chains where the current holds put it (the prediction for a free one),
  /// and sets the sliding ones' kinetic friction.
  void place(const Model& model, const NodeArray& start, double h, NodeArray& x);

  /// True if node `node` cannot move in the solve (pinned or stuck).
  bool immobile(const Model& model, int node) const
  {
    return !model.isFree(node) || holds_.kind[static_cast<std::size_t>(node)] == NodeHolds::kStick;
  }

  const NodeHolds& holds() const { return holds_; }

  void carry(StateArchive& archive)
  {
    archive(paths_, nodes_, holds_, before_, predicted_, contact_, slip_, impulse_, pressed_, force_);
  }

private:
  /// Calls visit(path, first, end) for every run nodes[first, end) of held nodes.
  template <typename Visit>
  void forEachRun(Visit visit) const;


  /// The unit direction along the rope at node j of `path` (towards its end), in the node's tangent plane.
  Vec3 along(const ChainPath& path, std::size_t j, const NodeArray& x) const;

  /// The run nodes[first, end) of `path` slips along itself, towards the path's end if `towards_end` >= 0.
  void setSlip(const ChainPath& path, std::size_t first, std::size_t end, const NodeArray& x, double towards_end);

  std::vector<ChainPath> paths_;
  std::vector<int> nodes_;            ///< the free nodes of the chains
  NodeHolds holds_;                   ///< per node of the model
  std::vector<std::uint8_t> before_;  ///< per node: its hold in the last sub-step
  NodeArray predicted_;               ///< x~ at the held nodes [m]
  std::vector<NodeContact> contact_;  ///< per node: its surface at x~ (held nodes)
  NodeArray slip_;                    ///< per node: the unit direction a sliding node slips in
  NodeArray impulse_;                 ///< per node: J^T lambda, the rows' impulses times h [kg m]
  std::vector<int> pressed_;          ///< the nodes held in the last checked solve
  NodeArray force_;                   ///< per node: F [N] of the last check, for the nodes in pressed_
};

}  // namespace soft_body_sim
