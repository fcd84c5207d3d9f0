#include "soft_body_sim/core/elements/forces.h"

#include "core/elements/element_kinds.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Geometry>

namespace soft_body_sim
{
void accumulateSpringForces(const Model& model, const NodeArray& x, const NodeArray& v, NodeArray& force)
{
  for (const Spring& s : model.springs)
  {
    Vec3 u;
    double length;
    if (!springAxis(x, s.a, s.b, u, length))
      continue;
    const Vec3 f = -springTension(s, u, length, v) * u;
    force.col(s.a) += f;
    force.col(s.b) -= f;
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

void computeAccelerations(const Model& model, const NodeArray& x, const NodeArray& v, NodeArray& force,
                          NodeArray& acceleration)
{
  force.setZero(3, x.cols());
  accumulateSpringForces(model, x, v, force);
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
