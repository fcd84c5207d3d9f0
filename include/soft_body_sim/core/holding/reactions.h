// What the bodies exert on what holds them (anchors, grasps): forces from the links' tensions and the
// cells' pressures (Integrator::internalForces), the readout a user plots to see how taut a cable is.
#pragma once

#include <vector>

#include "soft_body_sim/core/integrators/integrator.h"
#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
/// A force [N] and a torque [N m] about a stated point.
struct Wrench
{
  Vec3 force = Vec3::Zero();
  Vec3 torque = Vec3::Zero();
};

/// Per node, the sum of the internal forces on it [N] (3 x nodes), every element kind's: a link of tension T
/// pulls its end a toward b with T (x_b - x_a) / |x_b - x_a|, and b toward a likewise; a cell of pressure p
/// pushes its corner k with p dA/dx_k (cellArea); rods and tetrahedra pull with their forces at the state.
void internalPulls(const Model& model, const State& state, const InternalForces& forces, NodeArray& pull);

/// The wrench that a body exerts on whatever holds its nodes `nodes` in place, torque about `origin` [m]:
/// on each held node the pull of its links and cells (internalPulls) plus its weight m g, which the holder
/// carries.
/// At rest this is what a force sensor at the holder reads; while the holder accelerates, the held nodes'
/// own inertia (their mass times its acceleration) is left out.
Wrench holdingWrench(const Model& model, const NodeArray& x, const NodeArray& pull, const std::vector<int>& nodes,
                     const Vec3& origin);

}  // namespace soft_body_sim
