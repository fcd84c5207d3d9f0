#include "core/solvers/chain_solver.h"

#include <algorithm>
#include <array>
#include <limits>

#include <Eigen/LU>

namespace soft_body_sim
{
namespace
{
constexpr std::int64_t kNone = -1;

/// Chains whose heaviest free node weighs this many times their lightest are heavy: the usual rule of
/// thumb keeps iterative constraint solvers below a mass ratio of 10.
constexpr double kMassRatio = 10.0;

/// The largest load h^2 T / (m l) at which an even chain is solved directly (ChainSolver::solve).
constexpr double kEvenLoad = 1.0;

/// The largest move [rest lengths] of a node in one step of a chain pinned at both ends (ChainSolver).
constexpr double kReach = 1.0;

}  // namespace

RowPartition partitionRows(const std::vector<std::pair<int, int>>& ends, const Eigen::VectorXd& inverse_mass)
{
  const std::size_t row_count = ends.size();
  const auto free = [&](int node) { return inverse_mass[node] > 0.0; };
  // Per node: how many rows meet there, and the first two of them.
  std::vector<int> degree(static_cast<std::size_t>(inverse_mass.size()), 0);
  std::vector<std::array<std::int64_t, 2>> meeting(degree.size(), { kNone, kNone });
  for (std::size_t r = 0; r < row_count; ++r)
  {
    const auto [a, b] = ends[r];
    if (a == b)
      continue;
    for (const int node : { a, b })
    {
      int& d = degree[static_cast<std::size_t>(node)];
      if (d < 2)
        meeting[static_cast<std::size_t>(node)][static_cast<std::size_t>(d)] = static_cast<std::int64_t>(r);
      ++d;
    }
  }
  // Each row's neighbours: the other row at each free end where exactly two meet. A row at a free node
  // where three or more meet (a branch), or with both ends on one node, makes its set of rows no chain.
  std::vector<std::array<std::int64_t, 2>> neighbours(row_count, { kNone, kNone });
  std::vector<std::uint8_t> branching(row_count, 0);
  for (std::size_t r = 0; r < row_count; ++r)
  {
    const auto [a, b] = ends[r];
    if (a == b)
    {
      branching[r] = 1;
      continue;
    }
    int slot = 0;
    for (const int node : { a, b })
    {
      const std::size_t n = static_cast<std::size_t>(node);
      if (!free(node) || degree[n] < 2)
        continue;
      if (degree[n] > 2)
      {
        branching[r] = 1;
        continue;
      }
      const std::int64_t self = static_cast<std::int64_t>(r);
      neighbours[r][static_cast<std::size_t>(slot++)] = meeting[n][0] == self ? meeting[n][1] : meeting[n][0];
    }
  }
  // Each connected set of rows: a chain if nothing branches, it has two or more rows and it has one link
  // fewer than rows (with at most two links per row, the connected graphs without a cycle are paths;
  // two rows on the same two free nodes count as two links, a cycle). Pinned at both ends, a straight
  // chain's rows are linearly dependent and an inextensible one's system singular: a taut or compressed
  // chain between two supports can leave the line only to second order, which the linearised step cannot
  // see; it answers with moves of C / theta for a bend theta. Such steps are refused (ChainSolver::solve).
  RowPartition partition;
  partition.chain_starts.push_back(0);
  std::vector<std::uint8_t> visited(row_count, 0);
  std::vector<std::uint8_t> in_chain(row_count, 0);
  std::vector<std::size_t> component;
  const auto freeEnd = [&](std::size_t r) {
    // An end row's node that no other row shares, if free.
    for (const int node : { ends[r].first, ends[r].second })
      if (free(node) && degree[static_cast<std::size_t>(node)] == 1)
        return true;
    return false;
  };
  for (std::size_t start = 0; start < row_count; ++start)
  {
    if (visited[start])
      continue;
    component.assign(1, start);
    visited[start] = 1;
    std::size_t links = 0;
    bool branches = false;
    for (std::size_t k = 0; k < component.size(); ++k)
    {
      const std::size_t r = component[k];
      branches = branches || branching[r];
      for (const std::int64_t next : neighbours[r])
      {
        if (next == kNone)
          continue;
        ++links;
        if (!visited[static_cast<std::size_t>(next)])
        {
          visited[static_cast<std::size_t>(next)] = 1;
          component.push_back(static_cast<std::size_t>(next));
        }
      }
    }
    if (branches || component.size() < 2 || links != 2 * (component.size() - 1))
      continue;
    // Walk the path from its free end if it has one: eliminating from there, each pivot of the Thomas
    // algorithm in a straight chain is at least the inverse mass of its row's node toward the support,
    // with no cancellation against a lighter neighbour (from the support, the last pivot is
    // w_end = (w_next + w_end) - w_next, which loses w_next / w_end of its digits: all of them at a mass
    // ratio of 1e16). Pinned at both ends, from either.
    std::int64_t current = kNone;
    for (const std::size_t r : component)
      if (neighbours[r][1] == kNone && (current == kNone || freeEnd(r)))
        current = static_cast<std::int64_t>(r);
    // An even chain with a free end keeps the sweep (see RowPartition).
    double lightest = std::numeric_limits<double>::infinity();
    double heaviest = 0.0;
    for (const std::size_t r : component)
      for (const int node : { ends[r].first, ends[r].second })
        if (free(node))
        {
          lightest = std::min(lightest, 1.0 / inverse_mass[node]);
          heaviest = std::max(heaviest, 1.0 / inverse_mass[node]);
        }
    if (heaviest < kMassRatio * lightest && freeEnd(static_cast<std::size_t>(current)))
      continue;
    std::int64_t previous = kNone;
    while (current != kNone)
    {
      const std::size_t r = static_cast<std::size_t>(current);
      partition.chain_rows.push_back(static_cast<std::uint32_t>(r));
      in_chain[r] = 1;
      const std::int64_t next = neighbours[r][0] != previous ? neighbours[r][0] : neighbours[r][1];
      previous = current;
      current = next;
    }
    partition.chain_starts.push_back(static_cast<std::uint32_t>(partition.chain_rows.size()));
    partition.chain_heavy.push_back(heaviest >= kMassRatio * lightest ? 1 : 0);
  }
  for (std::size_t r = 0; r < row_count; ++r)
    if (!in_chain[r])
      partition.swept.push_back(static_cast<std::uint32_t>(r));
  return partition;
}

void ChainSolver::reserve(std::size_t rows)
{
  const Eigen::Index n = static_cast<Eigen::Index>(rows);
  start_a_.resize(3, n);
  start_b_.resize(3, n);
  start_lambda_.resize(rows);
  estimate_.resize(rows);
  direction_.resize(3, n);
  geometric_.resize(rows);
  mobility_a_.resize(rows);
  mobility_b_.resize(rows);
  diagonal_.resize(rows);
  coupling_.resize(rows);
  coupling_below_.resize(rows);
  rhs_.resize(rows);
  lag_.resize(3, n);
  push_a_.resize(3, n);
  push_b_.resize(3, n);
  step_a_.resize(3, n);
  step_b_.resize(3, n);
  upper_.resize(rows);
  delta_.resize(rows);
  path_.resize(rows + 1);
  node_push_.resize(3, n + 1);
  node_step_.resize(3, n + 1);
  a_leads_.resize(rows);
  node_mobility_.resize(rows + 1);
}

ChainSolver::Outcome ChainSolver::solve(const SweepRow* rows, std::size_t count, const Eigen::VectorXd& inverse_mass,
                        const NodeArray& x_prev, double h, const double* tension, bool heavy,
                        const NodeHolds* holds, const NodeArray* correction, bool push, NodeArray& x, double* lambda)
{
  // An even chain whose tension impulse rivals its nodes' masses is refused (see the class comment): the
  // load h^2 T w / l exceeds kEvenLoad at a node of a row, compared without a division.
  const bool even = !heavy;
  bool loaded = false;
  for (std::size_t i = 0; even && i < count; ++i)
    loaded |= h * h * tension[i] * std::max(inverse_mass[rows[i].a], inverse_mass[rows[i].b]) >
              kEvenLoad * std::max(rows[i].rest_length, kMinSpringLength);
  if (loaded)
    return kLoaded;
  const auto outer = [&](std::size_t i, std::size_t next) {
    return rows[i].a == rows[next].a || rows[i].a == rows[next].b ? rows[i].b : rows[i].a;
  };
  const bool bounded = count > 1 && inverse_mass[outer(0, 1)] == 0.0 && inverse_mass[outer(count - 1, count - 2)] == 0.0;
  for (std::size_t i = 0; i < count; ++i)
  {
    start_a_.col(static_cast<Eigen::Index>(i)) = x.col(rows[i].a);
    start_b_.col(static_cast<Eigen::Index>(i)) = x.col(rows[i].b);
    start_lambda_[i] = lambda[i];
    estimate_[i] = tension[i];
  }
  // The lumped stiffness's known part (see the class comment) only on even chains: on the heavy chain of
  // hard case 2 it broke two bounds (a pendulum's segment strain 1.04 % > 1 %, and the folded chain
  // snapping taut gained 0.66 J), and a heavy chain hangs nearly straight, where P g, the bias it
  // removes, is small.
  if (!even)
    correction = nullptr;
  if (!newtonStep(rows, count, inverse_mass, x_prev, h, holds, correction, push, bounded, x, lambda))
    return kSingular;
  // This sub-step's tension -lambda / h^2 against the estimate its geometric stiffness used.
  const double inverse_h2 = 1.0 / (h * h);
  bool underestimated = false;
  for (std::size_t i = 0; i < count; ++i)
  {
    const double now = -lambda[i] * inverse_h2;
    underestimated = underestimated || now > 2.0 * estimate_[i];
    estimate_[i] = std::max(estimate_[i], now);
  }
  if (underestimated)
  {
    restart(rows, count, x, lambda);
    if (!newtonStep(rows, count, inverse_mass, x_prev, h, holds, correction, push, bounded, x, lambda))
      return kSingular;
  }
  return kSolved;
}

void ChainSolver::restart(const SweepRow* rows, std::size_t count, NodeArray& x, double* lambda) const
{
  for (std::size_t i = 0; i < count; ++i)
  {
    x.col(rows[i].a) = start_a_.col(static_cast<Eigen::Index>(i));
    x.col(rows[i].b) = start_b_.col(static_cast<Eigen::Index>(i));
    lambda[i] = start_lambda_[i];
  }
}

// Inlined into both steps' loops: called, they cost the chain solve 10 % (measured).
[[gnu::always_inline]] inline void ChainSolver::evaluateRow(const SweepRow& row, std::size_t i,
                                                            const NodeArray& x_prev, double h, const NodeArray& x,
                                                            double lambda)
{
  // The row at the current positions (as projectDistance, but every row at the same x): its direction,
  // its right-hand side -C - alpha~ lambda - gamma u . ((x_a - x_prev_a) - (x_b - x_prev_b)), and its
  // lumped geometric stiffness 2 h^2 T / l [kg] (see the class comment).
  const Eigen::Index column = static_cast<Eigen::Index>(i);
  direction_.col(column).setZero();
  rhs_[i] = 0.0;
  geometric_[i] = 0.0;
  if (row.inverse_denominator == 0.0)
    return;  // both ends pinned: dlambda = 0
  const Vec3 d = x.col(row.a) - x.col(row.b);
  const double length = d.norm();
  if (length < kMinSpringLength)
    return;  // coincident nodes: the direction is undefined
  const double inverse_length = 1.0 / length;
  const Vec3 u = d * inverse_length;
  direction_.col(column) = u;
  const double c_rate_h =
      row.gamma == 0.0 ? 0.0 : u.dot((x.col(row.a) - x_prev.col(row.a)) - (x.col(row.b) - x_prev.col(row.b)));
  rhs_[i] = -(length - row.rest_length) - row.alpha_tilde * lambda - row.gamma * c_rate_h;
  geometric_[i] = 2.0 * h * h * estimate_[i] * inverse_length;
}

[[gnu::always_inline]] inline void ChainSolver::eliminate(std::size_t i, std::size_t count)
{
  // Thomas algorithm (LDL^T of a tridiagonal matrix, LU where it is unsymmetric): for a symmetric positive
  // definite matrix it is stable without pivoting and every pivot is positive; friction's unsymmetric part
  // is at most mu times a sliding node's normal coupling. With a free end the rows are independent, so a
  // pivot vanishes only to round-off (a mass ratio beyond ~1e14 along the chain); pinned at both ends, the
  // last one vanishes where the chain is straight (partitionRows). One within the round-off of the
  // subtraction that made it is treated as zero: its row keeps dlambda = 0 and the others are solved
  // without it, rather than divided by noise.
  constexpr double kPivotFloor = 64.0 * std::numeric_limits<double>::epsilon();
  const double lower = i > 0 ? coupling_below_[i - 1] : 0.0;
  const double pivot = i > 0 ? diagonal_[i] - lower * upper_[i - 1] : diagonal_[i];
  if (!(pivot > kPivotFloor * diagonal_[i]))
  {
    upper_[i] = 0.0;
    delta_[i] = 0.0;
    return;
  }
  const double inverse_pivot = 1.0 / pivot;
  upper_[i] = i + 1 < count ? coupling_[i] * inverse_pivot : 0.0;
  delta_[i] = (rhs_[i] - (i > 0 ? lower * delta_[i - 1] : 0.0)) * inverse_pivot;
}

bool ChainSolver::newtonStep(const SweepRow* rows, std::size_t count, const Eigen::VectorXd& inverse_mass,
                             const NodeArray& x_prev, double h, const NodeHolds* holds,
                             const NodeArray* correction, bool push, bool bounded, NodeArray& x, double* lambda)
{
  if (holds == nullptr)
    return freeStep(rows, count, inverse_mass, x_prev, h, push ? correction : nullptr, bounded, x, lambda);
  for (std::size_t i = 0; i < count; ++i)
    evaluateRow(rows[i], i, x_prev, h, x, lambda[i]);
  // The mobility W~ = M~^-1 at each row's two nodes (zero at a pinned one). A free node of a chain meets
  // at most two rows, consecutive ones: the node row i shares with row i - 1 has that row's mobility.
  int shared_before = -1;
  for (std::size_t i = 0; i < count; ++i)
  {
    const SweepRow& row = rows[i];
    const auto before = [&]() -> const Matrix3& {
      return rows[i - 1].a == shared_before ? mobility_a_[i - 1] : mobility_b_[i - 1];
    };
    mobility_a_[i] = row.a == shared_before ? before() : mobility(rows, count, i, row.a, inverse_mass, holds);
    mobility_b_[i] = row.b == shared_before ? before() : mobility(rows, count, i, row.b, inverse_mass, holds);
    if (i + 1 < count)
      shared_before = row.a == rows[i + 1].a || row.a == rows[i + 1].b ? row.a : row.b;
  }
  // The known forces of the first Newton step, as impulses h^2 f [kg m] on each row's two nodes
  // (ChainSolver::solve): kinetic friction that the rows do not cause (NodeHolds::push) and the part of the
  // lumped geometric stiffness that the exact one does not have, at the last sub-step's correction c:
  // per row, 2 h^2 T / l P c_k - h^2 T / l P (c_k - c_other) = h^2 T / l P (c_a + c_b) on each node.
  const bool pushing = push && (holds != nullptr || correction != nullptr);
  if (pushing)
  {
    for (std::size_t i = 0; i < count; ++i)
    {
      const Eigen::Index column = static_cast<Eigen::Index>(i);
      push_a_.col(column).setZero();
      push_b_.col(column).setZero();
      if (holds != nullptr)
        for (const int node : { rows[i].a, rows[i].b })
          if (holds->kind[static_cast<std::size_t>(node)] == NodeHolds::kSlide)
            (node == rows[i].a ? push_a_ : push_b_).col(column) = holds->push.col(node);
      lag_.col(column).setZero();
      if (correction != nullptr && geometric_[i] != 0.0)
      {
        const Vec3 u = direction_.col(column);
        const Vec3 sum = correction->col(rows[i].a) + correction->col(rows[i].b);
        lag_.col(column) = 0.5 * geometric_[i] * (sum - u * u.dot(sum));
      }
    }
    // A node's lag is the sum over its rows: this row's and the neighbour's that shares the node.
    for (std::size_t i = 0; i < count; ++i)
    {
      const Eigen::Index column = static_cast<Eigen::Index>(i);
      for (const int node : { rows[i].a, rows[i].b })
      {
        Vec3 lag = lag_.col(column);
        for (const std::size_t k : { i - 1, i + 1 })
          if (k < count && (rows[k].a == node || rows[k].b == node))
            lag += lag_.col(static_cast<Eigen::Index>(k));
        (node == rows[i].a ? push_a_ : push_b_).col(column) += lag;
      }
      push_a_.col(column) = mobility_a_[i] * push_a_.col(column);
      push_b_.col(column) = mobility_b_[i] * push_b_.col(column);
      rhs_[i] -= direction_.col(column).dot(push_a_.col(column) - push_b_.col(column));
    }
  }
  // The system with row i divided by 1 + gamma_i, tridiagonal, and symmetric positive definite but where
  // kinetic friction makes a sliding node's W~ unsymmetric (mobility()):
  //   diagonal_i = u_i . (W~_a + W~_b) u_i + alpha~_i / (1 + gamma_i),
  //   coupling_i = (+-u_i) . W~_s (+-u_{i+1}) for the node s rows i and i + 1 share, the signs those of
  //   gradC at s (+u at a row's node a, -u at its node b); zero next to a row that cannot move.
  for (std::size_t i = 0; i < count; ++i)
  {
    const SweepRow& row = rows[i];
    const Vec3 u = direction_.col(static_cast<Eigen::Index>(i));
    const double scale = 1.0 / (1.0 + row.gamma);
    diagonal_[i] = u.isZero(0.0) ? 1.0 : u.dot((mobility_a_[i] + mobility_b_[i]) * u) + row.alpha_tilde * scale;
    rhs_[i] *= scale;
    if (i + 1 == count)
      continue;
    const SweepRow& next = rows[i + 1];
    const bool at_a = row.a == next.a || row.a == next.b;
    const double sign = (at_a ? 1.0 : -1.0) * ((at_a ? row.a : row.b) == next.a ? 1.0 : -1.0);
    const Matrix3& shared = at_a ? mobility_a_[i] : mobility_b_[i];
    const Vec3 v = direction_.col(static_cast<Eigen::Index>(i + 1));
    coupling_[i] = sign * u.dot(shared * v);
    coupling_below_[i] = sign * v.dot(shared * u);
  }
  // Thomas algorithm (eliminate()).
  for (std::size_t i = 0; i < count; ++i)
    eliminate(i, count);
  for (std::size_t i = count - 1; i-- > 0;)
    delta_[i] -= upper_[i] * delta_[i + 1];
  // x += W~ J^T dlambda, row by row; on a chain pinned at both ends (`bounded`) only if no node moves by
  // more than kReach rest lengths (see ChainSolver::solve): else nothing is changed.
  for (std::size_t i = 0; i < count; ++i)
  {
    const Eigen::Index column = static_cast<Eigen::Index>(i);
    const Vec3 u = direction_.col(column);
    step_a_.col(column) = mobility_a_[i] * (delta_[i] * u);
    step_b_.col(column) = mobility_b_[i] * (delta_[i] * u);
    const double reach = kReach * rows[i].rest_length;
    if (bounded &&
        (step_a_.col(column).squaredNorm() > reach * reach || step_b_.col(column).squaredNorm() > reach * reach))
      return false;
  }
  for (std::size_t i = 0; i < count; ++i)
  {
    const SweepRow& row = rows[i];
    lambda[i] += delta_[i];
    x.col(row.a) += step_a_.col(static_cast<Eigen::Index>(i));
    x.col(row.b) -= step_b_.col(static_cast<Eigen::Index>(i));
  }
  // ... and those displacements, once per node (a node shared with the row before has had it).
  if (pushing)
    for (std::size_t i = 0; i < count; ++i)
    {
      const SweepRow& row = rows[i];
      const auto first_time = [&](int node) { return i == 0 || (rows[i - 1].a != node && rows[i - 1].b != node); };
      if (first_time(row.a))
        x.col(row.a) += push_a_.col(static_cast<Eigen::Index>(i));
      if (first_time(row.b))
        x.col(row.b) += push_b_.col(static_cast<Eigen::Index>(i));
    }
  return true;
}

[[gnu::always_inline]] inline ChainSolver::NodeMobility ChainSolver::nodeMobility(double w, double left,
                                                                                  double right, double s)
{
  if (w == 0.0)
    return NodeMobility{ 0.0, 0.0, 0.0, 0.0, s };
  // Without tension M~ = m I: w I exactly, as the Gauss-Seidel update uses.
  if (left == 0.0 && right == 0.0)
    return NodeMobility{ w, 0.0, 0.0, 0.0, s };
  // In units of the node's mass: a = w g_l, b = w g_r, c = 1 + a + b, D = (1 + a)(1 + b) - a b s^2 > 0.
  const double a = w * left;
  const double b = w * right;
  const double d = (1.0 + a) * (1.0 + b) - a * b * s * s;
  const double f = w / ((1.0 + a + b) * d);
  return NodeMobility{ d * f, a * (1.0 + a) * f, a * b * s * f, b * (1.0 + b) * f, s };
}

bool ChainSolver::freeStep(const SweepRow* rows, std::size_t count, const Eigen::VectorXd& inverse_mass,
                           const NodeArray& x_prev, double h, const NodeArray* correction, bool bounded, NodeArray& x,
                           double* lambda)
{
  // newtonStep without contacts, node by node along the path (path_[p] joins rows p - 1 and p), in short
  // passes: the rows, each on its own; the nodes' mobility (NodeMobility) and known displacement, each from
  // its two rows; the system and its elimination, the one pass where each row waits for the last.
  const auto column = [](std::size_t i) { return static_cast<Eigen::Index>(i); };
  for (std::size_t i = 0; i < count; ++i)
  {
    // Row i joins path_[i] and path_[i + 1]: the node it shares with row i + 1 is its second.
    const SweepRow& row = rows[i];
    a_leads_[i] = i + 1 < count ? row.a != rows[i + 1].a && row.a != rows[i + 1].b : i == 0 || row.a == path_[i];
    if (i == 0)
      path_[0] = a_leads_[0] ? row.a : row.b;
    path_[i + 1] = a_leads_[i] ? row.b : row.a;
    evaluateRow(row, i, x_prev, h, x, lambda[i]);
    // The lag of the lumped stiffness, h^2 T / l P (c_a + c_b) on each node (newtonStep).
    lag_.col(column(i)).setZero();
    if (correction != nullptr && geometric_[i] != 0.0)
    {
      const Vec3 u = direction_.col(column(i));
      const Vec3 sum = correction->col(row.a) + correction->col(row.b);
      lag_.col(column(i)) = 0.5 * geometric_[i] * (sum - u * u.dot(sum));
    }
  }
  for (std::size_t p = 0; p <= count; ++p)
  {
    const Vec3 u_left = p > 0 ? Vec3(direction_.col(column(p - 1))) : Vec3::Zero();
    const Vec3 u_right = p < count ? Vec3(direction_.col(column(p))) : Vec3::Zero();
    const NodeMobility node = nodeMobility(inverse_mass[path_[p]], p > 0 ? geometric_[p - 1] : 0.0,
                                           p < count ? geometric_[p] : 0.0, u_left.dot(u_right));
    node_mobility_[p] = node;
    if (correction == nullptr)
      continue;
    const Vec3 lag = p == 0 ? Vec3(lag_.col(0)) : p == count ? Vec3(lag_.col(column(p - 1)))
                                                          : Vec3(lag_.col(column(p - 1)) + lag_.col(column(p)));
    node_push_.col(column(p)) = node.times(u_left, u_right, lag);
  }
  // Row r is the right-hand row of path node r and the left-hand row of node r + 1 (see newtonStep for the
  // system), eliminated as it is made.
  for (std::size_t r = 0; r < count; ++r)
  {
    const SweepRow& row = rows[r];
    const Vec3 u = direction_.col(column(r));
    const NodeMobility& node = node_mobility_[r + 1];
    if (correction != nullptr)
      rhs_[r] -= (a_leads_[r] ? 1.0 : -1.0) * u.dot(node_push_.col(column(r)) - node_push_.col(column(r + 1)));
    const double scale = row.gamma == 0.0 ? 1.0 : 1.0 / (1.0 + row.gamma);
    rhs_[r] *= scale;
    diagonal_[r] = u.isZero(0.0) ? 1.0 : node_mobility_[r].rightRight() + node.leftLeft() + row.alpha_tilde * scale;
    // The signs of gradC at the shared node: +u at a row's node a, -u at its node b.
    coupling_[r] =
        r + 1 < count ? (a_leads_[r] ? -1.0 : 1.0) * (a_leads_[r + 1] ? 1.0 : -1.0) * node.leftRight() : 0.0;
    coupling_below_[r] = coupling_[r];
    eliminate(r, count);
  }
  for (std::size_t i = count - 1; i-- > 0;)
    delta_[i] -= upper_[i] * delta_[i + 1];
  // x += W~ J^T dlambda, node by node: gradC is +u at a row's node a, -u at its node b. On a chain pinned at
  // both ends (`bounded`) only if no row moves a node by more than kReach rest lengths: else nothing is changed.
  for (std::size_t p = 0; p <= count; ++p)
  {
    const NodeMobility& node = node_mobility_[p];
    const Vec3 u_l = p > 0 ? Vec3(direction_.col(column(p - 1))) : Vec3::Zero();
    const Vec3 u_r = p < count ? Vec3(direction_.col(column(p))) : Vec3::Zero();
    const Vec3 by_left =
        p > 0 ? node.leftTimes(u_l, u_r, (a_leads_[p - 1] ? -1.0 : 1.0) * delta_[p - 1]) : Vec3::Zero();
    const Vec3 by_right = p < count ? node.rightTimes(u_l, u_r, (a_leads_[p] ? 1.0 : -1.0) * delta_[p]) : Vec3::Zero();
    if (bounded)
    {
      const double reach_left = p > 0 ? kReach * rows[p - 1].rest_length : 0.0;
      const double reach_right = p < count ? kReach * rows[p].rest_length : 0.0;
      if (by_left.squaredNorm() > reach_left * reach_left || by_right.squaredNorm() > reach_right * reach_right)
        return false;
    }
    node_step_.col(column(p)) = by_left + by_right;
  }
  for (std::size_t i = 0; i < count; ++i)
    lambda[i] += delta_[i];
  for (std::size_t p = 0; p <= count; ++p)
    x.col(path_[p]) += correction != nullptr ? Vec3(node_step_.col(column(p)) + node_push_.col(column(p)))
                                             : Vec3(node_step_.col(column(p)));
  return true;
}

ChainSolver::Matrix3 ChainSolver::mobility(const SweepRow* rows, std::size_t count, std::size_t i, int node,
                                           const Eigen::VectorXd& inverse_mass, const NodeHolds* holds) const
{
  const double w = inverse_mass[node];
  const std::uint8_t hold = holds ? holds->kind[static_cast<std::size_t>(node)] : std::uint8_t{ NodeHolds::kFree };
  if (w == 0.0 || hold == NodeHolds::kStick)
    return Matrix3::Zero();
  Matrix3 inertia = (1.0 / w) * Matrix3::Identity();
  bool stiffened = false;
  for (std::size_t k = i > 0 ? i - 1 : 0; k <= i + 1 && k < count; ++k)
  {
    if (geometric_[k] == 0.0 || (k != i && rows[k].a != node && rows[k].b != node))
      continue;
    const Vec3 u = direction_.col(static_cast<Eigen::Index>(k));
    inertia += geometric_[k] * (Matrix3::Identity() - u * u.transpose());
    stiffened = true;
  }
  // Without tension M~ = m I: w I exactly, as the Gauss-Seidel update uses.
  const Matrix3 free = stiffened ? Matrix3(inertia.inverse()) : Matrix3(w * Matrix3::Identity());
  if (hold == NodeHolds::kFree)
    return free;
  const Vec3 n = holds->normal.col(node);
  const Matrix3 tangent = Matrix3::Identity() - n * n.transpose();
  // Kinetic friction mu nu against the slip s, nu = -n . g the normal impulse that the rows' impulse g
  // presses the node on with: the node moves by P W~ P (g + mu (n . g) s).
  const Vec3 slip = holds->friction[static_cast<std::size_t>(node)] * holds->slip.col(node);
  return tangent * free * tangent * (Matrix3::Identity() + slip * n.transpose());
}

}  // namespace soft_body_sim
