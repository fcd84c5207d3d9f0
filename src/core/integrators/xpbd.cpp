#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <unordered_map>
#include <utility>
#include <vector>

#include "core/elements/column_packets.h"
#include "core/elements/edge_colouring.h"
#include "core/elements/wide_columns.h"
#include "core/integrators/chain_contacts.h"
#include "core/solvers/chain_solver.h"
#include "core/integrators/integrator_kit.h"
#include "soft_body_sim/core/elements/forces.h"

namespace soft_body_sim
{
namespace
{
/// One XPBD update of a pressure cell (jelly) as a compliant area constraint whose energy is the
/// cell's gas, E = p0 A0 e(a) with a = A / A0 (see CellGas). XPBD's implicit position update
/// M (x - x~) = h^2 F = -h^2 p0 e'(a) dA/dx^T becomes, with lambda = -h^2 p0 e'(a),
///   x - x~ = M^-1 dA/dx^T lambda,   e'(a) + alpha~ lambda = 0,   alpha~ = 1 / (h^2 p0),
/// and one Newton step on the second equation along the first (dA/dx held fixed, as in XPBD) gives
///   dlambda = -(e'(a) + alpha~ lambda) / (e''(a) W / A0 + alpha~),   W = sum_k w_k |dA/dx_k|^2,
///   x_k += w_k dA/dx_k dlambda.
/// For the quadratic e = (a - 1)^2 / 2 this is the usual XPBD area constraint C = A - A0 with
/// compliance A0 / p0; the gas's e'' = 1/a^2 makes the step stiffen as the cell is squeezed.
/// e'(a) = -p / p0 and e''(a) = S A0 / p0 in terms of CellGas's pressure p and stiffness S.
void solveCell(const PressureCell& cell, const Eigen::VectorXd& inverse_mass, double h, NodeArray& x,
               double& lambda)
{
  if (!(cell.pressure > 0.0))
    return;
  Vec3 g[4];
  const CellGas gas = cellGas(cell, cellArea(cell, x, g));
  double w = 0.0;
  for (int k = 0; k < 4; ++k)
    w += inverse_mass[cell.nodes[k]] * g[k].squaredNorm();
  const double alpha_tilde = 1.0 / (h * h * cell.pressure);
  const double denominator = gas.stiffness * w / cell.pressure + alpha_tilde;
  if (w < 1e-300 || denominator < 1e-300)
    return;
  const double delta_lambda = (gas.pressure / cell.pressure - alpha_tilde * lambda) / denominator;
  lambda += delta_lambda;
  for (int k = 0; k < 4; ++k)
    x.col(cell.nodes[k]) += (inverse_mass[cell.nodes[k]] * delta_lambda) * g[k];
}

/// What a swept row's update takes besides its ends: SweepRow's four coefficients in its order, so that two
/// rows' (rest_length, alpha_tilde) and (gamma, inverse_denominator) load whole into packets.
struct RowCoefficients
{
  double rest_length;
  double alpha_tilde;
  double gamma;
  double inverse_denominator;

  void carry(StateArchive& archive) { archive(rest_length, alpha_tilde, gamma, inverse_denominator); }
};
static_assert(sizeof(RowCoefficients) == 4 * sizeof(double), "RowCoefficients' doubles must lie side by side");

/// A row swept by Gauss-Seidel: its ends and its coefficients' entry in the solve's table. Rows of the same
/// parameters and the same sum of their ends' inverse masses share an entry (a cloth's 600,000 springs have
/// a handful), so a row is 12 bytes where a SweepRow is 40.
struct SweptRow
{
  int a;
  int b;
  std::uint32_t coefficients;

