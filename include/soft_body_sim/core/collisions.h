// Contact with the scene's planes (walls and floors).
#pragma once

#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
/// Pushes every free node that is behind a plane back onto it and, if it was moving into the plane,
/// reflects its normal velocity with the plane's restitution and slows its tangential velocity by
/// Coulomb friction (by at most friction * the normal speed change, never reversing it).
/// A plane is a half-space, so a fast node cannot tunnel through it. Approach speeds below
/// `resting_speed` [m/s] do not bounce: a node resting on a floor gains ~g h per step and must not
/// jitter. Returns true if any node was touched.
bool collideWithPlanes(const Model& model, State& state, double resting_speed);

}  // namespace soft_body_sim
