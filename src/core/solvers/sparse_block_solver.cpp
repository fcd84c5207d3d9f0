#include "core/solvers/sparse_block_solver.h"

#include <algorithm>
#include <stdexcept>

#include <Eigen/OrderingMethods>

namespace soft_body_sim
{
namespace
{
/// Multiply-adds of factorising a matrix of 3x3 blocks whose block column j of L holds `below[j]` blocks
/// under the diagonal: its three scalar columns hold 3 below[j] + 2, + 1, + 0 entries under the diagonal,
/// and a column of c entries costs about (c + 1)^2.
double blockFactorWork(const std::vector<int>& below)
{
  double work = 0.0;
  for (const int c : below)
    for (int r = 0; r < 3; ++r)
    {
      const double entries = 3.0 * c + (2 - r) + 1;
      work += entries * entries;
    }
  return work;
}
}  // namespace

bool SparseBlockSolver::analyze(int nodes, const std::vector<std::pair<int, int>>& pairs, double max_work_per_entry)
{
  // The fill-reducing order of the nodes, from the node graph (A + A^T's pattern, as AMD wants it).
  std::vector<Eigen::Triplet<double, int>> graph;
  graph.reserve(static_cast<std::size_t>(nodes) + 2 * pairs.size());
  for (int i = 0; i < nodes; ++i)
    graph.emplace_back(i, i, 1.0);
  for (const auto& [a, b] : pairs)
  {
    if (a == b || a < 0 || b < 0 || a >= nodes || b >= nodes)
      throw std::invalid_argument("SparseBlockSolver: a pair must join two different nodes in range");
    graph.emplace_back(a, b, 1.0);
    graph.emplace_back(b, a, 1.0);
  }
  Eigen::SparseMatrix<double, Eigen::ColMajor, int> node_graph(nodes, nodes);
  node_graph.setFromTriplets(graph.begin(), graph.end());
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> inverse_order;
  Eigen::AMDOrdering<int> amd;
  amd(node_graph, inverse_order);
  // AMD gives P^-1: node i goes to block row P(i).
  const Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> order = inverse_order.inverse();
  position_.resize(static_cast<std::size_t>(nodes));
  for (int i = 0; i < nodes; ++i)
    position_[static_cast<std::size_t>(i)] = order.indices()[i];

  // The cost of the factorisation before any of it is allocated: in the new order, the elimination tree
  // and how many blocks each column of L holds. Row k of L is reached from each neighbour i < k of k by
  // climbing the tree until a node already marked for row k; every node passed gets an entry in row k.
  {
    std::vector<std::vector<int>> lower(static_cast<std::size_t>(nodes));  // per new index: neighbours before it
    for (const auto& [a, b] : pairs)
    {
      const int pa = position_[static_cast<std::size_t>(a)], pb = position_[static_cast<std::size_t>(b)];
      lower[static_cast<std::size_t>(std::max(pa, pb))].push_back(std::min(pa, pb));
    }
    std::vector<int> parent(static_cast<std::size_t>(nodes), -1), mark(static_cast<std::size_t>(nodes), -1),
        below(static_cast<std::size_t>(nodes), 0);
    for (int k = 0; k < nodes; ++k)
    {
      mark[static_cast<std::size_t>(k)] = k;
      for (int j : lower[static_cast<std::size_t>(k)])
        while (mark[static_cast<std::size_t>(j)] != k)
        {
          if (parent[static_cast<std::size_t>(j)] < 0)
            parent[static_cast<std::size_t>(j)] = k;
          ++below[static_cast<std::size_t>(j)];
          mark[static_cast<std::size_t>(j)] = k;
          j = parent[static_cast<std::size_t>(j)];
        }
    }
    work_ = blockFactorWork(below);
    entries_ = 9.0 * (nodes + 2.0 * static_cast<double>(pairs.size()));
  }
  if (work_ > max_work_per_entry * entries_)
  {
    upper_.resize(0, 0);
    upper_.data().squeeze();
    return false;
  }

  // The upper triangle's pattern in that order: each diagonal block's upper part, each pair's block.
  std::vector<Eigen::Triplet<double, int>> entries;
  entries.reserve(6 * static_cast<std::size_t>(nodes) + 9 * pairs.size());
  for (int i = 0; i < nodes; ++i)
  {
    const int p = 3 * position_[static_cast<std::size_t>(i)];
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r <= c; ++r)
        entries.emplace_back(p + r, p + c, 0.0);
  }
  for (const auto& [a, b] : pairs)
  {
    const int pa = 3 * position_[static_cast<std::size_t>(a)], pb = 3 * position_[static_cast<std::size_t>(b)];
    const int row = std::min(pa, pb), column = std::max(pa, pb);
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r)
        entries.emplace_back(row + r, column + c, 0.0);
  }
  upper_.resize(3 * nodes, 3 * nodes);
  upper_.setFromTriplets(entries.begin(), entries.end());  // repeated pairs merge into one block
  upper_.makeCompressed();

  diagonal_.resize(static_cast<std::size_t>(nodes));
  for (int i = 0; i < nodes; ++i)
  {
    const int p = 3 * position_[static_cast<std::size_t>(i)];
    diagonal_[static_cast<std::size_t>(i)] = { { entryIndex(p, p), entryIndex(p, p + 1), entryIndex(p, p + 2) }, false };
  }
  off_diagonal_.resize(pairs.size());
  for (std::size_t k = 0; k < pairs.size(); ++k)
  {
    const int pa = 3 * position_[static_cast<std::size_t>(pairs[k].first)];
    const int pb = 3 * position_[static_cast<std::size_t>(pairs[k].second)];
    const int row = std::min(pa, pb), column = std::max(pa, pb);
    off_diagonal_[k] = { { entryIndex(row, column), entryIndex(row, column + 1), entryIndex(row, column + 2) }, pa > pb };
  }
  factor_.analyzePattern(upper_);
  permuted_rhs_.resize(3 * nodes);
  permuted_x_.resize(3 * nodes);
  return true;
}

