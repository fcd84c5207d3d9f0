#include "soft_body_sim/core/elements/forces.h"

#include "core/elements/edge_colouring.h"
#include "core/elements/element_kinds.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <Eigen/Geometry>

namespace soft_body_sim
{
namespace
{
/// Springs updated at once: their arithmetic in Eigen's packets (two doubles each in SSE2), their
/// gathers and scatters one by one.
constexpr int kLanes = 4;
using Lanes = Eigen::Array<double, kLanes, 1>;

/// The force on end a per unit of d = x_a - x_b, the Spring law with u = d / |d| taken as one division:
///   F_a = -(k (|d| - rest_length) + c (v_a - v_b) . d / |d|) / |d|  d.
/// `rate` is (v_a - v_b) . d [m^2/s] and `length` |d| [m]; T is a double or Lanes.
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

void accumulateSpringForces(const SpringArrays& springs, const NodeArray& x, const NodeArray& v, NodeArray& force)
{
  // The columns through plain pointers: a store through force.col() may alias force's own data pointer,
  // which the compiler would load again after every store.
  const double* const position = x.data();
  const double* const velocity = v.data();
  double* const sum = force.data();
  const std::size_t count = springs.size();
  std::size_t k = 0;
  for (; k + kLanes <= count; k += kLanes)
  {
    Lanes dx, dy, dz, rate;
    for (int l = 0; l < kLanes; ++l)
    {
      const std::ptrdiff_t a = 3 * static_cast<std::ptrdiff_t>(springs.a[k + l]);
      const std::ptrdiff_t b = 3 * static_cast<std::ptrdiff_t>(springs.b[k + l]);
      dx[l] = position[a] - position[b];
      dy[l] = position[a + 1] - position[b + 1];
      dz[l] = position[a + 2] - position[b + 2];
      rate[l] = (velocity[a] - velocity[b]) * dx[l] + (velocity[a + 1] - velocity[b + 1]) * dy[l] +
                (velocity[a + 2] - velocity[b + 2]) * dz[l];
    }
    const Lanes length = (dx * dx + dy * dy + dz * dz).sqrt();
    const Lanes per_length = forcePerLength<Lanes>(length, rate, Eigen::Map<const Lanes>(&springs.rest_length[k]),
                                                   Eigen::Map<const Lanes>(&springs.stiffness[k]),
                                                   Eigen::Map<const Lanes>(&springs.damping[k]));
    for (int l = 0; l < kLanes; ++l)
    {
      if (length[l] < kMinSpringLength)
        continue;  // coincident nodes: the direction is undefined
      const std::ptrdiff_t a = 3 * static_cast<std::ptrdiff_t>(springs.a[k + l]);
      const std::ptrdiff_t b = 3 * static_cast<std::ptrdiff_t>(springs.b[k + l]);
      const double fx = per_length[l] * dx[l];
      const double fy = per_length[l] * dy[l];
      const double fz = per_length[l] * dz[l];
      sum[a] += fx;
      sum[a + 1] += fy;
      sum[a + 2] += fz;
      sum[b] -= fx;
      sum[b + 1] -= fy;
      sum[b + 2] -= fz;
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