  void carry(StateArchive& archive) { archive(a, b, coefficients); }
};

SweepRow sweepRow(const SweptRow& row, const RowCoefficients& c)
{
  return SweepRow{ row.a, row.b, c.rest_length, c.alpha_tilde, c.gamma, c.inverse_denominator };
}

/// projectDistance on two rows that share no node (of one colour), in one of Eigen's packets: lane by lane
/// the same operations in the same order, so the same bits as two calls. `lambda` holds their multipliers.
void projectDistancePair(const SweptRow* rows, const RowCoefficients* table, const Eigen::VectorXd& inverse_mass,
                         const NodeArray& x_prev, NodeArray& x, double* lambda)
{
  using Eigen::internal::ploadu;
  using Eigen::internal::vec2d_unpackhi;
  using Eigen::internal::vec2d_unpacklo;
  const std::ptrdiff_t a[2] = { rows[0].a, rows[1].a };
  const std::ptrdiff_t b[2] = { rows[0].b, rows[1].b };
  const ColumnPair x_a = loadColumns(x.data(), a[0], a[1]);
  const ColumnPair x_b = loadColumns(x.data(), b[0], b[1]);
  const ColumnPair previous_a = loadColumns(x_prev.data(), a[0], a[1]);
  const ColumnPair previous_b = loadColumns(x_prev.data(), b[0], b[1]);
  const Packet dx = x_a.x - x_b.x;
  const Packet dy = x_a.y - x_b.y;
  const Packet dz = x_a.z - x_b.z;
  const Packet length = Eigen::internal::psqrt(dx * dx + dy * dy + dz * dz);
  const Packet inverse_length = 1.0 / length;
  const Packet ux = dx * inverse_length;
  const Packet uy = dy * inverse_length;
  const Packet uz = dz * inverse_length;
  // Each row's (rest_length, alpha_tilde) and (gamma, inverse_denominator), transposed into the rows' lanes.
  const RowCoefficients& c_0 = table[rows[0].coefficients];
  const RowCoefficients& c_1 = table[rows[1].coefficients];
  const Packet rest_alpha_0 = ploadu<Packet>(&c_0.rest_length), rest_alpha_1 = ploadu<Packet>(&c_1.rest_length);
  const Packet gamma_inverse_0 = ploadu<Packet>(&c_0.gamma), gamma_inverse_1 = ploadu<Packet>(&c_1.gamma);
  const Packet gamma = vec2d_unpacklo(gamma_inverse_0, gamma_inverse_1);
  // gradC . (x - x_prev), and 0 without damping (as projectDistance).
  const Packet rate_h = ux * ((x_a.x - previous_a.x) - (x_b.x - previous_b.x)) +
                        uy * ((x_a.y - previous_a.y) - (x_b.y - previous_b.y)) +
                        uz * ((x_a.z - previous_a.z) - (x_b.z - previous_b.z));
  const Packet zero = Eigen::internal::pzero(gamma);
  const Packet c_rate_h = Eigen::internal::pselect(Eigen::internal::pcmp_eq(gamma, zero), zero, rate_h);
  const Packet c = length - vec2d_unpacklo(rest_alpha_0, rest_alpha_1);
  const Packet inverse_denominator = vec2d_unpackhi(gamma_inverse_0, gamma_inverse_1);
  const Packet delta_lambda =
      (-c - vec2d_unpackhi(rest_alpha_0, rest_alpha_1) * ploadu<Packet>(lambda) - gamma * c_rate_h) *
      inverse_denominator;
  alignas(16) double lanes[4][2];  // delta lambda, u_z, 1 / denominator, |d| of each row
  Eigen::internal::pstore(lanes[0], delta_lambda);
  Eigen::internal::pstore(lanes[1], uz);
  Eigen::internal::pstore(lanes[2], inverse_denominator);
  Eigen::internal::pstore(lanes[3], length);
  // (u_x, u_y) of each row
  const Packet u_xy[2] = { vec2d_unpacklo(ux, uy), vec2d_unpackhi(ux, uy) };
  double* const position = x.data();
  for (int l = 0; l < 2; ++l)
  {
    // As projectDistance: rows that cannot move, and coincident nodes (no direction), are left.
    if (lanes[2][l] == 0.0 || lanes[3][l] < kMinSpringLength)
      continue;
    lambda[l] += lanes[0][l];
    const double move_a = inverse_mass[a[l]] * lanes[0][l];
    const double move_b = inverse_mass[b[l]] * lanes[0][l];
    addToColumn(position, a[l], Eigen::internal::pset1<Packet>(move_a) * u_xy[l], move_a * lanes[1][l]);
    subtractFromColumn(position, b[l], Eigen::internal::pset1<Packet>(move_b) * u_xy[l], move_b * lanes[1][l]);
  }
}

/// Four rows' updates as quadMove works them out, before applyQuadMove moves their ends.
struct QuadMove
{
  std::ptrdiff_t a[4];
  std::ptrdiff_t b[4];
  alignas(32) double lanes[4][4];  // delta lambda, u_z, 1 / denominator, |d| of each row
  __m128d u_xy[4];                 // (u_x, u_y) of each row
};

/// The updates of four rows that share no node (AVX2; hasWideLanes): lane by lane the same operations in the
/// same order as projectDistance, so the same bits as four calls.
SOFT_BODY_SIM_WIDE void quadMove(const SweptRow* rows, const RowCoefficients* table, const NodeArray& x_prev,
                                 const NodeArray& x, const double* lambda, QuadMove& move)
{
  for (int l = 0; l < 4; ++l)
  {
    move.a[l] = rows[l].a;
    move.b[l] = rows[l].b;
  }
  const ColumnQuad x_a = loadColumns4(x.data(), move.a);
  const ColumnQuad x_b = loadColumns4(x.data(), move.b);
  const ColumnQuad previous_a = loadColumns4(x_prev.data(), move.a);
  const ColumnQuad previous_b = loadColumns4(x_prev.data(), move.b);
  const __m256d dx = x_a.x - x_b.x;
  const __m256d dy = x_a.y - x_b.y;
  const __m256d dz = x_a.z - x_b.z;
  const __m256d length = _mm256_sqrt_pd(dx * dx + dy * dy + dz * dz);
  const __m256d inverse_length = 1.0 / length;
  const __m256d ux = dx * inverse_length;
  const __m256d uy = dy * inverse_length;
  const __m256d uz = dz * inverse_length;
  // Each row's four coefficients (RowCoefficients) transposed into the rows' lanes.
  __m256d coefficient[4];
  for (int l = 0; l < 4; ++l)
    coefficient[l] = _mm256_loadu_pd(&table[rows[l].coefficients].rest_length);
  const __m256d low_01 = _mm256_unpacklo_pd(coefficient[0], coefficient[1]);   // (r0, r1, g0, g1)
  const __m256d high_01 = _mm256_unpackhi_pd(coefficient[0], coefficient[1]);  // (a0, a1, i0, i1)
  const __m256d low_23 = _mm256_unpacklo_pd(coefficient[2], coefficient[3]);
  const __m256d high_23 = _mm256_unpackhi_pd(coefficient[2], coefficient[3]);
  const __m256d rest_length = _mm256_permute2f128_pd(low_01, low_23, 0x20);
  const __m256d gamma = _mm256_permute2f128_pd(low_01, low_23, 0x31);
  const __m256d alpha_tilde = _mm256_permute2f128_pd(high_01, high_23, 0x20);
  const __m256d inverse_denominator = _mm256_permute2f128_pd(high_01, high_23, 0x31);
  // gradC . (x - x_prev), and 0 without damping (as projectDistance).
  const __m256d rate_h = ux * ((x_a.x - previous_a.x) - (x_b.x - previous_b.x)) +
                         uy * ((x_a.y - previous_a.y) - (x_b.y - previous_b.y)) +
                         uz * ((x_a.z - previous_a.z) - (x_b.z - previous_b.z));
  const __m256d zero = _mm256_setzero_pd();
  const __m256d c_rate_h = _mm256_blendv_pd(rate_h, zero, _mm256_cmp_pd(gamma, zero, _CMP_EQ_OQ));
  const __m256d c = length - rest_length;
  const __m256d delta_lambda = (-c - alpha_tilde * _mm256_loadu_pd(lambda) - gamma * c_rate_h) * inverse_denominator;
  _mm256_store_pd(move.lanes[0], delta_lambda);
  _mm256_store_pd(move.lanes[1], uz);
  _mm256_store_pd(move.lanes[2], inverse_denominator);
  _mm256_store_pd(move.lanes[3], length);
  lanePairs(ux, uy, move.u_xy);
}

/// Moves the ends of quadMove's four rows and adds to their multipliers `lambda`, row by row.
SOFT_BODY_SIM_WIDE void applyQuadMove(const QuadMove& move, const Eigen::VectorXd& inverse_mass, NodeArray& x,
                                      double* lambda)
{
  double* const position = x.data();
  for (int l = 0; l < 4; ++l)
  {
    // As projectDistance: rows that cannot move, and coincident nodes (no direction), are left.
    if (move.lanes[2][l] == 0.0 || move.lanes[3][l] < kMinSpringLength)
      continue;
    const double delta_lambda = move.lanes[0][l];
    lambda[l] += delta_lambda;
    const double move_a = inverse_mass[move.a[l]] * delta_lambda;
    const double move_b = inverse_mass[move.b[l]] * delta_lambda;
    addToColumn(position, move.a[l], _mm_set1_pd(move_a) * move.u_xy[l], move_a * move.lanes[1][l]);
    subtractFromColumn(position, move.b[l], _mm_set1_pd(move_b) * move.u_xy[l], move_b * move.lanes[1][l]);
  }
}

/// The rows [k, end) of one colour four at a time (AVX2), two quads worked out before either moves its
/// ends, so that the processor overlaps their square roots and divisions: returns where it stopped.
[[gnu::target("avx2")]] std::size_t projectDistanceQuads(const SweptRow* rows, std::size_t k, std::size_t end,
                                                         const RowCoefficients* table,
                                                         const Eigen::VectorXd& inverse_mass, const NodeArray& x_prev,
                                                         NodeArray& x, double* lambda)
{
  QuadMove first;
  QuadMove second;
  for (; k + 8 <= end; k += 8)
  {
    quadMove(rows + k, table, x_prev, x, lambda + k, first);
    quadMove(rows + k + 4, table, x_prev, x, lambda + k + 4, second);
    applyQuadMove(first, inverse_mass, x, lambda + k);
    applyQuadMove(second, inverse_mass, x, lambda + k + 4);
  }
  for (; k + 4 <= end; k += 4)
  {
    quadMove(rows + k, table, x_prev, x, lambda + k, first);
    applyQuadMove(first, inverse_mass, x, lambda + k);
  }
  return k;
}

/// Extended position-based dynamics (Macklin, Mueller, Chentanez 2016), one call per sub-step as in
/// "Small steps in physics simulation" (Macklin et al. 2019) and Ten Minute Physics:
///   preSolve:  v = v / (1 + h drag) + h g,  x_prev = x,  x += h v
///              (drag implicit on the carried velocity only, so it stays stable for any h drag and
///              cannot scale gravity down at rest, where the constraints cancel h g every sub-step)
///   solve:     `iterations` block Gauss-Seidel sweeps over springs (compliance 1/k, damping c),
///              distance constraints (their own compliance) and pressure cells (see solveCell),
///              lambda accumulated per sub-step. Rows that form chains (partitionRows) are solved
///              together and exactly, one Newton step per sweep (chain_solver.h), unless an even chain
///              has been too loaded for that step (solveChains); the others one by one
///   postSolve: v = (x - x_prev) / h
class Xpbd final : public Integrator
{
public:
  std::unique_ptr<Integrator> clone() const override { return std::make_unique<Xpbd>(*this); }
  bool assign(const Integrator& other) override { return assignIfSame(*this, other); }
  /// The chain solver's buffers are made anew by every solve; the rest is carried.
  void carry(StateArchive& archive, const Model& /*model*/) override
  {
    archive(order_, swept_count_, colour_starts_, last_colour_shares_nodes_, chain_starts_, ordered_nodes_,
            chain_contacts_, chain_heavy_, swept_chain_, correction_, chain_tension_, swept_, coefficients_,
            coefficient_rows_, chain_rows_, rows_h_, reorder_, lambda_, solved_h_, cell_lambda_);
    if (archive.reading())
      reserveChains();
  }
  void step(const Model& model, State& state, double h, int iterations) override
  {
    stepWithContacts(model, state, h, iterations, nullptr);
  }

