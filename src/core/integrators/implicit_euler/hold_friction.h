// What implicit Euler's contact holds share (collider_holds.h, surface_holds.h; private to the core library):
// their stiffness relative to the nodes they hold, and Coulomb friction as a damping of their slip.
#pragma once

#include <algorithm>

#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
/// A hold's stiffness relative to its node's diagonal block: h^2 k = kContactStiffness b, so that the solve
/// leaves about 1 / kContactStiffness of the depth.
constexpr double kContactStiffness = 1000.0;

/// [m/s] below this tangential speed a hold sticks (its friction's damping no longer grows).
constexpr double kStickSpeed = 1e-4;

/// Coulomb friction of a hold as a damping of its slip: the part v_t of the `relative` velocity across n into
/// `tangential`, and c = friction N / max(|v_t|, kStickSpeed) [kg/s], 0 without friction or without a
/// pressing force N. The hold's row gains -h c v_t, its block h c (I - n n^T). Sliding (h c << b) it takes
/// friction N h / b of the tangential speed v_t, as Coulomb's law; where that is more than v_t (h c >> b)
/// the node sticks.
inline double frictionDamping(double friction, double normal_force, const Vec3& relative, const Vec3& n, Vec3& tangential)
{
  tangential = relative - relative.dot(n) * n;
  if (!(friction > 0.0 && normal_force > 0.0))
    return 0.0;
  return friction * normal_force / std::max(tangential.norm(), kStickSpeed);
}

}  // namespace soft_body_sim
