#include "core/solvers/block_tridiagonal_solver.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace soft_body_sim
{
namespace
{
/// A pivot of a Cholesky factorisation: positive and finite (a NaN fails too).
bool usablePivot(double d) { return d > 0.0 && d < std::numeric_limits<double>::infinity(); }

/// The lower triangle of s -= a^T g, the only part of the symmetric S that is read: (a^T g)_rc =
/// a.col(r) . g.col(c), c <= r.
template <class Left>
void subtractLowerProduct(const Left& a, const Eigen::Matrix3d& g, Eigen::Matrix3d& s)
{
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c <= r; ++c)
      s(r, c) -= a.col(r).dot(g.col(c));
}

/// S^-1 of a symmetric 3x3 S by its cofactors, into `inverse`; false unless S is positive definite (its
/// leading minors positive, Sylvester) and the inverse finite. Inline: it is on the factorisation's
/// sequential path.
inline bool invertPositiveDefinite(const Eigen::Matrix3d& s, Eigen::Matrix3d& inverse)
{
  // The cofactors of the lower triangle (S is symmetric; only that triangle is read).
  const double c00 = s(1, 1) * s(2, 2) - s(2, 1) * s(2, 1);
  const double c10 = s(2, 1) * s(2, 0) - s(1, 0) * s(2, 2);
  const double c20 = s(1, 0) * s(2, 1) - s(1, 1) * s(2, 0);
  const double c11 = s(0, 0) * s(2, 2) - s(2, 0) * s(2, 0);
  const double c21 = s(1, 0) * s(2, 0) - s(0, 0) * s(2, 1);
  const double c22 = s(0, 0) * s(1, 1) - s(1, 0) * s(1, 0);
  const double determinant = s(0, 0) * c00 + s(1, 0) * c10 + s(2, 0) * c20;
  if (!(usablePivot(s(0, 0)) && usablePivot(c22) && usablePivot(determinant)))
    return false;
  const double r = 1.0 / determinant;
  inverse << c00 * r, c10 * r, c20 * r,  //
      c10 * r, c11 * r, c21 * r,         //
      c20 * r, c21 * r, c22 * r;
  return std::isfinite(r);
}
}  // namespace

bool BlockTridiagonalSolver::analyzePaths(int nodes, const std::vector<std::pair<int, int>>& pairs, bool chains_only)
{
  const std::size_t n = static_cast<std::size_t>(nodes);
  // Each node's distinct neighbours (at most two on a path); a node with a third is a branch.
  std::vector<std::array<int, 2>> neighbours(n, { -1, -1 });
  std::vector<char> branch(n, 0);
  for (const auto& [a, b] : pairs)
  {
    if (a == b || a < 0 || b < 0 || a >= nodes || b >= nodes)
      throw std::invalid_argument("BlockTridiagonalSolver: a pair must join two different nodes in range");
    for (const auto& [from, to] : { std::pair<int, int>{ a, b }, std::pair<int, int>{ b, a } })
    {
      std::array<int, 2>& near = neighbours[static_cast<std::size_t>(from)];
      if (near[0] == to || near[1] == to)
        continue;  // the same pair again: its blocks add up in one place
      if (near[1] >= 0)
      {
        if (!chains_only)
          return false;
        branch[static_cast<std::size_t>(from)] = 1;
        continue;
      }
      near[near[0] < 0 ? 0 : 1] = to;
    }
  }
  // Walk each path from one of its ends; nodes left over lie on cycles. With chains_only, a walk that meets
  // a branch is undone (its component is no path: every node before the branch has its neighbours on the
  // walk, so a walk that ends without meeting one has gone through its whole component), and so is a lone
  // node (its diagonal block alone: the caller's).
  position_.assign(n, -1);
  order_.clear();
  order_.reserve(n);
  paths_.clear();
  for (std::size_t start = 0; start < n; ++start)
  {
    if (position_[start] >= 0 || neighbours[start][1] >= 0 || branch[start] != 0)
      continue;
    const std::size_t begin = order_.size();
    bool path = true;
    int previous = -1;
    for (int node = static_cast<int>(start); node >= 0;)
    {
      if (branch[static_cast<std::size_t>(node)] != 0)
      {
        path = false;
        break;
      }
      position_[static_cast<std::size_t>(node)] = static_cast<int>(order_.size());
      order_.push_back(node);
      const std::array<int, 2>& near = neighbours[static_cast<std::size_t>(node)];
      const int next = near[0] != previous ? near[0] : near[1];
      previous = node;
      node = next;
    }
    if (chains_only && (!path || order_.size() - begin < 2))
    {
      for (std::size_t k = begin; k < order_.size(); ++k)
        position_[static_cast<std::size_t>(order_[k])] = -1;
      order_.resize(begin);
      continue;
    }
    paths_.push_back(Path{ begin, begin + (order_.size() - begin) / 2, order_.size() });
  }
  if (!chains_only && order_.size() != n)
    return false;
  slot_.clear();
  slot_.reserve(pairs.size());
  for (const auto& [a, b] : pairs)
  {
    const int pa = position_[static_cast<std::size_t>(a)], pb = position_[static_cast<std::size_t>(b)];
    slot_.push_back(pa < 0 ? Slot{ -1, false } : Slot{ std::min(pa, pb), pa > pb });
  }
  const std::size_t places = order_.size();
  diagonal_.resize(places);
  upper_.resize(places);
  inverse_.resize(places);
  gain_.resize(places);
  z_.resize(3, static_cast<Eigen::Index>(places));
  return true;
}

