// A symmetric positive definite linear system of 3x3 blocks, one block row per node: implicit Euler's
// Newton system A dv = rhs (private to the core library). It owns what every element kind shares: the
// right-hand side, each node's diagonal block, the pattern of node pairs whose blocks may be non-zero (one
// slot each), and the solves. The off-diagonal blocks stay with the kinds that make them (each kind's
// ImplicitBlocks, element_kinds.h), in whatever compact form suits the kind, so A is never stored whole
// except inside a direct solver. A solve takes them as `Blocks`, anything with
//   multiply(p, out)            out += (A - its diagonal blocks in diagonal()) p
//   addToPreconditioner(blocks) each node's block of A not in diagonal() (kinds that keep theirs apart)
//   write(solver)               addDiagonal / addOffDiagonal of those blocks into a direct solver
// and chooses between the direct solves (block tridiagonal where the free nodes form chains, else a sparse
// LDL^T) and conjugate gradients, preconditioned by block Jacobi or by a multigrid cycle, by what they cost
// (see solve). Where some of the free nodes form chains and others not (ropes beside a cloth), block-Jacobi
// conjugate gradients solve the chains exactly in their preconditioner (chain_preconditioner_).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>
#include <vector>

#include <Eigen/LU>

#include "core/integrators/integrator_kit.h"
#include "core/solvers/aggregation_multigrid.h"
#include "core/solvers/block_tridiagonal_solver.h"
#include "core/solvers/sparse_block_solver.h"
#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
class BlockSystem
{
public:
  using Matrix3 = Eigen::Matrix3d;

  explicit BlockSystem(LinearSolve mode) : mode_(mode) {}

  // --- the pattern: node pairs whose blocks may be non-zero, one slot each --------------------------
  /// Forgets every pair (a new model).
  void clearPattern() { pairs_.clear(); }
  /// The slot of the new pair (a, b), a != b both free.
  int addPair(int a, int b)
  {
    pairs_.emplace_back(a, b);
    return static_cast<int>(pairs_.size()) - 1;
  }
  std::size_t pairCount() const { return pairs_.size(); }
  /// Room for `more` pairs beyond those there (a kind adds its pairs after it: no spare capacity from
  /// growth by doubling, 36 bytes a node on a large cloth).
  void reservePairs(std::size_t more) { pairs_.reserve(pairs_.size() + more); }
  const std::vector<std::pair<int, int>>& pairs() const { return pairs_; }
  /// Drops the pairs after the first `count` (those a kind added later and no longer needs).
  void truncatePairs(std::size_t count) { pairs_.resize(count); }
  /// Prepares the solves for the pattern over `nodes` nodes: the block-tridiagonal one where the pairs form
  /// chains, the sparse one where the chains alone cannot serve (not chains, or `sparse_too`: pairs outside
  /// chains may join in some steps, analyzeSparse).
  void analyze(int nodes, bool sparse_too)
  {
    nodes_ = nodes;
    solid_sweeps_taken_ = 0.0;
    chains_ = !iterativeOnly() && tridiagonal_solver_.analyze(nodes, pairs_);
    factorable_ = chains_ && !sparse_too;
    if (factorable_)
    {
      keepChainPreconditioner(false);  // every solve is the direct one
      keepMultigrid(false);
    }
    else
      analyzeSparse();
  }
  /// Prepares the sparse solve again, for pairs added since analyze, and the chains of conjugate gradients'
  /// preconditioner.
  void analyzeSparse()
  {
    factorable_ = !iterativeOnly() &&
                  sparse_solver_.analyze(nodes_, pairs_, mode_ == LinearSolve::Direct ? kAnyWork : kMaxFactorWork);
    keepChainPreconditioner(mode_ == LinearSolve::Cheaper && chain_solver_.analyzeChains(nodes_, pairs_));
    keepMultigrid(false);  // analysed again where a solve first takes it
  }
  bool iterativeOnly() const { return mode_ == LinearSolve::Iterative || mode_ == LinearSolve::Multigrid; }

