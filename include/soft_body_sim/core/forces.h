// Force and energy kernels shared by every force-based integrator.
#pragma once

#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
/// Below this spring length [m] the spring direction is undefined and the spring exerts no force
/// (coincident nodes must not produce NaN).
constexpr double kMinSpringLength = 1e-12;

/// Length [m] and unit direction u = d / |d| of d = x_a - x_b; false when the nodes (nearly) coincide
/// and the direction is undefined, in which case the caller skips the pair.
inline bool springAxis(const NodeArray& x, int a, int b, Vec3& u, double& length)
{
  const Vec3 d = x.col(a) - x.col(b);
  length = d.norm();
  if (length < kMinSpringLength)
    return false;
  u = d / length;
  return true;
}

/// Adds every spring's Hooke + dashpot force [N] to `force` (see Spring).
void accumulateSpringForces(const Model& model, const NodeArray& x, const NodeArray& v, NodeArray& force);

/// a(x, v) [m/s^2] of the model: gravity + F/m - drag v on free nodes, 0 on pinned ones.
/// `force` is caller-owned scratch space so that the hot loop never allocates.
void computeAccelerations(const Model& model, const NodeArray& x, const NodeArray& v, NodeArray& force,
                          NodeArray& acceleration);

/// Kinetic [J] of the free nodes.
double kineticEnergy(const Model& model, const State& state);
/// Potential [J]: elastic energy of the springs plus gravitational energy -m g.x of the free nodes.
double potentialEnergy(const Model& model, const State& state);

}  // namespace soft_body_sim