  void stepWithContacts(const Model& model, State& state, double h, int iterations,
                        ContactQuery* contacts) override
  {
    preSolve(model, state, h);
    solve(model, state.position, h, iterations, contacts);
    postSolve(model, state, h);
  }

  void internalForces(const Model& model, const State& state, InternalForces& forces) const override
  {
    stateInternalForces(model, state, forces);
    if (solved_h_ == 0.0 || lambda_.size() != forces.tension.size() || cell_lambda_.size() != forces.pressure.size())
      return;
    // Row order_[k]'s multiplier moved its ends by w lambda u: the displacement h^2 w F of a force
    // F = lambda u / h^2 on end a, a tension of -lambda / h^2. A cell's moved its corners by w lambda dA/dx,
    // the displacement of the force p dA/dx of a pressure p = lambda / h^2 (solveCell).
    const double inverse_h2 = 1.0 / (solved_h_ * solved_h_);
    for (std::size_t k = 0; k < order_.size(); ++k)
      forces.tension[order_[k]] = -lambda_[static_cast<Eigen::Index>(k)] * inverse_h2;
    forces.pressure = cell_lambda_ * inverse_h2;
  }

  /// The rows hold only the model's parameters and h, so a change of state (invalidate()) keeps them;
  /// a change of the model (stiffness, masses, an attached node) orders and builds them again.
  void modelChanged() override { reorder_ = true; }

private:
  void preSolve(const Model& model, State& state, double h)
  {
    previous_.resize(3, model.nodeCount());  // no allocation after the first sub-step
    const double drag_factor = 1.0 / (1.0 + h * model.drag);
    for (int i = 0; i < model.nodeCount(); ++i)
    {
      previous_.col(i) = state.position.col(i);
      if (!model.isFree(i))
        continue;
      state.velocity.col(i) = state.velocity.col(i) * drag_factor + h * model.gravity;
      state.position.col(i) += h * state.velocity.col(i);
    }
  }

