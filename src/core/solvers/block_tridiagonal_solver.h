// A direct solve of a symmetric positive definite system of 3x3 blocks whose nodes form chains (private
// to the core library): implicit Euler's Newton system on ropes.
#pragma once

#include <array>
#include <utility>
#include <vector>

#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
/// A = sum of 3x3 blocks over node pairs that form paths (every node coupled to at most two others, no
/// cycle), solved along each path by block Gaussian elimination from both ends towards its middle m (a
/// twisted factorisation). With B_k = A_{k,k+1} in path order:
///   from the first node:  S_k = A_kk - B_{k-1}^T G_{k-1},  G_k = S_k^-1 B_k,          k < m
///   from the last node:   S_k = A_kk - B_k H_{k+1},        H_k = S_k^-1 B_{k-1}^T,    k > m
///   at the middle:        S_m = A_mm - B_{m-1}^T G_{m-1} - B_m H_{m+1}
///   forward   z_k = r_k - G_{k-1}^T z_{k-1} (k < m),  z_k = r_k - H_{k+1}^T z_{k+1} (k > m),  both at m,
///   back      x_m = S_m^-1 z_m,  x_k = S_k^-1 z_k - G_k x_{k+1} (k < m),  S_k^-1 z_k - H_k x_{k-1} (k > m).
/// In path order a chain's matrix is block tridiagonal and the factor has no fill: about 100
/// multiply-adds per node in fixed-size arrays, where a general sparse LDL^T (SparseBlockSolver) does the
/// same arithmetic through index arrays, several times slower. Each recursion is sequential, so its
/// speed is the latency of one node's work. So the two halves are independent and interleaved, and the
/// processor overlaps them, and each S_k is inverted by its cofactors, one division where a 3x3 Cholesky
/// has three square roots and three divisions in a row. Measured on implicit Euler's whole step of a
/// 1000-node rope (bench_step StiffRope): 159 us with Cholesky pivots, 121 us with cofactors, 104 -> 91 us
/// from one sweep to two interleaved ones. The error is that of the blocks' condition, as a Cholesky's
/// would be; every S_k is SPD for an SPD A.
/// Same interface as SparseBlockSolver: the pattern analysed once per model change, values written per
/// Newton iteration, no allocation after analyze.
class BlockTridiagonalSolver
{
public:
  using Matrix3 = Eigen::Matrix3d;

  /// The pattern of a system over `nodes` nodes whose off-diagonal blocks may be non-zero for the node
  /// pairs `pairs` (i != j; a pair may repeat). Slot k of addOffDiagonal is pairs[k]. True if the pairs
  /// form paths (then everything is prepared); false if a node is coupled to three or more others or
  /// the pairs close a cycle (nothing is kept: solve otherwise).
  bool analyze(int nodes, const std::vector<std::pair<int, int>>& pairs) { return analyzePaths(nodes, pairs, false); }
  /// The chains among a pattern that is not all chains: its components (nodes joined through pairs) that are
  /// paths of two nodes or more, each solved as analyze's; the other nodes and their pairs are left out
  /// (addDiagonal and addOffDiagonal pass them over, solve leaves their columns of x as they were). True if
  /// there is such a chain (implicit Euler's preconditioner in a scene of ropes and cloths, BlockSystem).
  bool analyzeChains(int nodes, const std::vector<std::pair<int, int>>& pairs)
  {
    return analyzePaths(nodes, pairs, true) && !paths_.empty();
  }
  /// True if node i lies on one of the analysed paths.
  bool onPath(int i) const { return position_[static_cast<std::size_t>(i)] >= 0; }

  /// Starts a new matrix (same pattern): A's diagonal block of node i = diagonal[i], every other block 0.
  void start(const std::vector<Matrix3>& diagonal);
  /// A's diagonal block of node i += block (symmetric).
  void addDiagonal(int i, const Matrix3& block)
  {
    const int place = position_[static_cast<std::size_t>(i)];
    if (place >= 0)
      diagonal_[static_cast<std::size_t>(place)] += block;
  }
  /// A's block (a, b) += block, and (b, a) += block^T, for the pair (a, b) of slot `slot`.
  void addOffDiagonal(std::size_t slot, const Matrix3& block)
  {
    const Slot& s = slot_[slot];
    if (s.link < 0)
      return;  // a pair off the paths (analyzeChains)
    if (s.transposed)
      upper_[static_cast<std::size_t>(s.link)] += block.transpose();
    else
      upper_[static_cast<std::size_t>(s.link)] += block;
  }

  /// Factorises A; false if it is not positive definite to working precision.
  bool factorize();
  /// x = A^-1 rhs (3 x nodes), after a successful factorize: the columns of the nodes on the paths.
  void solve(const NodeArray& rhs, NodeArray& x);

private:
  /// Where a slot's block goes: the link between path positions `link` and link + 1, stored as
  /// A(order[link], order[link + 1]); transposed when the pair names them the other way round; link -1 for
  /// a pair off the paths.
  struct Slot
  {
    int link;
    bool transposed;
  };

  /// analyze (every node on a path, else false) or, with `chains_only`, analyzeChains.
  bool analyzePaths(int nodes, const std::vector<std::pair<int, int>>& pairs, bool chains_only);

  /// A path's places [begin, end) and its middle.
  struct Path
  {
    std::size_t begin, middle, end;
  };

  /// S_k^-1 at place k of `path`, and G_k before its middle, H_k after it, from the pivots next to it
  /// on the side of the middle (both at the middle); false if S_k is not SPD.
  bool pivot(std::size_t k, const Path& path);

  std::vector<int> position_;      ///< per node: its place in the paths' order, -1 off them
  std::vector<int> order_;         ///< per place: the node
  std::vector<Path> paths_;
  std::vector<Slot> slot_;
  std::vector<Matrix3> diagonal_;  ///< per place: A's diagonal block
  std::vector<Matrix3> upper_;     ///< per place k: A(order[k], order[k + 1]) (zero at a path's last place)
  std::vector<Matrix3> inverse_;   ///< per place: S_k^-1
  std::vector<Matrix3> gain_;      ///< per place: G_k before the path's middle, H_k after it
  NodeArray z_;                    ///< the forward sweep's z, per place
};

}  // namespace soft_body_sim
