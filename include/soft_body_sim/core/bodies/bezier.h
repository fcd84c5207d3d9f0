// Quadratic Bezier curves (verlet-bezier-limbs.txt: a limb's root, joint and leaf are the control
// points of the curve that draws it). Header-only: three small formulas.
#pragma once

#include <vector>

#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
/// The point at parameter t in [0, 1] of the quadratic Bezier curve with control points p1, p2, p3 [m]:
///   B(t) = (1 - t)^2 p1 + 2 (1 - t) t p2 + t^2 p3
/// (the seed's zb_quadratic_get). B(0) = p1 and B(1) = p3; the curve does not pass through p2.
inline Vec3 quadraticBezier(const Vec3& p1, const Vec3& p2, const Vec3& p3, double t)
{
  const double u = 1.0 - t;
  return (u * u) * p1 + (2.0 * u * t) * p2 + (t * t) * p3;
}

/// The derivative dB/dt [m per unit t] of the curve above (the seed's zb_quadratic_get_deriv):
///   B'(t) = 2 (1 - t) (p2 - p1) + 2 t (p3 - p2)
/// B'(0) = 2 (p2 - p1) and B'(1) = 2 (p3 - p2): the curve leaves p1 toward p2 and arrives at p3 from p2.
inline Vec3 quadraticBezierTangent(const Vec3& p1, const Vec3& p2, const Vec3& p3, double t)
{
  return (2.0 * (1.0 - t)) * (p2 - p1) + (2.0 * t) * (p3 - p2);
}

/// The curve sampled at t_i = i / (samples - 1), i = 0 .. samples - 1 (so both ends are included) [m];
/// `samples` below 2 is taken as 2. (Its tangents, where needed, are quadraticBezierTangent at the same t.)
inline std::vector<Vec3> sampleQuadraticBezier(const Vec3& p1, const Vec3& p2, const Vec3& p3, int samples)
{
  const int n = samples < 2 ? 2 : samples;
  std::vector<Vec3> points;
  points.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i)
    points.push_back(quadraticBezier(p1, p2, p3, static_cast<double>(i) / (n - 1)));
  return points;
}

}  // namespace soft_body_sim
