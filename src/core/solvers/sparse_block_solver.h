// A direct solve of a symmetric positive definite system of 3x3 blocks, one block row per node
// (private to the core library): implicit Euler's Newton system.
#pragma once

#include <array>
#include <limits>
#include <utility>
#include <vector>

#include <Eigen/SparseCholesky>

#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
/// A = sum of 3x3 blocks, solved by a sparse LDL^T factorisation (Eigen's SimplicialLDLT).
///
/// The pattern is analysed once per model change (analyze): a fill-reducing order of the nodes (AMD,
/// Amestoy, Davis and Duff 1996, Eigen's AMDOrdering over the node graph, each node's three rows kept
/// together), the symbolic factorisation, and where every block's entries sit in the matrix's storage.
/// Each Newton step then writes the values through those positions (no search, no allocation),
/// factorises numerically and solves. On a rope the order is the rope's own and the factor has no
/// fill: the cost is linear in the nodes; on a cloth of n nodes AMD keeps the fill near n log n.
class SparseBlockSolver
{
public:
  using Matrix3 = Eigen::Matrix3d;

  SparseBlockSolver() = default;
  /// The pattern and the symbolic factorisation made again from it (Eigen's factorisations cannot be
  /// copied; the numeric one is made afresh by every factorize, so the copy solves as the original).
  SparseBlockSolver(const SparseBlockSolver& other);
  SparseBlockSolver& operator=(const SparseBlockSolver& other);

  /// The pattern of a system over `nodes` nodes whose off-diagonal blocks may be non-zero for the node
  /// pairs `pairs` (i != j; a pair may repeat). Slot k of addOffDiagonal is pairs[k]. First counts what
  /// the factorisation would cost (the elimination tree and the column counts of L, node by node, in
  /// O(nodes) memory: Liu's up-looking algorithm); if that is more than `max_work_per_entry`
  /// multiply-adds per entry of A (a product A p costs one), it stops there and returns false (nothing
  /// more is allocated: the caller solves otherwise); else it prepares everything and returns true.
  bool analyze(int nodes, const std::vector<std::pair<int, int>>& pairs, double max_work_per_entry);

  /// Starts a new matrix (same pattern): A's diagonal block of node i = diagonal[i], every other block 0.
  void start(const std::vector<Matrix3>& diagonal);
  /// A's diagonal block of node i += block (symmetric).
  void addDiagonal(int i, const Matrix3& block);
  /// A's block (a, b) += block, and (b, a) += block^T, for the pair (a, b) of slot `slot`.
  void addOffDiagonal(std::size_t slot, const Matrix3& block);

  /// After analyze: the multiply-adds of one factorisation and the entries of A (both triangles), as
  /// analyze counted them.
  double factorWork() const { return work_; }
  double matrixEntries() const { return entries_; }

  /// Factorises A; false if it is not positive definite to working precision.
  bool factorize();
  /// x = A^-1 rhs (3 x nodes), after a successful factorize.
  void solve(const NodeArray& rhs, NodeArray& x);

private:
  /// Where a block's nine entries are stored: the storage index of its first row in each of its three
  /// columns (the rows of a block are consecutive within a column), and whether it is stored transposed
  /// (it lies below the diagonal in the permuted order, and only the upper triangle is kept).
  struct BlockSlot
  {
    std::array<int, 3> column_start;
    bool transposed;
  };

  /// The storage index of entry (row, column) of the upper triangle.
  int entryIndex(int row, int column) const;

  /// Eigen's SimplicialLDLT on a matrix already in its order (the upper triangle, natural ordering),
  /// factorised without the copy (and the allocation) that its factorize() makes of it.
  class Ldlt : public Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Upper, Eigen::NaturalOrdering<int>>
  {
  public:
    void factorizeInPlace(const Eigen::SparseMatrix<double>& upper) { factorize_preordered<true>(upper); }
    /// The smallest pivot of D (vectorD() would copy it).
    double smallestPivot() const
    {
      return m_diag.size() > 0 ? m_diag.minCoeff() : std::numeric_limits<double>::infinity();
    }
  };

  double work_ = 0.0;
  double entries_ = 0.0;
  std::vector<int> position_;           ///< per node: its block row in the permuted order
  std::vector<BlockSlot> diagonal_;     ///< per node
  std::vector<BlockSlot> off_diagonal_;  ///< per slot
  Eigen::SparseMatrix<double> upper_;   ///< the upper triangle of A in the permuted order
  Ldlt factor_;
  Eigen::VectorXd permuted_rhs_;
  Eigen::VectorXd permuted_x_;
};

}  // namespace soft_body_sim
