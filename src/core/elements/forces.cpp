#include "soft_body_sim/core/elements/forces.h"

#include "core/elements/column_packets.h"
#include "core/elements/edge_colouring.h"
#include "core/elements/element_kinds.h"
#include "core/elements/wide_columns.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <tuple>
#include <utility>

#include <Eigen/Geometry>

namespace soft_body_sim
{
namespace
{
/// The force on end a per unit of d = x_a - x_b, the Spring law with u = d / |d| taken as one division:
///   F_a = -(k (|d| - rest_length) + c (v_a - v_b) . d / |d|) / |d|  d.
/// `rate` is (v_a - v_b) . d [m^2/s] and `length` |d| [m]; T is a double or a Packet (the four-lane
/// kernel writes it out: a function not compiled for AVX2 may not return AVX2's packets).
template <typename T>
T forcePerLength(const T& length, const T& rate, const T& rest_length, const T& stiffness, const T& damping)
{
  const T inverse_length = 1.0 / length;
  return -(stiffness * (length - rest_length) + damping * rate * inverse_length) * inverse_length;
}
}  // namespace

SpringArrays springArrays(const Model& model)
{
  // Each spring by its ends' distance and lower end, so that a run's springs come one after another.
  struct Oriented
  {
    int distance, a;
    std::uint32_t spring;
  };
  std::vector<Oriented> oriented;
  for (std::size_t k = 0; k < model.springs.size(); ++k)
  {
    const Spring& s = model.springs[k];
    const int distance = std::abs(s.b - s.a);
    if (distance == 1 || distance == 2 || distance >= SpringArrays::kFarRun)
      oriented.push_back({ distance, std::min(s.a, s.b), static_cast<std::uint32_t>(k) });
  }
  std::sort(oriented.begin(), oriented.end(), [](const Oriented& p, const Oriented& q) {
    return std::tie(p.distance, p.a, p.spring) < std::tie(q.distance, q.a, q.spring);
  });
  // The runs as stretches of `oriented`, then ordered by their first node.
  std::vector<SpringRun> runs;
  std::vector<bool> in_run(model.springs.size(), false);
  for (std::size_t i = 0; i < oriented.size();)
  {
    std::size_t j = i + 1;
    while (j < oriented.size() && j - i < SpringArrays::kMostRun && oriented[j].distance == oriented[i].distance &&
           oriented[j].a == oriented[j - 1].a + 1)
      ++j;
    if (j - i >= SpringArrays::kLeastRun)
    {
      runs.push_back({ static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(j - i), oriented[i].a,
                       oriented[i].distance });
      for (std::size_t r = i; r < j; ++r)
        in_run[oriented[r].spring] = true;
    }
    i = j;
  }
  std::sort(runs.begin(), runs.end(), [](const SpringRun& p, const SpringRun& q) {
    return std::tie(p.a, p.distance) < std::tie(q.a, q.distance);
  });
  SpringArrays arrays;
  const auto add = [&](std::uint32_t k, int a, int b) {
    const Spring& s = model.springs[k];
    arrays.a.push_back(a);
    arrays.b.push_back(b);
    arrays.rest_length.push_back(s.rest_length);
    arrays.stiffness.push_back(s.stiffness);
    arrays.damping.push_back(s.damping);
  };
  for (SpringRun& run : runs)
  {
    const std::uint32_t first = run.start;
    run.start = static_cast<std::uint32_t>(arrays.size());
    for (std::uint32_t i = 0; i < run.count; ++i)
      add(oriented[first + i].spring, run.a + static_cast<int>(i), run.a + static_cast<int>(i) + run.distance);
  }
  arrays.runs = std::move(runs);
  arrays.run_springs = arrays.size();
  std::vector<std::pair<int, int>> ends;
  ends.reserve(model.springs.size());
  for (const Spring& s : model.springs)
    ends.emplace_back(s.a, s.b);
  std::vector<std::uint32_t> rows;
  for (std::size_t k = 0; k < model.springs.size(); ++k)
    if (!in_run[k])
      rows.push_back(static_cast<std::uint32_t>(k));
  for (const std::uint32_t k : edgeColourOrder(ends, rows, model.nodeCount()).order)
    add(k, model.springs[k].a, model.springs[k].b);
  return arrays;
}

namespace
{
/// Spring k's force on its end a as a run's lanes make it, by the same operations: zero where its ends
/// coincide.
Vec3 runSpringForce(const SpringArrays& springs, std::size_t k, const double* position, const double* velocity)
{
  const double* const x_a = position + 3 * static_cast<std::ptrdiff_t>(springs.a[k]);
  const double* const x_b = position + 3 * static_cast<std::ptrdiff_t>(springs.b[k]);
  const double* const v_a = velocity + 3 * static_cast<std::ptrdiff_t>(springs.a[k]);
  const double* const v_b = velocity + 3 * static_cast<std::ptrdiff_t>(springs.b[k]);
  const double dx = x_a[0] - x_b[0];
  const double dy = x_a[1] - x_b[1];
  const double dz = x_a[2] - x_b[2];
  const double rate = (v_a[0] - v_b[0]) * dx + (v_a[1] - v_b[1]) * dy + (v_a[2] - v_b[2]) * dz;
  const double length = std::sqrt(dx * dx + dy * dy + dz * dz);
  if (length < kMinSpringLength)
    return Vec3::Zero();
  const double per_length =
      forcePerLength(length, rate, springs.rest_length[k], springs.stiffness[k], springs.damping[k]);
  return Vec3(per_length * dx, per_length * dy, per_length * dz);
}

/// A run's springs from i on, one at a time, after the lanes: those of a run of distance 1 or 2 add to each
/// node a + m the difference F_m - F_(m - distance) of the forces of the two springs it ends (either 0 where
/// there is none; `before` holds F_(i - 2) and F_(i - 1)), the others F_m to a + m and -F_m to a + m +
/// distance, spring after spring: what the lanes do, so the same bits with four lanes, two or one.
void finishRun(const SpringArrays& springs, const SpringRun& run, std::uint32_t i, const Vec3 before[2],
               const double* position, const double* velocity, double* sum)
{
  const auto column = [&](std::uint32_t m) { return Eigen::Map<Vec3>(sum + 3 * (std::ptrdiff_t{ run.a } + m)); };
  if (run.distance > 2)
  {
    for (; i < run.count; ++i)
    {
      const Vec3 f = runSpringForce(springs, run.start + i, position, velocity);
      column(i) += f;
      column(i + static_cast<std::uint32_t>(run.distance)) -= f;
    }
    return;
  }
  Vec3 earlier[2] = { before[0], before[1] };  // F_(m - 2), F_(m - 1)
  for (std::uint32_t m = i; m < run.count + static_cast<std::uint32_t>(run.distance); ++m)
  {
    const Vec3 now = m < run.count ? runSpringForce(springs, run.start + m, position, velocity) : Vec3::Zero();
    column(m) += now - earlier[2 - run.distance];
    earlier[0] = earlier[1];
    earlier[1] = now;
  }
}

/// F_(m - distance) of each lane's node m, distance 1 or 2, from four springs' forces `now` and the four
/// before them, `last`.
SOFT_BODY_SIM_WIDE __m256d shiftedBy(int distance, __m256d last, __m256d now)
{
  return distance == 1 ? _mm256_permute4x64_pd(_mm256_blend_pd(now, last, 0b1000), 0b10010011)  // last3 now0 now1 now2
                       : _mm256_permute2f128_pd(last, now, 0x21);                               // last2 last3 now0 now1
}

/// The runs (AVX2; hasWideLanes), four springs at a time: each end's four nodes by three loads, their forces
/// added by three stores; on a run of distance 1 or 2 each node's two forces summed in the lanes first, so
/// that consecutive springs' stores never meet.
[[gnu::target("avx2")]] void accumulateRuns4(const SpringArrays& springs, const double* position,
                                             const double* velocity, double* sum)
{
  const __m256d least = _mm256_set1_pd(kMinSpringLength);
  for (const SpringRun& run : springs.runs)
  {
    const std::ptrdiff_t to_b = 3 * std::ptrdiff_t{ run.distance };
    __m256d last_x = _mm256_setzero_pd(), last_y = last_x, last_z = last_x;  // the previous four's forces
    std::uint32_t i = 0;
    for (; i + 4 <= run.count; i += 4)
    {
      const std::ptrdiff_t at = 3 * (std::ptrdiff_t{ run.a } + i);
      const std::size_t k = run.start + i;
      const ColumnQuad x_a = loadRun4(position + at);
      const ColumnQuad x_b = loadRun4(position + at + to_b);
      const ColumnQuad v_a = loadRun4(velocity + at);
      const ColumnQuad v_b = loadRun4(velocity + at + to_b);
      const __m256d dx = x_a.x - x_b.x;
      const __m256d dy = x_a.y - x_b.y;
      const __m256d dz = x_a.z - x_b.z;
      const __m256d rate = (v_a.x - v_b.x) * dx + (v_a.y - v_b.y) * dy + (v_a.z - v_b.z) * dz;
      const __m256d length = _mm256_sqrt_pd(dx * dx + dy * dy + dz * dz);
      // forcePerLength, lane by lane; zero where the ends coincide (not less than kMinSpringLength: NaN on)
      const __m256d rest_length = _mm256_loadu_pd(&springs.rest_length[k]);
      const __m256d stiffness = _mm256_loadu_pd(&springs.stiffness[k]);
      const __m256d damping = _mm256_loadu_pd(&springs.damping[k]);
      const __m256d inverse_length = 1.0 / length;
      const __m256d per_length = -(stiffness * (length - rest_length) + damping * rate * inverse_length) * inverse_length;
      const __m256d apart = _mm256_cmp_pd(length, least, _CMP_NLT_UQ);
      const __m256d f_x = _mm256_and_pd(apart, per_length * dx);
      const __m256d f_y = _mm256_and_pd(apart, per_length * dy);
      const __m256d f_z = _mm256_and_pd(apart, per_length * dz);
      if (run.distance > 2)
      {
        addToRun4<1>(sum + at, f_x, f_y, f_z);
        addToRun4<-1>(sum + at + to_b, f_x, f_y, f_z);
        continue;
      }
      addToRun4<1>(sum + at, f_x - shiftedBy(run.distance, last_x, f_x), f_y - shiftedBy(run.distance, last_y, f_y),
                   f_z - shiftedBy(run.distance, last_z, f_z));
      last_x = f_x;
      last_y = f_y;
      last_z = f_z;
    }
    alignas(32) double last[3][4];
    _mm256_store_pd(last[0], last_x);
    _mm256_store_pd(last[1], last_y);
    _mm256_store_pd(last[2], last_z);
    const Vec3 before[2] = { Vec3(last[0][2], last[1][2], last[2][2]), Vec3(last[0][3], last[1][3], last[2][3]) };
    finishRun(springs, run, i, before, position, velocity, sum);
  }
}

/// The runs two springs at a time (SSE2), as accumulateRuns4.
void accumulateRuns2(const SpringArrays& springs, const double* position, const double* velocity, double* sum)
{
  const Packet least = Eigen::internal::pset1<Packet>(kMinSpringLength);
  for (const SpringRun& run : springs.runs)
  {
    const std::ptrdiff_t to_b = 3 * std::ptrdiff_t{ run.distance };
    Packet last_x = Eigen::internal::pset1<Packet>(0.0), last_y = last_x, last_z = last_x;
    std::uint32_t i = 0;
    for (; i + 2 <= run.count; i += 2)
    {
      const std::ptrdiff_t at = 3 * (std::ptrdiff_t{ run.a } + i);
      const std::size_t k = run.start + i;
      const ColumnPair x_a = loadRun2(position + at);
      const ColumnPair x_b = loadRun2(position + at + to_b);
      const ColumnPair v_a = loadRun2(velocity + at);
      const ColumnPair v_b = loadRun2(velocity + at + to_b);
      const Packet dx = x_a.x - x_b.x;
      const Packet dy = x_a.y - x_b.y;
      const Packet dz = x_a.z - x_b.z;
      const Packet rate = (v_a.x - v_b.x) * dx + (v_a.y - v_b.y) * dy + (v_a.z - v_b.z) * dz;
      const Packet length = Eigen::internal::psqrt(dx * dx + dy * dy + dz * dz);
      const Packet per_length =
          forcePerLength(length, rate, Eigen::internal::ploadu<Packet>(&springs.rest_length[k]),
                         Eigen::internal::ploadu<Packet>(&springs.stiffness[k]),
                         Eigen::internal::ploadu<Packet>(&springs.damping[k]));
      const Packet apart = _mm_cmpnlt_pd(length, least);
      const Packet f_x = _mm_and_pd(apart, per_length * dx);
      const Packet f_y = _mm_and_pd(apart, per_length * dy);
      const Packet f_z = _mm_and_pd(apart, per_length * dz);
      if (run.distance > 2)
      {
        addToRun2<1>(sum + at, f_x, f_y, f_z);
        addToRun2<-1>(sum + at + to_b, f_x, f_y, f_z);
        continue;
      }
      const auto shifted = [&](const Packet& last, const Packet& now) {
        return run.distance == 1 ? _mm_shuffle_pd(last, now, 0b01) : last;  // (last1, now0) or (last0, last1)
      };
      addToRun2<1>(sum + at, f_x - shifted(last_x, f_x), f_y - shifted(last_y, f_y), f_z - shifted(last_z, f_z));
      last_x = f_x;
      last_y = f_y;
      last_z = f_z;
    }
    alignas(16) double last[3][2];
    Eigen::internal::pstore(last[0], last_x);
    Eigen::internal::pstore(last[1], last_y);
    Eigen::internal::pstore(last[2], last_z);
    const Vec3 before[2] = { Vec3(last[0][0], last[1][0], last[2][0]), Vec3(last[0][1], last[1][1], last[2][1]) };
    finishRun(springs, run, i, before, position, velocity, sum);
  }
}

/// accumulateSpringForces' springs after the runs, four at a time from `first` (AVX2; hasWideLanes): returns
/// where it stopped. The scatters go lane by lane in the springs' order, as the two-lane loop's.
[[gnu::target("avx2")]] std::size_t accumulateSpringForces4(const SpringArrays& springs, std::size_t first,
                                                            const double* position, const double* velocity,
                                                            double* sum)
{
  const std::size_t count = springs.size();
  std::size_t k = first;
  for (; k + 4 <= count; k += 4)
  {
    const std::ptrdiff_t a[4] = { springs.a[k], springs.a[k + 1], springs.a[k + 2], springs.a[k + 3] };
    const std::ptrdiff_t b[4] = { springs.b[k], springs.b[k + 1], springs.b[k + 2], springs.b[k + 3] };
    const ColumnQuad x_a = loadColumns4(position, a);
    const ColumnQuad x_b = loadColumns4(position, b);
    const ColumnQuad v_a = loadColumns4(velocity, a);
    const ColumnQuad v_b = loadColumns4(velocity, b);
    const __m256d dx = x_a.x - x_b.x;
    const __m256d dy = x_a.y - x_b.y;
    const __m256d dz = x_a.z - x_b.z;
    const __m256d rate = (v_a.x - v_b.x) * dx + (v_a.y - v_b.y) * dy + (v_a.z - v_b.z) * dz;
    const __m256d length = _mm256_sqrt_pd(dx * dx + dy * dy + dz * dz);
    // forcePerLength, lane by lane.
    const __m256d rest_length = _mm256_loadu_pd(&springs.rest_length[k]);
    const __m256d stiffness = _mm256_loadu_pd(&springs.stiffness[k]);
    const __m256d damping = _mm256_loadu_pd(&springs.damping[k]);
    const __m256d inverse_length = 1.0 / length;
    const __m256d per_length = -(stiffness * (length - rest_length) + damping * rate * inverse_length) * inverse_length;
    __m128d f_xy[4];
    lanePairs(per_length * dx, per_length * dy, f_xy);
    alignas(32) double f_z[4];
    alignas(32) double lengths[4];
    _mm256_store_pd(f_z, per_length * dz);
    _mm256_store_pd(lengths, length);
    for (int l = 0; l < 4; ++l)
    {
      if (lengths[l] < kMinSpringLength)
        continue;  // coincident nodes: the direction is undefined
      addToColumn(sum, a[l], f_xy[l], f_z[l]);
      subtractFromColumn(sum, b[l], f_xy[l], f_z[l]);
    }
  }
  return k;
}
}  // namespace

void accumulateSpringForces(const SpringArrays& springs, const NodeArray& x, const NodeArray& v, NodeArray& force)
{
  // The columns through plain pointers: a store through force.col() may alias force's own data pointer,
  // which the compiler would load again after every store.
  const double* const position = x.data();
  const double* const velocity = v.data();
  double* const sum = force.data();
  const std::size_t count = springs.size();
  std::size_t k = springs.run_springs;
  if (hasWideLanes())
  {
    accumulateRuns4(springs, position, velocity, sum);
    k = accumulateSpringForces4(springs, k, position, velocity, sum);
  }
  else
    accumulateRuns2(springs, position, velocity, sum);
  // Two springs at once (Packet); their scatters go lane by lane, so that a pair across two colours that
  // shares a node still adds both forces to it.
  for (; k + 2 <= count; k += 2)
  {
    const std::ptrdiff_t a[2] = { springs.a[k], springs.a[k + 1] };
    const std::ptrdiff_t b[2] = { springs.b[k], springs.b[k + 1] };
    const ColumnPair x_a = loadColumns(position, a[0], a[1]);
    const ColumnPair x_b = loadColumns(position, b[0], b[1]);
    const ColumnPair v_a = loadColumns(velocity, a[0], a[1]);
    const ColumnPair v_b = loadColumns(velocity, b[0], b[1]);
    const Packet dx = x_a.x - x_b.x;
    const Packet dy = x_a.y - x_b.y;
    const Packet dz = x_a.z - x_b.z;
    const Packet rate = (v_a.x - v_b.x) * dx + (v_a.y - v_b.y) * dy + (v_a.z - v_b.z) * dz;
    const Packet length = Eigen::internal::psqrt(dx * dx + dy * dy + dz * dz);
    const Packet per_length =
        forcePerLength(length, rate, Eigen::internal::ploadu<Packet>(&springs.rest_length[k]),
                       Eigen::internal::ploadu<Packet>(&springs.stiffness[k]),
                       Eigen::internal::ploadu<Packet>(&springs.damping[k]));
    const Packet f_x = per_length * dx;
    const Packet f_y = per_length * dy;
    // (f_x, f_y) of each spring
    const Packet f_xy[2] = { Eigen::internal::vec2d_unpacklo(f_x, f_y), Eigen::internal::vec2d_unpackhi(f_x, f_y) };
    alignas(16) double f_z[2];
    alignas(16) double lengths[2];
    Eigen::internal::pstore(f_z, per_length * dz);
    Eigen::internal::pstore(lengths, length);
    for (int l = 0; l < 2; ++l)
    {
      if (lengths[l] < kMinSpringLength)
        continue;  // coincident nodes: the direction is undefined
      addToColumn(sum, a[l], f_xy[l], f_z[l]);
      subtractFromColumn(sum, b[l], f_xy[l], f_z[l]);
    }
  }
  for (; k < count; ++k)
  {
    const int a = springs.a[k];
    const int b = springs.b[k];
    const Vec3 d = x.col(a) - x.col(b);
    const double length = std::sqrt(d.x() * d.x() + d.y() * d.y() + d.z() * d.z());
    if (length < kMinSpringLength)
      continue;
    const Vec3 dv = v.col(a) - v.col(b);
    const double rate = dv.x() * d.x() + dv.y() * d.y() + dv.z() * d.z();
    const Vec3 f =
        forcePerLength(length, rate, springs.rest_length[k], springs.stiffness[k], springs.damping[k]) * d;
    force.col(a) += f;
    force.col(b) -= f;
  }
}

double cellArea(const PressureCell& cell, const NodeArray& x, Vec3* gradient)
{
  const Vec3 diagonal_02 = x.col(cell.nodes[2]) - x.col(cell.nodes[0]);
  const Vec3 diagonal_13 = x.col(cell.nodes[3]) - x.col(cell.nodes[1]);
  if (gradient)
  {
    gradient[0] = -0.5 * diagonal_13.cross(cell.normal);
    gradient[1] = -0.5 * cell.normal.cross(diagonal_02);
    gradient[2] = -gradient[0];
    gradient[3] = -gradient[1];
  }
  return 0.5 * cell.normal.dot(diagonal_02.cross(diagonal_13));
}

BoyleGas boyleGas(double a)
{
  if (a >= kCellBarrierArea)
    return { a - 1.0 - std::log(a), 1.0 - 1.0 / a, 1.0 / (a * a) };
  const double a_c = kCellBarrierArea;
  const double slope = 1.0 - 1.0 / a_c;        // E'(a_c), < 0
  const double curvature = 1.0 / (a_c * a_c);  // E''(a_c)
  const double da = a - a_c;
  return { (a_c - 1.0 - std::log(a_c)) + slope * da + 0.5 * curvature * da * da, slope + curvature * da, curvature };
}

CellGas cellGas(const PressureCell& cell, double area)
{
  if (!(cell.rest_area > 0.0) || !(cell.pressure > 0.0))
    return { 0.0, 0.0, 0.0 };  // no gas (buildWorld never makes such a cell)
  const double p0 = cell.pressure;
  const BoyleGas gas = boyleGas(area / cell.rest_area);
  return { p0 * cell.rest_area * gas.energy, -p0 * gas.slope, p0 * gas.curvature / cell.rest_area };
}

void accumulatePressureForces(const Model& model, const NodeArray& x, NodeArray& force)
{
  Vec3 gradient[4];
  for (const PressureCell& cell : model.cells)
  {
    const double pressure = cellGas(cell, cellArea(cell, x, gradient)).pressure;
    for (int k = 0; k < 4; ++k)
      force.col(cell.nodes[k]) += pressure * gradient[k];
  }
}

void computeAccelerations(const Model& model, const SpringArrays& springs, const NodeArray& x, const NodeArray& v,
                          NodeArray& force, NodeArray& acceleration)
{
  force.setZero(3, x.cols());
  accumulateSpringForces(springs, x, v, force);
  if (!model.cells.empty())
    accumulatePressureForces(model, x, force);
  acceleration.resize(3, x.cols());
  for (int i = 0; i < model.nodeCount(); ++i)
  {
    if (model.isFree(i))
      acceleration.col(i) = model.gravity + model.inverse_mass[i] * force.col(i) - model.drag * v.col(i);
    else
      acceleration.col(i).setZero();
  }
}

double kineticEnergy(const Model& model, const State& state)
{
  double energy = 0.0;
  for (int i = 0; i < model.nodeCount(); ++i)
    if (model.isFree(i))
      energy += 0.5 * model.mass[i] * state.velocity.col(i).squaredNorm();
  return energy;
}

double potentialEnergy(const Model& model, const State& state)
{
  double energy = 0.0;
  forEachKind([&](auto kind) {
    for (const auto& element : kind.of(model))
      energy += kind.energy(element, state);
  });
  for (int i = 0; i < model.nodeCount(); ++i)
    if (model.isFree(i))
      energy -= model.mass[i] * model.gravity.dot(state.position.col(i));
  return energy;
}

double maxStrain(const Model& model, const State& state)
{
  const NodeArray& x = state.position;
  double strain = 0.0;
  const auto stretch = [&](int a, int b, double rest) {
    if (!(rest > 0.0))
      return;
    const double s = std::abs((x.col(a) - x.col(b)).norm() - rest) / rest;
    // A NaN would be dropped by std::max: a length that is not finite is an infinite strain.
    strain = std::isnan(s) ? std::numeric_limits<double>::infinity() : std::max(strain, s);
  };
  for (const Spring& s : model.springs)
    stretch(s.a, s.b, s.rest_length);
  for (const DistanceConstraint& c : model.constraints)
    stretch(c.a, c.b, c.rest_length);
  return strain;
}

}  // namespace soft_body_sim