  void solve(const Model& model, NodeArray& x, double h, int iterations, ContactQuery* contacts)
  {
    const std::size_t row_count = model.springs.size() + model.constraints.size();
    // The partition into chains depends on which nodes are pinned (modelChanged() follows World::attach
    // and detach).
    if (reorder_ || order_.size() != row_count || ordered_nodes_ != model.nodeCount())
    {
      reorder_ = false;
      orderRows(model);
      rows_h_ = 0.0;
    }
    lambda_.setZero(static_cast<Eigen::Index>(row_count));
    cell_lambda_.setZero(static_cast<Eigen::Index>(model.cells.size()));
    // The coefficients are stale after a new h or a new order (modelChanged()).
    if (h != rows_h_)
      makeCoefficients(model, h);
    const bool held =
        contacts != nullptr && chain_starts_.size() > 1 && chain_contacts_.hold(model, *contacts, previous_, h, x);
    if (held)
      startChains(model, h, true);
    const bool chained = chain_starts_.size() > 1;
    if (chained)
      predicted_ = x;  // sized once: no allocation after the first sub-step
    for (int iteration = 0; iteration < iterations; ++iteration)
    {
      sweepColours(model, x);
      // Chains share no free node with the swept rows: each is one block of a block Gauss-Seidel, solved
      // exactly (one Newton step per iteration).
      solveChains(model, h, held, iteration, false, x);
      for (std::size_t k = 0; k < model.cells.size(); ++k)
        solveCell(model.cells[k], model.inverse_mass, h, x, cell_lambda_[static_cast<Eigen::Index>(k)]);
    }
    // Contacts that the solve's forces break change their holds, and the chains are solved again from
    // their prediction (chain_contacts.h); the swept rows and cells share no free node with them.
    for (int pass = 1;
         held && chain_contacts_.check(model, chain_rows_, lambda_.data() + swept_count_, previous_, h, x) &&
         pass < ChainContacts::kPasses;
         ++pass)
    {
      chain_contacts_.place(model, previous_, h, x);
      startChains(model, h, false);
      for (int iteration = 0; iteration < iterations; ++iteration)
        solveChains(model, h, held, iteration, true, x);
    }
    if (held)
      chain_contacts_.report(model, h, x, *contacts);
    if (chained)
      correction_ = x - predicted_;
    // The chains' tensions T = -lambda / h^2 [N] (lambda < 0 pulls the ends together), for the next
    // sub-step's geometric stiffness; compression adds none.
    const double inverse_h2 = 1.0 / (h * h);
    for (std::size_t k = swept_count_; k < row_count; ++k)
      chain_tension_[static_cast<Eigen::Index>(k - swept_count_)] =
          std::max(0.0, -lambda_[static_cast<Eigen::Index>(k)] * inverse_h2);
    solved_h_ = h;
  }