  // --- the values of one Newton iteration -----------------------------------------------------------
  /// Per node: its diagonal block of A [kg], which the kinds add to (their diagonal blocks, unless they keep
  /// them apart: addToPreconditioner and write give them then).
  std::vector<Matrix3>& diagonal() { return diagonal_; }
  const std::vector<Matrix3>& diagonal() const { return diagonal_; }
  Matrix3& diagonal(int node) { return diagonal_[static_cast<std::size_t>(node)]; }
  /// The right-hand side (3 x nodes); a solve by conjugate gradients leaves its residual there.
  NodeArray& rhs() { return rhs_; }
  const NodeArray& rhs() const { return rhs_; }
  /// Sizes the right-hand side and the diagonal for `nodes` nodes and restarts the condition estimate.
  void start(int nodes)
  {
    rhs_.resize(3, nodes);
    diagonal_.resize(static_cast<std::size_t>(nodes));
    condition_ = 1.0;
    solid_sweeps_ = 0.0;
  }
  /// An element's estimate of the block-Jacobi preconditioned A's condition number (the largest is kept):
  /// about 1 + 4 (h^2 k + h c) / m for a spring of stiffness k and dashpot c on its lightest free end m.
  void noteCondition(double condition) { condition_ = std::max(condition_, condition); }
  /// The same for an element on nodes a and b, unless it lies on a chain that the preconditioner solves
  /// exactly: conjugate gradients' sweeps are then those of the other nodes' elements.
  void noteCondition(double condition, int a, int b)
  {
    if (!(chain_preconditioner_ && (chain_solver_.onPath(a) || chain_solver_.onPath(b))))
      noteCondition(condition);
  }
  /// A soft solid's estimate of the sweeps conjugate gradients take on it (the largest is kept): its
  /// sweeps grow with the mesh's size, not with its elements' stiffness over mass (TetrahedronKind).
  void noteSolidSweeps(double sweeps) { solid_sweeps_ = std::max(solid_sweeps_, sweeps); }
  /// The sweeps conjugate gradients took in their last solve with soft solids since analyze (0: none), which
  /// the choice of solve takes where more than the estimate; carried in snapshots, since it steers the
  /// choice.
  double& solidSweepsTaken() { return solid_sweeps_taken_; }

  /// dv = A^-1 rhs: directly, A written from the diagonal and `blocks` into the analysed pattern (block
  /// tridiagonal where the free nodes form chains and `chains_usable`, else sparse), or by conjugate
  /// gradients where they cost less (see kDirectWorkPerRootCondition). A chain's factorisation costs about as
  /// much as one CG sweep, so a chain always takes the direct path.
  template <class Blocks>
  void solve(const Blocks& blocks, bool chains_usable, NodeArray& dv)
  {
    if (chains_ && chains_usable)
    {
      solveDirectly(blocks, tridiagonal_solver_, dv);
      return;
    }
    const double solid_sweeps = solid_sweeps_ > 0.0 ? std::max(solid_sweeps_, solid_sweeps_taken_) : 0.0;
    const double cg_cost = std::max(kDirectWorkPerRootCondition * std::sqrt(condition_),
                                    kDirectWorkPerSolidSweep * solid_sweeps);
    // The multigrid cycle's cost hardly grows with the condition or the size (kMultigridWork). Not where
    // the chains' exact solve serves (a stiff chain's sweeps under the cycle: 131 to 235 for a 1e4 N/m chain
    // beside a cloth, test_linear_solvers, where the chains' solve leaves the cloth's), nor on soft solids,
    // whose rotations its coarse levels leave out.
    const bool by_multigrid =
        mode_ == LinearSolve::Multigrid ||
        (mode_ == LinearSolve::Cheaper && !chain_preconditioner_ && solid_sweeps == 0.0 && nodes_ >= kMultigridNodes &&
         cg_cost > kMultigridWork);
    const bool cheaper_by_cg = mode_ == LinearSolve::Cheaper && sparse_solver_.factorWork() /
                                                                        sparse_solver_.matrixEntries() >
                                                                    (by_multigrid ? kMultigridWork : cg_cost);
    if (!factorable_ || cheaper_by_cg)
    {
      if (!(by_multigrid ? buildMultigrid(blocks) : buildPreconditioner(blocks)))
      {
        dv.setConstant(3, rhs_.cols(), std::numeric_limits<double>::quiet_NaN());  // as solveDirectly's
        return;
      }
      const double sweeps = static_cast<double>(solveIteratively(blocks, by_multigrid, dv));
      if (solid_sweeps_ > 0.0)
        solid_sweeps_taken_ = sweeps;
      return;
    }
    solveDirectly(blocks, sparse_solver_, dv);
  }

private:
  /// Whether conjugate gradients' preconditioner solves the chains (chain_preconditioner_); without, the
  /// chains' solver's arrays are freed (a cloth of 100,000 nodes has no chain).
  void keepChainPreconditioner(bool keep)
  {
    chain_preconditioner_ = keep;
    if (!keep)
      chain_solver_ = BlockTridiagonalSolver();
  }

