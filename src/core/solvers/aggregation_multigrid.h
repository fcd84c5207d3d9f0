// A preconditioner for a symmetric positive definite system of 3x3 blocks, one block row per node
// (private to the core library): implicit Euler's Newton system on large cloths at a ROS node's steps.
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

#include <Eigen/Cholesky>

#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
/// Smoothed aggregation multigrid (Vaněk, Mandel and Brezina 1996, "Algebraic multigrid by smoothed
/// aggregation for second and fourth order elliptic problems"), one V-cycle per application, for
/// conjugate gradients (BlockSystem).
///
/// Why: block-Jacobi CG's sweeps grow like sqrt(condition), and on a cloth at 1/60 s (h^2 k / m ~ 200) that
/// is several hundred sweeps once the cloth is large enough for its smoothest modes to be felt: the cost
/// grows faster than the nodes (docs/RESULTS.md, "Cost per spring update"). A multigrid cycle removes the
/// smooth part of the error on coarser levels, where it is not smooth any more, so the sweeps stop growing.
///
/// Each level's nodes are grouped into aggregates of strongly coupled neighbours (a root and its strong
/// neighbours, then the nodes left over joined to an adjacent aggregate), and a coarse node stands for an
/// aggregate's common translation (the 3 x 3 identity per node: the tentative prolongation P0; the
/// rotations are left out: measured on cloths only, whose sweeps stop growing without them). That P0 is smoothed by one damped Jacobi
/// step, P = (I - w D^-1 A) P0, so that a coarse correction is smooth across aggregates; the coarse matrix is
/// the Galerkin product P^T A P, SPD for an SPD A. Down to kDenseNodes nodes, solved there by a dense
/// Cholesky factorisation.
///
/// The cycle: pre-smoothing from zero by damped block Jacobi (x = w D^-1 b), the residual restricted by P^T,
/// the coarse level's cycle, the correction prolongated by P, and the same Jacobi step after. The two
/// smoothings are the same symmetric operator and each is a contraction in A's norm (w rho(D^-1 A) <= 4/3
/// < 2, rho bounded by the infinity norm of D^-1 A), so the cycle is a symmetric positive definite
/// operator, as CG's preconditioner must be.
///
/// The same interface as the direct solvers for the values (start, addDiagonal, addOffDiagonal: the
/// pattern's slots), analysed once per model change; setup builds the hierarchy from the values, every
/// Newton iteration. The levels keep their arrays, so after the first setup the same pattern allocates
/// nothing more.
class AggregationMultigrid
{
public:
  using Matrix3 = Eigen::Matrix3d;

  /// The pattern of a system over `nodes` nodes whose off-diagonal blocks may be non-zero for the node
  /// pairs `pairs` (i != j; a pair may repeat). Slot k of addOffDiagonal is pairs[k].
  void analyze(int nodes, const std::vector<std::pair<int, int>>& pairs);
  /// Starts a new matrix (same pattern): A's diagonal block of node i = diagonal[i], every other block 0.
  void start(const std::vector<Matrix3>& diagonal);
  /// A's diagonal block of node i += block (symmetric).
  void addDiagonal(int i, const Matrix3& block)
  {
    Level& fine = levels_.front();
    fine.a.block[fine.diagonal[static_cast<std::size_t>(i)]] += block;
  }
  /// A's block (a, b) += block, and (b, a) += block^T, for the pair (a, b) of slot `slot`.
  void addOffDiagonal(std::size_t slot, const Matrix3& block)
  {
    std::vector<Matrix3>& blocks = levels_.front().a.block;
    blocks[slot_position_[slot].first] += block;
    blocks[slot_position_[slot].second] += block.transpose();
  }

  /// Frees every array (the pattern is analysed again before the next use).
  void release();

  /// Builds the coarse levels from A as written; false if A is not positive definite to working precision
  /// (a diagonal block or the coarsest matrix fails its Cholesky factorisation: the state is not finite).
  bool setup();
  /// out = A x on the fine level, by whatever form the caller keeps A in (BlockSystem: the kinds' compact
  /// blocks, a few times fewer bytes to read than A's 3 x 3 blocks).
  class FineProduct
  {
  public:
    virtual void operator()(const NodeArray& x, NodeArray& out) const = 0;

  protected:
    ~FineProduct() = default;
  };
  /// z = one V-cycle applied to r (3 x nodes), after a successful setup.
  void apply(const NodeArray& r, NodeArray& z, const FineProduct& fine);

  /// The levels made by the last setup (the fine one included), and the nodes of the coarsest.
  std::size_t levelCount() const { return level_count_; }
  int coarsestNodes() const { return levels_[level_count_ - 1].a.rows(); }

private:
  /// A sparse matrix of 3 x 3 blocks by rows: row r's blocks are block[start[r] .. start[r + 1]), in
  /// columns column[...].
  struct BlockRows
  {
    int columns = 0;
    std::vector<std::size_t> start{ 0 };
    std::vector<int> column;
    std::vector<Matrix3> block;