SparseBlockSolver::SparseBlockSolver(const SparseBlockSolver& other) { *this = other; }

SparseBlockSolver& SparseBlockSolver::operator=(const SparseBlockSolver& other)
{
  if (this == &other)
    return *this;
  work_ = other.work_;
  entries_ = other.entries_;
  position_ = other.position_;
  diagonal_ = other.diagonal_;
  off_diagonal_ = other.off_diagonal_;
  upper_ = other.upper_;
  permuted_rhs_ = other.permuted_rhs_;
  permuted_x_ = other.permuted_x_;
  if (upper_.rows() > 0)
    factor_.analyzePattern(upper_);
  return *this;
}

int SparseBlockSolver::entryIndex(int row, int column) const
{
  const int* rows = upper_.innerIndexPtr();
  const int begin = upper_.outerIndexPtr()[column], end = upper_.outerIndexPtr()[column + 1];
  const int* found = std::lower_bound(rows + begin, rows + end, row);
  if (found == rows + end || *found != row)
    throw std::logic_error("SparseBlockSolver: an entry is missing from the pattern");
  return static_cast<int>(found - rows);
}

void SparseBlockSolver::start(const std::vector<Matrix3>& diagonal)
{
  std::fill_n(upper_.valuePtr(), upper_.nonZeros(), 0.0);
  for (std::size_t i = 0; i < diagonal.size(); ++i)
    addDiagonal(static_cast<int>(i), diagonal[i]);
}

void SparseBlockSolver::addDiagonal(int i, const Matrix3& block)
{
  double* values = upper_.valuePtr();
  const BlockSlot& slot = diagonal_[static_cast<std::size_t>(i)];
  // Column c holds rows 0..c of the block.
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r <= c; ++r)
      values[slot.column_start[static_cast<std::size_t>(c)] + r] += block(r, c);
}

void SparseBlockSolver::addOffDiagonal(std::size_t slot_index, const Matrix3& block)
{
  double* values = upper_.valuePtr();
  const BlockSlot& slot = off_diagonal_[slot_index];
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r)
      values[slot.column_start[static_cast<std::size_t>(c)] + r] += slot.transposed ? block(c, r) : block(r, c);
}

bool SparseBlockSolver::factorize()
{
  factor_.factorizeInPlace(upper_);
  // LDL^T also factorises indefinite matrices: positive definite means every pivot of D > 0.
  return factor_.info() == Eigen::Success && factor_.smallestPivot() > 0.0;
}

void SparseBlockSolver::solve(const NodeArray& rhs, NodeArray& x)
{
  const Eigen::Index nodes = rhs.cols();
  for (Eigen::Index i = 0; i < nodes; ++i)
    permuted_rhs_.segment<3>(3 * position_[static_cast<std::size_t>(i)]) = rhs.col(i);
  permuted_x_ = factor_.solve(permuted_rhs_);
  x.resize(3, nodes);
  for (Eigen::Index i = 0; i < nodes; ++i)
    x.col(i) = permuted_x_.segment<3>(3 * position_[static_cast<std::size_t>(i)]);
}

}  // namespace soft_body_sim