  /// Whether the multigrid cycle's levels are kept (multigrid_ready_); without, their arrays are freed.
  void keepMultigrid(bool keep)
  {
    multigrid_ready_ = keep;
    if (!keep)
      multigrid_.release();
  }

  /// The multigrid cycle as conjugate gradients' preconditioner, its pattern analysed where first taken
  /// since analyze; false if A is not positive definite (as buildPreconditioner).
  template <class Blocks>
  bool buildMultigrid(const Blocks& blocks)
  {
    if (!multigrid_ready_)
    {
      multigrid_.analyze(nodes_, pairs_);
      multigrid_ready_ = true;
    }
    multigrid_.start(diagonal_);
    blocks.write(multigrid_);
    return multigrid_.setup();
  }

  /// Writes A into `solver` (analysed with the pattern's slots), factorises it and solves for dv.
  template <class Blocks, class Solver>
  void solveDirectly(const Blocks& blocks, Solver& solver, NodeArray& dv)
  {
    solver.start(diagonal_);
    blocks.write(solver);
    // A is symmetric positive definite by construction (each kind keeps its blocks so), unless the state is
    // not finite: then the step is not finite either, and the divergence guard (guard.h) takes it.
    if (solver.factorize())
      solver.solve(rhs_, dv);
    else
      dv.setConstant(3, rhs_.cols(), std::numeric_limits<double>::quiet_NaN());
  }

  /// Conjugate gradients' preconditioner: block Jacobi, the inverse of each node's full 3x3 diagonal block
  /// (SPD, so invertible), and with chain_preconditioner_ the chains' own part of A factorised; false if that
  /// is not positive definite (the state is not finite, as in solveDirectly).
  template <class Blocks>
  bool buildPreconditioner(const Blocks& blocks)
  {
    preconditioner_ = diagonal_;
    blocks.addToPreconditioner(preconditioner_);
    // The chains' nodes take the chains' solve instead (precondition).
    for (std::size_t i = 0; i < preconditioner_.size(); ++i)
      if (!(chain_preconditioner_ && chain_solver_.onPath(static_cast<int>(i))))
        preconditioner_[i] = preconditioner_[i].inverse().eval();
    if (!chain_preconditioner_)
      return true;
    chain_solver_.start(diagonal_);
    blocks.write(chain_solver_);
    return chain_solver_.factorize();
  }

  /// out = A p.
  template <class Blocks>
  void multiply(const Blocks& blocks, const NodeArray& p, NodeArray& out) const
  {
    for (Eigen::Index i = 0; i < p.cols(); ++i)
      out.col(i) = diagonal_[static_cast<std::size_t>(i)] * p.col(i);
    blocks.multiply(p, out);
  }

  /// z = M^-1 r: the multigrid cycle where `multigrid` (its fine level's product) is given, else block
  /// Jacobi (with the chains' solve).
  void precondition(const NodeArray& r, NodeArray& z, const AggregationMultigrid::FineProduct* multigrid)
  {
    if (multigrid)
    {
      multigrid_.apply(r, z, *multigrid);
      return;
    }
    if (!chain_preconditioner_)
    {
      for (Eigen::Index i = 0; i < r.cols(); ++i)
        z.col(i) = preconditioner_[static_cast<std::size_t>(i)] * r.col(i);
      return;
    }
    chain_solver_.solve(r, z);
    for (Eigen::Index i = 0; i < r.cols(); ++i)
      if (!chain_solver_.onPath(static_cast<int>(i)))
        z.col(i) = preconditioner_[static_cast<std::size_t>(i)] * r.col(i);
  }

  static double dot(const NodeArray& a, const NodeArray& b) { return a.cwiseProduct(b).sum(); }

  /// A p through the kinds' compact blocks, for the multigrid cycle's fine level.
  template <class Blocks>
  class FineProduct final : public AggregationMultigrid::FineProduct
  {
  public:
    FineProduct(const BlockSystem& system, const Blocks& blocks) : system_(system), blocks_(blocks) {}
    void operator()(const NodeArray& x, NodeArray& out) const override { system_.multiply(blocks_, x, out); }

  private:
    const BlockSystem& system_;
    const Blocks& blocks_;
  };

