#include "core/solvers/aggregation_multigrid.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace soft_body_sim
{
void AggregationMultigrid::analyze(int nodes, const std::vector<std::pair<int, int>>& pairs)
{
  const std::size_t n = static_cast<std::size_t>(nodes);
  // Each node's distinct neighbours, and itself, in ascending order: the fine matrix's rows.
  std::vector<std::vector<int>> neighbours(n);
  for (std::size_t i = 0; i < n; ++i)
    neighbours[i].push_back(static_cast<int>(i));
  for (const auto& [a, b] : pairs)
  {
    if (a == b || a < 0 || b < 0 || a >= nodes || b >= nodes)
      throw std::invalid_argument("AggregationMultigrid: a pair must join two different nodes in range");
    neighbours[static_cast<std::size_t>(a)].push_back(b);
    neighbours[static_cast<std::size_t>(b)].push_back(a);
  }
  levels_.assign(1, Level());
  BlockRows& a = levels_.front().a;
  std::vector<std::size_t>& diagonal = levels_.front().diagonal;
  a.clear(nodes);
  diagonal.resize(n);
  for (std::size_t i = 0; i < n; ++i)
  {
    std::vector<int>& row = neighbours[i];
    std::sort(row.begin(), row.end());
    row.erase(std::unique(row.begin(), row.end()), row.end());
    const std::size_t first = a.column.size();
    a.column.insert(a.column.end(), row.begin(), row.end());
    a.start.push_back(a.column.size());
    diagonal[i] = first + static_cast<std::size_t>(std::lower_bound(row.begin(), row.end(), static_cast<int>(i)) - row.begin());
  }
  a.block.assign(a.column.size(), Matrix3::Zero());
  const auto position = [&](int row, int column) {
    const auto begin = a.column.begin() + static_cast<std::ptrdiff_t>(a.start[static_cast<std::size_t>(row)]);
    const auto end = a.column.begin() + static_cast<std::ptrdiff_t>(a.start[static_cast<std::size_t>(row) + 1]);
    return static_cast<std::size_t>(std::lower_bound(begin, end, column) - a.column.begin());
  };
  slot_position_.resize(pairs.size());
  for (std::size_t k = 0; k < pairs.size(); ++k)
    slot_position_[k] = { position(pairs[k].first, pairs[k].second), position(pairs[k].second, pairs[k].first) };
  level_count_ = 0;
}

void AggregationMultigrid::release()
{
  std::vector<std::pair<std::size_t, std::size_t>>().swap(slot_position_);
  std::vector<Level>().swap(levels_);
  level_count_ = 0;
  coarsest_.resize(0, 0);
  coarsest_factor_.compute(coarsest_);
  coarsest_rhs_.resize(0);
  std::vector<std::ptrdiff_t>().swap(mark_);
  std::vector<int>().swap(roots_took_);
  std::vector<double>().swap(diagonal_norm_);
  std::vector<std::size_t>().swap(next_);
}

void AggregationMultigrid::start(const std::vector<Matrix3>& diagonal)
{
  Level& fine = levels_.front();
  std::fill(fine.a.block.begin(), fine.a.block.end(), Matrix3::Zero());
  for (std::size_t i = 0; i < fine.diagonal.size(); ++i)
    fine.a.block[fine.diagonal[i]] = diagonal[i];
}

bool AggregationMultigrid::setup()
{
  level_count_ = 0;
  double threshold = kStrengthThreshold;
  for (std::size_t l = 0;; ++l)
  {
    if (levels_.size() < l + 2)
      levels_.resize(l + 2);
    Level& level = levels_[l];
    ++level_count_;
    if (!makeSmoother(level))
      return false;
    const int n = level.a.rows();
    level.x.resize(3, n);
    level.b.resize(3, n);
    level.residual.resize(3, n);
    if (n <= kDenseNodes || l + 1 == kMostLevels)
      break;
    const int aggregates = aggregate(level, threshold);
    if (aggregates == 0 || aggregates > kLeastCoarsening * n)
      break;
    makeProlongation(level, aggregates);
    Level& next = levels_[l + 1];
    multiply(level.a, level.prolongation, level.product, mark_);
    multiply(level.restriction, level.product, next.a, mark_);
    if (!findDiagonals(next))
      return false;
    threshold *= 0.5;
  }
  return factorCoarsest();
}

bool AggregationMultigrid::makeSmoother(Level& level)
{
  const BlockRows& a = level.a;
  const std::size_t n = static_cast<std::size_t>(a.rows());
  level.smoother.resize(n);
  double norm = 0.0;  // |D^-1 A|_inf, which bounds D^-1 A's spectral radius
  for (std::size_t i = 0; i < n; ++i)
  {
    const Eigen::LLT<Matrix3> factor(a.block[level.diagonal[i]]);
    if (factor.info() != Eigen::Success)
      return false;
    Matrix3 inverse = factor.solve(Matrix3::Identity());
    inverse = (0.5 * (inverse + inverse.transpose())).eval();
    if (!inverse.allFinite())
      return false;
    Eigen::Vector3d row_sums = Eigen::Vector3d::Zero();
    for (std::size_t k = a.start[i]; k < a.start[i + 1]; ++k)
      row_sums += (inverse * a.block[k]).cwiseAbs().rowwise().sum();
    norm = std::max(norm, row_sums.maxCoeff());
    level.smoother[i] = inverse;
  }
  if (!(norm > 0.0 && std::isfinite(norm)))
    return n == 0;
  level.damping = 4.0 / (3.0 * norm);
  for (Matrix3& s : level.smoother)
    s *= level.damping;
  return true;
}

int AggregationMultigrid::aggregate(Level& level, double strength_threshold)
{
  const BlockRows& a = level.a;
  const int n = a.rows();
  std::vector<int>& aggregate = level.aggregate;
  aggregate.assign(static_cast<std::size_t>(n), -1);
  const double threshold2 = strength_threshold * strength_threshold;
  std::vector<double>& diagonal_norm = diagonal_norm_;
  diagonal_norm.resize(static_cast<std::size_t>(n));
  for (std::size_t i = 0; i < diagonal_norm.size(); ++i)
    diagonal_norm[i] = a.block[level.diagonal[i]].norm();
  // Entry k of row i couples strongly: |A_ij|^2 >= threshold^2 |A_ii| |A_jj|.
  const auto strong = [&](int i, std::size_t k) {
    const int j = a.column[k];
    return j != i && a.block[k].squaredNorm() >=
                         threshold2 * diagonal_norm[static_cast<std::size_t>(i)] * diagonal_norm[static_cast<std::size_t>(j)];
  };
  int count = 0;
  // Roots: a node whose strong neighbours are all free takes them into a new aggregate. A node with no
  // strong neighbour is left out (its row of P0 is zero: the smoothing alone serves it).
  for (int i = 0; i < n; ++i)
  {
    if (aggregate[static_cast<std::size_t>(i)] >= 0)
      continue;
    bool free = true;
    bool any = false;
    for (std::size_t k = a.start[static_cast<std::size_t>(i)]; k < a.start[static_cast<std::size_t>(i) + 1]; ++k)
      if (strong(i, k))
      {
        any = true;
        free = free && aggregate[static_cast<std::size_t>(a.column[k])] < 0;
      }
    if (!any || !free)
      continue;
    aggregate[static_cast<std::size_t>(i)] = count;
    for (std::size_t k = a.start[static_cast<std::size_t>(i)]; k < a.start[static_cast<std::size_t>(i) + 1]; ++k)
      if (strong(i, k))
        aggregate[static_cast<std::size_t>(a.column[k])] = count;
    ++count;
  }
  // The nodes left with a strong neighbour join the aggregate of the most strongly coupled one that the
  // roots took (every such node has one: else it would have been a root).
  std::vector<int>& roots_took = roots_took_;
  roots_took = aggregate;
  for (int i = 0; i < n; ++i)
  {
    if (roots_took[static_cast<std::size_t>(i)] >= 0)
      continue;
    double strongest = -1.0;
    for (std::size_t k = a.start[static_cast<std::size_t>(i)]; k < a.start[static_cast<std::size_t>(i) + 1]; ++k)
    {
      const int j = a.column[k];
      if (roots_took[static_cast<std::size_t>(j)] >= 0 && strong(i, k) && a.block[k].squaredNorm() > strongest)
      {
        strongest = a.block[k].squaredNorm();
        aggregate[static_cast<std::size_t>(i)] = roots_took[static_cast<std::size_t>(j)];
      }
    }
  }
  return count;
}

void AggregationMultigrid::makeProlongation(Level& level, int aggregates)
{
  const BlockRows& a = level.a;
  const std::size_t n = static_cast<std::size_t>(a.rows());
  BlockRows& p = level.prolongation;
  p.clear(aggregates);
  mark_.assign(static_cast<std::size_t>(aggregates), -1);
  for (std::size_t i = 0; i < n; ++i)
  {
    const std::ptrdiff_t row_start = static_cast<std::ptrdiff_t>(p.block.size());
    if (level.aggregate[i] >= 0)
      p.rowEntry(level.aggregate[i], row_start, mark_) += Matrix3::Identity();
    // - w D_i^-1 A_ij for each neighbour j in an aggregate (j = i included: -w I)
    for (std::size_t k = a.start[i]; k < a.start[i + 1]; ++k)
    {
      const int j = level.aggregate[static_cast<std::size_t>(a.column[k])];
      if (j >= 0)
        p.rowEntry(j, row_start, mark_) -= level.smoother[i] * a.block[k];
    }
    p.start.push_back(p.block.size());
  }
  transpose(p, level.restriction, next_);
}

bool AggregationMultigrid::findDiagonals(Level& level)
{
  const BlockRows& a = level.a;
  const std::size_t n = static_cast<std::size_t>(a.rows());
  level.diagonal.resize(n);
  for (std::size_t i = 0; i < n; ++i)
  {
    const auto begin = a.column.begin() + static_cast<std::ptrdiff_t>(a.start[i]);
    const auto end = a.column.begin() + static_cast<std::ptrdiff_t>(a.start[i + 1]);
    const auto at = std::find(begin, end, static_cast<int>(i));
    if (at == end)
      return false;
    level.diagonal[i] = static_cast<std::size_t>(at - a.column.begin());
  }
  return true;
}

bool AggregationMultigrid::factorCoarsest()
{
  const BlockRows& a = levels_[level_count_ - 1].a;
  const int n = a.rows();
  coarsest_dense_ = n <= kDenseNodes;
  if (!coarsest_dense_)
    return true;
  coarsest_.setZero(3 * n, 3 * n);
  for (int i = 0; i < n; ++i)
    for (std::size_t k = a.start[static_cast<std::size_t>(i)]; k < a.start[static_cast<std::size_t>(i) + 1]; ++k)
      coarsest_.block<3, 3>(3 * i, 3 * a.column[k]) = a.block[k];
  coarsest_factor_.compute(coarsest_);
  return coarsest_factor_.info() == Eigen::Success;
}

void AggregationMultigrid::apply(const NodeArray& r, NodeArray& z, const FineProduct& fine)
{
  levels_.front().b = r;
  cycle(0, fine);
  z = levels_.front().x;
}

void AggregationMultigrid::cycle(std::size_t l, const FineProduct& fine)
{
  Level& level = levels_[l];
  const Eigen::Index n = level.b.cols();
  if (l + 1 == level_count_ && coarsest_dense_)
  {
    coarsest_rhs_ = Eigen::Map<const Eigen::VectorXd>(level.b.data(), 3 * n);
    Eigen::Map<Eigen::VectorXd>(level.x.data(), 3 * n) = coarsest_factor_.solve(coarsest_rhs_);
    return;
  }
  for (Eigen::Index i = 0; i < n; ++i)
    level.x.col(i) = level.smoother[static_cast<std::size_t>(i)] * level.b.col(i);
  if (l + 1 == level_count_)
    return;  // a level that hardly coarsens, smoothed only
  Level& next = levels_[l + 1];
  const auto product = [&](const NodeArray& x, NodeArray& out) {
    if (l == 0)
      fine(x, out);
    else
      multiply(level.a, x, out);
  };
  product(level.x, level.residual);
  level.residual = level.b - level.residual;
  multiply(level.restriction, level.residual, next.b);
  cycle(l + 1, fine);
  multiply(level.prolongation, next.x, level.residual);
  level.x += level.residual;
  product(level.x, level.residual);
  level.residual = level.b - level.residual;
  for (Eigen::Index i = 0; i < n; ++i)
    level.x.col(i) += level.smoother[static_cast<std::size_t>(i)] * level.residual.col(i);
}

void AggregationMultigrid::multiply(const BlockRows& a, const NodeArray& x, NodeArray& out)
{
  const std::size_t rows = static_cast<std::size_t>(a.rows());
  out.resize(3, static_cast<Eigen::Index>(rows));
  for (std::size_t i = 0; i < rows; ++i)
  {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (std::size_t k = a.start[i]; k < a.start[i + 1]; ++k)
      sum.noalias() += a.block[k] * x.col(a.column[k]);
    out.col(static_cast<Eigen::Index>(i)) = sum;
  }
}

void AggregationMultigrid::multiply(const BlockRows& a, const BlockRows& b, BlockRows& out,
                                    std::vector<std::ptrdiff_t>& mark)
{
  out.clear(b.columns);
  mark.assign(static_cast<std::size_t>(b.columns), -1);
  const std::size_t rows = static_cast<std::size_t>(a.rows());
  for (std::size_t i = 0; i < rows; ++i)
  {
    const std::ptrdiff_t row_start = static_cast<std::ptrdiff_t>(out.block.size());
    for (std::size_t k = a.start[i]; k < a.start[i + 1]; ++k)
    {
      const std::size_t middle = static_cast<std::size_t>(a.column[k]);
      for (std::size_t m = b.start[middle]; m < b.start[middle + 1]; ++m)
        out.rowEntry(b.column[m], row_start, mark).noalias() += a.block[k] * b.block[m];
    }
    out.start.push_back(out.block.size());
  }
}

void AggregationMultigrid::transpose(const BlockRows& a, BlockRows& out, std::vector<std::size_t>& next)
{
  const std::size_t rows = static_cast<std::size_t>(a.rows());
  const std::size_t columns = static_cast<std::size_t>(a.columns);
  out.clear(a.rows());
  out.start.assign(columns + 1, 0);
  for (const int c : a.column)
    ++out.start[static_cast<std::size_t>(c) + 1];
  for (std::size_t c = 0; c < columns; ++c)
    out.start[c + 1] += out.start[c];
  out.column.resize(a.column.size());
  out.block.resize(a.block.size());
  next.assign(out.start.begin(), out.start.end() - 1);
  for (std::size_t i = 0; i < rows; ++i)
    for (std::size_t k = a.start[i]; k < a.start[i + 1]; ++k)
    {
      const std::size_t at = next[static_cast<std::size_t>(a.column[k])]++;
      out.column[at] = static_cast<int>(i);
      out.block[at] = a.block[k].transpose();
    }
}

}  // namespace soft_body_sim
