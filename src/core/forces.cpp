#include "soft_body_sim/core/forces.h"

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
    const double closing_speed = (v.col(s.a) - v.col(s.b)).dot(u);
    const Vec3 f = (-s.stiffness * (length - s.rest_length) - s.damping * closing_speed) * u;
    force.col(s.a) += f;
    force.col(s.b) -= f;
  }
}

void computeAccelerations(const Model& model, const NodeArray& x, const NodeArray& v, NodeArray& force,
                          NodeArray& acceleration)
{
  force.setZero(3, x.cols());
  accumulateSpringForces(model, x, v, force);
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
  for (const Spring& s : model.springs)
  {
    const double stretch = (state.position.col(s.a) - state.position.col(s.b)).norm() - s.rest_length;
    energy += 0.5 * s.stiffness * stretch * stretch;
  }
  for (int i = 0; i < model.nodeCount(); ++i)
    if (model.isFree(i))
      energy -= model.mass[i] * model.gravity.dot(state.position.col(i));
  return energy;
}

}  // namespace soft_body_sim