  /// dv = A^-1 rhs by preconditioned conjugate gradients from 0, stopped at a relative residual of
  /// kTolerance or after 2 * 3n iterations (the algorithm and the stopping rule of Eigen's
  /// ConjugateGradient), multiplying by the blocks directly, preconditioned by the multigrid cycle where
  /// `by_multigrid`, else by the inverse of each node's 3x3 diagonal block (and the chains' solve).
  ///
  /// The residual takes the right-hand side's place (rhs_, which the next assembly makes anew), and the
  /// preconditioned residual z the product's (A direction, not needed once the residual is updated): two
  /// vectors where Eigen's takes four, 48 bytes a node.
  /// Returns the sweeps it took.
  template <class Blocks>
  Eigen::Index solveIteratively(const Blocks& blocks, bool by_multigrid, NodeArray& dv)
  {
    const Eigen::Index n = rhs_.cols();
    dv.setZero(3, n);
    NodeArray& residual = rhs_;
    const double rhs_norm2 = rhs_.squaredNorm();
    if (rhs_norm2 == 0.0)
      return 0;
    const double threshold = std::max(kTolerance * kTolerance * rhs_norm2, std::numeric_limits<double>::min());
    double residual_norm2 = rhs_norm2;
    if (residual_norm2 < threshold)
      return 0;  // rhs so small (near underflow) that any iteration would divide by zero
    direction_.resize(3, n);
    product_.resize(3, n);
    const FineProduct<Blocks> fine_product(*this, blocks);
    const AggregationMultigrid::FineProduct* multigrid = by_multigrid ? &fine_product : nullptr;
    NodeArray& z = product_;
    precondition(residual, direction_, multigrid);
    double r_dot_z = dot(residual, direction_);
    const Eigen::Index max_iterations = 2 * 3 * n;
    Eigen::Index iteration = 0;
    while (iteration < max_iterations)
    {
      multiply(blocks, direction_, product_);
      ++iteration;
      const double alpha = r_dot_z / dot(direction_, product_);
      dv += alpha * direction_;
      residual -= alpha * product_;
      residual_norm2 = residual.squaredNorm();
      if (residual_norm2 < threshold)
        break;
      precondition(residual, z, multigrid);
      const double previous_r_dot_z = r_dot_z;
      r_dot_z = dot(residual, z);
      direction_ = z + (r_dot_z / previous_r_dot_z) * direction_;
    }
    return iteration;
  }

  /// CG stops at a relative residual of 1e-12: far below the scheme's O(h) error; without it CG would
  /// iterate to machine precision (up to 6n sweeps).
  static constexpr double kTolerance = 1e-12;