  /// Every chain, one Newton step each (chain_solver.h), with the contacts' holds if `held` (their
  /// kinetic friction and the geometric stiffness's known part in the first iteration). A chain whose
  /// step is refused (ChainSolver::solve) is swept by Gauss-Seidel: for this sub-step if the step was
  /// nearly singular, from then on until the rows are ordered again if the chain was too loaded: switching back, the direct solve meets the sweep's stretched
  /// chain and snaps it back in one step (measured: the 201-node rope swinging at h = 0.6 ms, stable
  /// solved directly, gained 1.7 kJ when its chain switched at every sub-step). Swept, the chain has no
  /// holds: the contact stage after the solve keeps its nodes out of the colliders, as for every swept row.
  void solveChains(const Model& model, double h, bool held, int iteration, bool heavy_only, NodeArray& x)
  {
    const NodeHolds* holds = held ? &chain_contacts_.holds() : nullptr;
    for (std::size_t c = 0; c + 1 < chain_starts_.size(); ++c)
    {
      if (heavy_only && !chain_heavy_[c])
        continue;
      const std::size_t first = chain_starts_[c];
      const std::size_t count = chain_starts_[c + 1] - first;
      ChainSolver::Outcome outcome = ChainSolver::kLoaded;
      if (!swept_chain_[c])
        outcome = chains_.solve(&chain_rows_[first - swept_count_], count, model.inverse_mass, previous_, h,
                                chain_tension_.data() + (first - swept_count_), chain_heavy_[c] != 0, holds,
                                &correction_, iteration == 0, x, lambda_.data() + first);
      swept_chain_[c] = outcome == ChainSolver::kLoaded;
      if (outcome != ChainSolver::kSolved)
        for (std::size_t k = first; k < first + count; ++k)
          projectDistance(chain_rows_[k - swept_count_], model.inverse_mass, previous_, x,
                          lambda_[static_cast<Eigen::Index>(k)]);
    }
  }