    int rows() const { return static_cast<int>(start.size()) - 1; }
    /// The block in column `in_column` of the row being made (its blocks from row_start on), appended if the row has
    /// none yet; `mark` holds, per column, where its block last went (any value below row_start: none in
    /// this row).
    Matrix3& rowEntry(int in_column, std::ptrdiff_t row_start, std::vector<std::ptrdiff_t>& mark)
    {
      std::ptrdiff_t& at = mark[static_cast<std::size_t>(in_column)];
      if (at < row_start)
      {
        at = static_cast<std::ptrdiff_t>(block.size());
        column.push_back(in_column);
        block.push_back(Matrix3::Zero());
      }
      return block[static_cast<std::size_t>(at)];
    }
    void clear(int columns_count)
    {
      columns = columns_count;
      start.assign(1, 0);
      column.clear();
      block.clear();
    }
  };

  struct Level
  {
    BlockRows a;                            ///< this level's matrix (the fine one: as the kinds wrote it)
    std::vector<std::size_t> diagonal;      ///< per node: where its diagonal block is in a
    std::vector<Matrix3> smoother;          ///< per node: w D^-1, the damped block-Jacobi step
    double damping = 0.0;                   ///< w = 4 / (3 |D^-1 A|_inf)
    std::vector<int> aggregate;             ///< per node: its coarse node on the next level
    BlockRows prolongation;                 ///< P: this level's nodes from the next level's
    BlockRows restriction;                  ///< P^T
    BlockRows product;                      ///< A P, on the way to the next level's P^T A P
    NodeArray x, b, residual;               ///< the cycle's vectors on this level
  };

  /// Groups level l's nodes into aggregates (level.aggregate); returns how many.
  int aggregate(Level& level, double strength_threshold);
  /// level.smoother and the damping w; false if a diagonal block is not positive definite.
  bool makeSmoother(Level& level);
  /// P = (I - w D^-1 A) P0 of the aggregates, and P^T.
  void makeProlongation(Level& level, int aggregates);
  /// Where each node's diagonal block is in level.a; false if one has none.
  static bool findDiagonals(Level& level);
  /// The coarsest level's dense Cholesky factor, where it has at most kDenseNodes nodes (else it is smoothed
  /// only); false if that matrix is not positive definite.
  bool factorCoarsest();
  /// x = one cycle on b from level l down.
  void cycle(std::size_t l, const FineProduct& fine);

  /// out = a x.
  static void multiply(const BlockRows& a, const NodeArray& x, NodeArray& out);
  /// out = a b (a's columns are b's rows), with `mark` (b.columns entries, any values) as scratch.
  static void multiply(const BlockRows& a, const BlockRows& b, BlockRows& out, std::vector<std::ptrdiff_t>& mark);
  /// out = a^T, with `next` (a.columns entries) as scratch.
  static void transpose(const BlockRows& a, BlockRows& out, std::vector<std::size_t>& next);

  /// The coarsest level is solved directly at or below this many nodes (a 72 x 72 Cholesky factorisation,
  /// about 1e5 multiply-adds, a fraction of one fine sweep on a cloth of 1,000 nodes).
  static constexpr int kDenseNodes = 24;
  /// At most this many levels (a 2D mesh loses about 9 times its nodes a level: 100,000 nodes need 5).
  static constexpr std::size_t kMostLevels = 12;
  /// The levels stop where a level's aggregates would be more than this fraction of its nodes (a pattern
  /// that hardly coarsens: its last level is then smoothed rather than solved).
  static constexpr double kLeastCoarsening = 0.6;
  /// Two nodes are strongly coupled where |A_ij| >= threshold sqrt(|A_ii| |A_jj|) (Frobenius norms), the
  /// threshold halved on each coarser level (Vaněk, Mandel and Brezina's epsilon = 0.08 * 0.5^level).
  static constexpr double kStrengthThreshold = 0.08;

  std::vector<std::pair<std::size_t, std::size_t>> slot_position_;  ///< per slot: its blocks (a, b), (b, a)
  std::vector<Level> levels_;
  std::size_t level_count_ = 0;
  bool coarsest_dense_ = false;  ///< the coarsest level is solved by coarsest_factor_ (else smoothed)
  Eigen::MatrixXd coarsest_;
  Eigen::LLT<Eigen::MatrixXd> coarsest_factor_;
  Eigen::VectorXd coarsest_rhs_;
  std::vector<std::ptrdiff_t> mark_;  ///< scratch: where a column's block is in the row being made
  std::vector<int> roots_took_;       ///< scratch: the aggregates before the left-over nodes join them
  std::vector<double> diagonal_norm_;  ///< scratch: each node's |A_ii| (aggregate)
  std::vector<std::size_t> next_;     ///< scratch: transpose's next place in each row
};

}  // namespace soft_body_sim