void BlockTridiagonalSolver::start(const std::vector<Matrix3>& diagonal)
{
  for (std::size_t k = 0; k < order_.size(); ++k)
  {
    diagonal_[k] = diagonal[static_cast<std::size_t>(order_[k])];
    upper_[k].setZero();
  }
}

bool BlockTridiagonalSolver::pivot(std::size_t k, const Path& path)
{
  Matrix3 s = diagonal_[k];
  if (k <= path.middle && k > path.begin)
    subtractLowerProduct(upper_[k - 1], gain_[k - 1], s);  // B_{k-1}^T G_{k-1}
  if (k >= path.middle && k + 1 < path.end)
    subtractLowerProduct(upper_[k].transpose(), gain_[k + 1], s);  // B_k H_{k+1}
  if (!invertPositiveDefinite(s, inverse_[k]))
    return false;
  if (k < path.middle)
    gain_[k].noalias() = inverse_[k] * upper_[k];
  else if (k > path.middle)
    gain_[k].noalias() = inverse_[k] * upper_[k - 1].transpose();
  return true;
}

bool BlockTridiagonalSolver::factorize()
{
  for (const Path& path : paths_)
  {
    // The two halves in one loop, so that their independent recursions overlap.
    const std::size_t steps = std::max(path.middle - path.begin, path.end - 1 - path.middle);
    for (std::size_t i = 0; i < steps; ++i)
    {
      if (path.begin + i < path.middle && !pivot(path.begin + i, path))
        return false;
      if (path.end - 1 - i > path.middle && !pivot(path.end - 1 - i, path))
        return false;
    }
    if (!pivot(path.middle, path))
      return false;
  }
  return true;
}

void BlockTridiagonalSolver::solve(const NodeArray& rhs, NodeArray& x)
{
  x.resize(3, rhs.cols());
  const auto z = [this](std::size_t k) { return z_.col(static_cast<Eigen::Index>(k)); };
  for (const Path& path : paths_)
  {
    const std::size_t m = path.middle;
    const std::size_t steps = std::max(m - path.begin, path.end - 1 - m);
    for (std::size_t i = 0; i < steps; ++i)
    {
      const std::size_t first = path.begin + i, last = path.end - 1 - i;
      if (first < m)
      {
        z(first) = rhs.col(order_[first]);
        if (first > path.begin)
          z(first).noalias() -= gain_[first - 1].transpose() * z(first - 1);
      }
      if (last > m)
      {
        z(last) = rhs.col(order_[last]);
        if (last + 1 < path.end)
          z(last).noalias() -= gain_[last + 1].transpose() * z(last + 1);
      }
    }
    z(m) = rhs.col(order_[m]);
    if (m > path.begin)
      z(m).noalias() -= gain_[m - 1].transpose() * z(m - 1);
    if (m + 1 < path.end)
      z(m).noalias() -= gain_[m + 1].transpose() * z(m + 1);
    x.col(order_[m]).noalias() = inverse_[m] * z(m);
    for (std::size_t i = 1; i <= steps; ++i)
    {
      if (m >= path.begin + i)
      {
        const std::size_t k = m - i;
        x.col(order_[k]).noalias() = inverse_[k] * z(k) - gain_[k] * x.col(order_[k + 1]);
      }
      if (m + i < path.end)
      {
        const std::size_t k = m + i;
        x.col(order_[k]).noalias() = inverse_[k] * z(k) - gain_[k] * x.col(order_[k - 1]);
      }
    }
  }
}

}  // namespace soft_body_sim