  /// The heavy chains' multipliers at the start of a solve with contacts: a row between two nodes that cannot
  /// move (pinned or stuck) keeps its tension (see ChainContacts): the last sub-step's in the first pass,
  /// the last pass's in the others; the other rows start at 0.
  void startChains(const Model& model, double h, bool first_pass)
  {
    for (std::size_t c = 0; c + 1 < chain_starts_.size(); ++c)
      for (std::size_t k = chain_starts_[c]; chain_heavy_[c] && k < chain_starts_[c + 1]; ++k)
      {
        const std::size_t chain_row = k - swept_count_;
        const SweepRow& row = chain_rows_[chain_row];
        const Eigen::Index r = static_cast<Eigen::Index>(k);
        const bool frozen = chain_contacts_.immobile(model, row.a) && chain_contacts_.immobile(model, row.b);
        lambda_[r] = !frozen      ? 0.0
                     : first_pass ? -chain_tension_[static_cast<Eigen::Index>(chain_row)] * h * h
                                  : lambda_[r];
      }
  }

  /// Row r of the solve: spring r (compliance 1 / k, damping c) for r < springs.size(), else a distance
  /// constraint.
  static ConstraintRow constraintRow(const Model& model, std::size_t r, double h, double inverse_h2)
  {
    if (r < model.springs.size())
    {
      const Spring& s = model.springs[r];
      const double alpha_tilde = inverse_h2 / s.stiffness;
      return ConstraintRow{ s.a, s.b, s.rest_length, alpha_tilde, alpha_tilde * s.damping * h };
    }
    const DistanceConstraint& c = model.constraints[r - model.springs.size()];
    return ConstraintRow{ c.a, c.b, c.rest_length, c.compliance * inverse_h2, 0.0 };
  }

  /// The solve order: the rows swept by Gauss-Seidel (see colourRows), then the chains (see
  /// partitionRows), each in path order.
  void orderRows(const Model& model)
  {
    const std::size_t spring_count = model.springs.size();
    std::vector<std::pair<int, int>> ends;
    ends.reserve(spring_count + model.constraints.size());
    for (const Spring& s : model.springs)
      ends.emplace_back(s.a, s.b);
    for (const DistanceConstraint& c : model.constraints)
      ends.emplace_back(c.a, c.b);
    const RowPartition partition = partitionRows(ends, model.inverse_mass);
    order_.clear();
    colourRows(model, ends, partition.swept);
    swept_count_ = order_.size();
    order_.insert(order_.end(), partition.chain_rows.begin(), partition.chain_rows.end());
    chain_starts_.clear();
    for (const std::size_t start : partition.chain_starts)
      chain_starts_.push_back(swept_count_ + start);
    tableRows(model, ends);
    chain_rows_.resize(order_.size() - swept_count_);
    reserveChains();
    chain_tension_.setZero(static_cast<Eigen::Index>(chain_rows_.size()));
    correction_.setZero(3, chain_starts_.size() > 1 ? model.nodeCount() : 0);  // only a chain's solve reads it
    swept_chain_.assign(chain_starts_.size(), 0);
    // Each chain's nodes in path order, and its rows between them, for the contacts in its solve.
    // Contacts act inside the solve of heavy chains only (chain_contacts.h: a load held by friction on
    // light nodes); an even chain, whose nodes the contact stage stops at their own mass as well as the
    // sweep's, keeps that stage (measured: held inside the solve, the rope of test_self_contacts that is
    // pulled across another sank 16 % of a diameter into it, against less than 10 % after the solve).
    chain_heavy_ = partition.chain_heavy;
    std::vector<ChainPath> paths;
    for (std::size_t c = 0; c + 1 < chain_starts_.size(); ++c)
    {
      if (!chain_heavy_[c])
        continue;
      ChainPath path;
      for (std::size_t k = chain_starts_[c]; k < chain_starts_[c + 1]; ++k)
      {
        const auto [a, b] = ends[order_[k]];
        if (path.nodes.empty())
        {
          // The first row's end that the second row does not share.
          const bool a_leads = k + 1 == chain_starts_[c + 1] ||
                               (ends[order_[k + 1]].first != a && ends[order_[k + 1]].second != a);
          path.nodes.push_back(a_leads ? a : b);
        }
        path.nodes.push_back(path.nodes.back() == a ? b : a);
        path.rows.push_back(k - swept_count_);
      }
      paths.push_back(std::move(path));
    }
    chain_contacts_.setPaths(model, std::move(paths));
    ordered_nodes_ = model.nodeCount();
  }

