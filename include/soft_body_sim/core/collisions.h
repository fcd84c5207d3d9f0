// Contact with the scene's planes (walls and floors).
#pragma once

#include <cstdint>
#include <vector>

#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
/// Pushes every free node that is behind a plane back onto it and, if it was moving into the plane,
/// takes away its normal velocity, slows its tangential velocity by Coulomb friction (by at most
/// friction * the normal speed change, never reversing it) and, on a new impact, bounces it with the
/// plane's restitution. A plane is a half-space, so a fast node cannot tunnel through it.
/// An impact is new when the node did not touch any plane in the previous sub-step (`touching`, one
/// flag per node, updated here) and approaches faster than `resting_speed` [m/s]: a node resting on a
/// floor, alone or under the weight of others, gains approach speed every step and must not jitter.
/// Returns true if any node was touched.
bool collideWithPlanes(const Model& model, State& state, double resting_speed, std::vector<std::uint8_t>& touching);

}  // namespace soft_body_sim
