// How a node leaves a surface it has gone behind: shared by every kind of collider. Private to the core.
#pragma once

#include <algorithm>

#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
/// A surface at one contact: its outward unit normal, its velocity at the contact point and its material.
struct ContactSurface
{
  Vec3 normal;
  Vec3 velocity;             ///< [m/s] of the surface point (0 for a fixed collider)
  double friction = 0.0;     ///< Coulomb coefficient [-]
  double restitution = 0.0;  ///< [0, 1]
};

/// The approach speed [m/s] at or below which a node's contact is no impact (it does not bounce), for
/// gravity `gravity` [m/s^2] and a sub-step of h [s]: a node resting on a surface approaches it by ~|g| h
/// per sub-step; twice that does not bounce.
inline double restingSpeed(const Vec3& gravity, double h) { return 2.0 * gravity.norm() * h; }

/// A node `depth` [m] (> 0) behind `surface` after a sub-step of h [s] that moved it by `displacement`
/// [m]: it moves out along the normal and, if it was approaching the surface, loses its approach speed
/// (bouncing with the restitution on an `impact`), and Coulomb friction acts relative to the surface at
/// both levels: the sub-step's tangential displacement relative to the surface is cancelled up to
/// friction * depth (static friction: a node resting on a slope with tan(theta) < friction stays put,
/// since gravity pushes it in and along the slope in the ratio cos(theta) : sin(theta)), and the
/// tangential speed is reduced by friction * the normal speed change, never reversed.
inline void leaveSurface(const ContactSurface& surface, double depth, bool impact, double h, const Vec3& displacement,
                         Eigen::Ref<Vec3> x, Eigen::Ref<Vec3> v)
{
  x += depth * surface.normal;
  const Vec3 relative = v - surface.velocity;
  const double normal_speed = relative.dot(surface.normal);
  if (normal_speed >= 0.0)
    return;
  const double bounce_speed = impact ? -surface.restitution * normal_speed : 0.0;
  if (surface.friction > 0.0)
  {
    const Vec3 moved = displacement - h * surface.velocity;
    const Vec3 slid = moved - moved.dot(surface.normal) * surface.normal;
    const double slid_length = slid.norm();
    if (slid_length > 0.0)
      x -= std::min(1.0, surface.friction * depth / slid_length) * slid;
  }
  Vec3 tangential = relative - normal_speed * surface.normal;
  const double tangential_speed = tangential.norm();
  const double friction_loss = surface.friction * (bounce_speed - normal_speed);
  if (tangential_speed > 0.0)
    tangential *= std::max(0.0, 1.0 - friction_loss / tangential_speed);
  v = surface.velocity + tangential + bounce_speed * surface.normal;
}

}  // namespace soft_body_sim