  /// The swept rows' ends and their coefficients' entries: one entry for each distinct kind (spring or
  /// constraint), rest length, stiffness or compliance, damping and sum of the ends' inverse masses, the
  /// values sweepRow makes a row's coefficients from, so that rows sharing an entry would have had the same
  /// coefficients bit for bit. Each entry keeps a row it was made from, to make it again for a new h.
  void tableRows(const Model& model, const std::vector<std::pair<int, int>>& ends)
  {
    const auto bits = [](double value) {
      std::uint64_t word;
      std::memcpy(&word, &value, sizeof word);
      return word;
    };
    struct WordsHash
    {
      std::size_t operator()(const std::array<std::uint64_t, 5>& words) const
      {
        std::uint64_t hash = 14695981039346656037ull;  // FNV-1a over the words
        for (const std::uint64_t word : words)
          hash = (hash ^ word) * 1099511628211ull;
        return static_cast<std::size_t>(hash);
      }
    };
    std::unordered_map<std::array<std::uint64_t, 5>, std::uint32_t, WordsHash> entries;
    coefficient_rows_.clear();
    swept_.resize(swept_count_);
    for (std::size_t k = 0; k < swept_count_; ++k)
    {
      const std::uint32_t r = order_[k];
      const auto [a, b] = ends[r];
      const double w = model.inverse_mass[a] + model.inverse_mass[b];
      std::array<std::uint64_t, 5> key;
      if (r < model.springs.size())
      {
        const Spring& s = model.springs[r];
        key = { 0, bits(s.rest_length), bits(s.stiffness), bits(s.damping), bits(w) };
      }
      else
      {
        const DistanceConstraint& c = model.constraints[r - model.springs.size()];
        key = { 1, bits(c.rest_length), bits(c.compliance), 0, bits(w) };
      }
      const auto [entry, added] = entries.try_emplace(key, static_cast<std::uint32_t>(coefficient_rows_.size()));
      if (added)
        coefficient_rows_.push_back(r);
      swept_[k] = SweptRow{ a, b, entry->second };
    }
    coefficient_rows_.shrink_to_fit();
    coefficients_.resize(coefficient_rows_.size());
  }

  /// The swept rows' coefficients and the chains' rows for a (sub)step of h [s].
  void makeCoefficients(const Model& model, double h)
  {
    const double inverse_h2 = 1.0 / (h * h);
    for (std::size_t e = 0; e < coefficients_.size(); ++e)
    {
      const SweepRow row = sweepRow(constraintRow(model, coefficient_rows_[e], h, inverse_h2), model.inverse_mass);
      coefficients_[e] = RowCoefficients{ row.rest_length, row.alpha_tilde, row.gamma, row.inverse_denominator };
    }
    for (std::size_t k = swept_count_; k < order_.size(); ++k)
      chain_rows_[k - swept_count_] = sweepRow(constraintRow(model, order_[k], h, inverse_h2), model.inverse_mass);
    rows_h_ = h;
  }

  /// Appends `rows` (row indices, in model order) to order_ grouped by a greedy edge colouring
  /// (edgeColourOrder), and keeps where each colour starts for the sweep (sweepColours). Gauss-Seidel in
  /// this order converges as fast as in model order (both are consistent orderings; for a chain, red-black
  /// and lexicographic have the same spectral radius).
  void colourRows(const Model& model, const std::vector<std::pair<int, int>>& ends,
                  const std::vector<std::uint32_t>& rows)
  {
    EdgeColouring colouring = edgeColourOrder(ends, rows, model.nodeCount());
    order_ = std::move(colouring.order);
    colour_starts_ = std::move(colouring.colour_starts);
    last_colour_shares_nodes_ = colouring.last_shares_nodes;
  }