  /// Which solve is cheaper. A conjugate-gradient sweep costs one multiply-add per entry of A, and CG's
  /// sweeps to a relative residual of 1e-12 grow like the square root of the preconditioned condition
  /// number (noteCondition); a factorisation costs its work per entry. So the direct path is taken while
  /// work per entry <= C sqrt(condition). The bound ln(2e12) / 2 = 14 sweeps per square root of the
  /// condition would give C = 14, but CG converges faster than its bound on these spectra and a sparse
  /// factorisation's multiply-add costs more than a sweep's: measured on the benchmark cloth at
  /// dt = 1/60 s (bench_step BM_ClothLinearSolveAt60Hz, condition ~840), direct is 1.4 times faster at
  /// 100 nodes (61 per entry, 2.1 sqrt(condition)) and CG 1.1 times faster at 324 (169 per entry,
  /// 5.8 sqrt(condition)), 1.8 times at 1,024: C = 4 switches between them. On a rope with bending
  /// springs the factor has no fill (2.9 per entry) and a stiff rope is badly conditioned (k = 1e6 N/m,
  /// 1 g nodes, dt = 1/60 s: ~1e6): always direct, and linear in the length. At small steps the mass
  /// dominates the matrix (condition ~1) and CG serves every cloth.
  static constexpr double kDirectWorkPerRootCondition = 4.0;
  /// On soft solids the condition estimate says little: CG's sweeps there hardly change with the step (at
  /// 1/60 and 4 ms: 167 and 146 on the benchmark box of 1,243 tetrahedra, where sqrt(condition) is 300 and
  /// 72) and grow with the mesh (TetrahedronKind's estimate). Measured (bench_step BM_SoftBox direct and
  /// iterative, both steps, docs/RESULTS.md "Soft solids"): direct is faster at 3,127 tetrahedra (136
  /// multiply-adds per entry; CG took 239 sweeps at 1/60 s) and CG at 5,269 (266; 268 sweeps): the direct
  /// path while its work per entry <= 0.7 of the estimated sweeps. The estimate is the cube's: on a slender
  /// or light solid CG takes more (a 30 cm cantilever 3 cm deep of 32,557 tetrahedra whose nodes weigh
  /// next to nothing, test_volume: 1,300 to 1,500 sweeps where it estimated 479, and 495 multiply-adds per
  /// entry), so the sweeps CG took in its last solve stand for the estimate where more (solidSweepsTaken):
  /// one solve by CG, then the cheaper factorisation.
  static constexpr double kDirectWorkPerSolidSweep = 0.7;
  /// Multigrid-preconditioned conjugate gradients (AggregationMultigrid) in the units of
  /// kDirectWorkPerRootCondition: measured on the benchmark cloth at 1/60 s (bench_step
  /// BM_ClothLinearSolveAt60Hz, docs/RESULTS.md "Multigrid"), 29 to 40 sweeps from 1,024 to 99,856 nodes
  /// where block Jacobi takes 110 to 417, each sweep about five of block Jacobi's and the levels' setup about
  /// 60 more: about 230 block-Jacobi sweeps a solve, which block Jacobi, at about 14 sweeps per square root
  /// of the condition on this cloth (417 at sqrt(condition) 29), costs at 4 sqrt(condition) = 66.
  static constexpr double kMultigridWork = 66.0;
  /// Below this many nodes block Jacobi's sweeps have not reached their bound (the cloth's smoothest modes
  /// are not yet felt): at 1,024 nodes the two cost the same (8.4 and 8.6 ms), at 3,136 multigrid is 1.3
  /// times faster (28.6 and 37.9 ms), at 324 slower.
  static constexpr int kMultigridNodes = 2000;
  /// No factorisation is even prepared beyond this work per entry (a 100,000-node cloth would need
  /// 0.75 GB for its factor).
  static constexpr double kMaxFactorWork = 2000.0;
  static constexpr double kAnyWork = std::numeric_limits<double>::infinity();

  LinearSolve mode_;
  int nodes_ = 0;
  std::vector<std::pair<int, int>> pairs_;  ///< the pattern: slot k couples pairs_[k]
  bool chains_ = false;                     ///< the pairs form chains: tridiagonal_solver_ can solve
  bool factorable_ = true;                  ///< the pattern is prepared for a direct solve (see kMaxFactorWork)
  double condition_ = 1.0;                  ///< estimate of block-Jacobi preconditioned A's condition number
  double solid_sweeps_ = 0.0;               ///< the soft solids' estimate of CG's sweeps (0: none)
  double solid_sweeps_taken_ = 0.0;         ///< solidSweepsTaken
  NodeArray rhs_;
  std::vector<Matrix3> diagonal_;        ///< per node: its block of A (but the kinds' kept apart)
  std::vector<Matrix3> preconditioner_;  ///< per node: the inverse of A's full diagonal block (CG)
  NodeArray direction_, product_;        ///< conjugate gradients' vectors (solveIteratively)
  SparseBlockSolver sparse_solver_;
  BlockTridiagonalSolver tridiagonal_solver_;
  /// Where the free nodes are not all chains but some components of the pattern are (the demo's rope,
  /// string and coil beside its cloth, jelly and creature), those components' blocks are factorised by the
  /// block-tridiagonal solve and the preconditioner applies their inverse exactly, block Jacobi the others'.
  /// A is block diagonal over its components, so the chains' residual is gone after the first sweep and the
  /// sweeps are the other components': before, the stiffest chain set them all (the demo's coil, h^2 k / m =
  /// 11 at 1 ms: 110 to 130 sweeps, against 13 to 25 with the chains solved while its cloth falls; measured,
  /// docs/RESULTS.md "The demo under implicit Euler"). The preconditioner stays SPD: each chain component
  /// holds all of its elements' blocks. Only where the rule chooses (LinearSolve::Cheaper):
  /// LinearSolve::Iterative stays plain block Jacobi.
  bool chain_preconditioner_ = false;
  BlockTridiagonalSolver chain_solver_;  ///< the chains among the pattern (analyzeChains)
  AggregationMultigrid multigrid_;       ///< the multigrid cycle, where the rule takes it (solve)
  bool multigrid_ready_ = false;         ///< multigrid_ is analysed for the pattern
};

}  // namespace soft_body_sim
