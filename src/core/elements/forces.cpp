#include "soft_body_sim/core/elements/forces.h"

#include "core/elements/column_packets.h"
#include "core/elements/edge_colouring.h"
#include "core/elements/element_kinds.h"
#include "core/elements/wide_columns.h"

#include <algorithm>
#include <cmath>
#include <limits>
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
  std::vector<std::pair<int, int>> ends;
  ends.reserve(model.springs.size());
  for (const Spring& s : model.springs)
    ends.emplace_back(s.a, s.b);
  std::vector<std::uint32_t> rows(model.springs.size());
  for (std::size_t k = 0; k < rows.size(); ++k)
    rows[k] = static_cast<std::uint32_t>(k);
  SpringArrays arrays;
  for (const std::uint32_t k : edgeColourOrder(ends, rows, model.nodeCount()).order)
  {
    const Spring& s = model.springs[k];
    arrays.a.push_back(s.a);
    arrays.b.push_back(s.b);
    arrays.rest_length.push_back(s.rest_length);
    arrays.stiffness.push_back(s.stiffness);
    arrays.damping.push_back(s.damping);
  }
  return arrays;
}

namespace
{
/// accumulateSpringForces' springs [0, 4 n) four at a time (AVX2; hasWideLanes): returns 4 n, the springs it
/// did. The scatters go lane by lane in the springs' order, as the two-lane loop's.
[[gnu::target("avx2")]] std::size_t accumulateSpringForces4(const SpringArrays& springs, const double* position,
                                                            const double* velocity, double* sum)
{
  const std::size_t count = springs.size();
  std::size_t k = 0;
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
  std::size_t k = hasWideLanes() ? accumulateSpringForces4(springs, position, velocity, sum) : 0;
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