  /// One Gauss-Seidel sweep over the swept rows, colour by colour. The rows of a colour share no node, so
  /// updating four (projectDistanceQuads, with AVX2) or two of them at once (projectDistancePair) is the
  /// same arithmetic in the same order as one by one: the same bits on every processor.
  void sweepColours(const Model& model, NodeArray& x)
  {
    const bool wide = hasWideLanes();
    for (std::size_t c = 0; c + 1 < colour_starts_.size(); ++c)
    {
      std::size_t k = colour_starts_[c];
      const std::size_t end = colour_starts_[c + 1];
      if (!(last_colour_shares_nodes_ && c + 2 == colour_starts_.size()))
      {
        if (wide)
          k = projectDistanceQuads(swept_.data(), k, end, coefficients_.data(), model.inverse_mass, previous_, x,
                                   lambda_.data());
        for (; k + 2 <= end; k += 2)
          projectDistancePair(&swept_[k], coefficients_.data(), model.inverse_mass, previous_, x, lambda_.data() + k);
      }
      for (; k < end; ++k)
        projectDistance(sweepRow(swept_[k], coefficients_[swept_[k].coefficients]), model.inverse_mass, previous_, x,
                        lambda_[static_cast<Eigen::Index>(k)]);
    }
  }

  void postSolve(const Model& model, State& state, double h)
  {
    // One division per sub-step, not three per node.
    const double inverse_h = 1.0 / h;
    for (int i = 0; i < model.nodeCount(); ++i)
      if (model.isFree(i))
        state.velocity.col(i) = (state.position.col(i) - previous_.col(i)) * inverse_h;
  }

  /// The chain solver's buffers for the longest chain of chain_starts_.
  void reserveChains()
  {
    std::size_t longest = 0;
    for (std::size_t c = 1; c < chain_starts_.size(); ++c)
      longest = std::max(longest, chain_starts_[c] - chain_starts_[c - 1]);
    chains_.reserve(longest);
  }

  NodeArray previous_;
  std::vector<std::uint32_t> order_;  ///< solve order of the rows (see orderRows)
  std::size_t swept_count_ = 0;       ///< order_[0, swept_count_) are swept by Gauss-Seidel
  std::vector<std::size_t> colour_starts_;  ///< the swept rows' colours (EdgeColouring::colour_starts)
  bool last_colour_shares_nodes_ = false;   ///< EdgeColouring::last_shares_nodes of the swept rows
  std::vector<std::size_t> chain_starts_;  ///< chain c is order_[chain_starts_[c], chain_starts_[c + 1])
  int ordered_nodes_ = -1;
  ChainSolver chains_;
  ChainContacts chain_contacts_;
  std::vector<std::uint8_t> chain_heavy_;  ///< per chain: 1 if heavy (RowPartition::chain_heavy)
  std::vector<std::uint8_t> swept_chain_;  ///< per chain: 1 once the chain solve refused it (solveChains)
  NodeArray predicted_;               ///< [m] the chains' nodes before their solve in this sub-step
  NodeArray correction_;              ///< [m] x - predicted_ after the last sub-step's solve (ChainSolver::solve)
  Eigen::VectorXd chain_tension_;     ///< [N] per chain row (chain_rows_): the chains' tensions at the last sub-step
  std::vector<SweptRow> swept_;       ///< the swept rows, order_[0, swept_count_)
  std::vector<RowCoefficients> coefficients_;  ///< the swept rows' entries (tableRows), valid for h = rows_h_
  std::vector<std::uint32_t> coefficient_rows_;  ///< per entry, a model row it was made from
  std::vector<SweepRow> chain_rows_;  ///< the chains' rows, order_[swept_count_, end), valid for h = rows_h_
  double rows_h_ = 0.0;               ///< [s]; 0 = coefficients not made
  bool reorder_ = false;              ///< the model changed: order and build the rows again
  Eigen::VectorXd lambda_;            ///< per row in solve order, the last sub-step's multipliers
  double solved_h_ = 0.0;             ///< [s] of the last sub-step solved; 0 = none yet
  Eigen::VectorXd cell_lambda_;
};
}  // namespace

std::unique_ptr<Integrator> makeXpbd() { return std::make_unique<Xpbd>(); }

}  // namespace soft_body_sim
