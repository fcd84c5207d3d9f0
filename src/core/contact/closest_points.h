// The closest points of two segments: shared by a link's contact with a capsule (shape_contacts.h), by
// two links' contact with each other (self_contacts.cpp) and by two solids' edges (surface_contacts.cpp).
// Private to the core.
#pragma once

#include <algorithm>
#include <utility>

#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
/// Two links within ~10 degrees of parallel (sin^2 of the angle between them below this) meet at the
/// nearest of their ends to the other link (closestSegmentParameters; self_contacts.cpp, and two solids'
/// edges in surface_contacts.cpp). A link lying along another (a rope in a groove, on a rope) then meets
/// it at one of its nodes, each node pushed out by its own depth: a point inside the link (where the nearly
/// parallel lines come closest, ill-conditioned) would push both nodes by the depth there, throwing out one
/// that a neighbouring link had already freed, and that node, off the surface, would slip with no friction
/// holding it.
constexpr double kNearParallelSine2 = 0.03;

/// The parameters s, t in [0, 1] of the nearest points p0 + s d1 and q0 + t d2 of two segments (Ericson,
/// Real-Time Collision Detection, 5.1.9): s minimises the distance between the lines, clamped to the first
/// segment; t is the second's parameter nearest to that point, and if it leaves [0, 1] it is clamped and s
/// recomputed for the clamped end. A segment of zero length is its first point.
/// Segments within `parallel_sine2` (sin^2 of the angle between them, 0: none) of parallel, whose lines
/// come closest at an ill-conditioned point, meet at the nearest of each one's ends to the other segment
/// instead; with 0, exactly parallel ones (a * e - b^2 <= 0) take s = 0, as Ericson does. `by_ends`, if
/// given, tells whether that rule chose the points (they are then no nearer than the segments' nearest).
inline std::pair<double, double> closestSegmentParameters(const Vec3& p0, const Vec3& d1, const Vec3& q0,
                                                           const Vec3& d2, double parallel_sine2 = 0.0,
                                                           bool* by_ends = nullptr)
{
  if (by_ends != nullptr)
    *by_ends = false;
  const Vec3 r = p0 - q0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  if (!(a > 0.0) && !(e > 0.0))
    return { 0.0, 0.0 };
  if (!(a > 0.0))
    return { 0.0, std::clamp(f / e, 0.0, 1.0) };
  const double c = d1.dot(r);
  if (!(e > 0.0))
    return { std::clamp(-c / a, 0.0, 1.0), 0.0 };
  const double b = d1.dot(d2), denominator = a * e - b * b;
  if (parallel_sine2 > 0.0 && denominator < parallel_sine2 * a * e)
  {
    if (by_ends != nullptr)
      *by_ends = true;
    const std::pair<double, double> ends[4] = { { 0.0, std::clamp(f / e, 0.0, 1.0) },
                                                { 1.0, std::clamp((b + f) / e, 0.0, 1.0) },
                                                { std::clamp(-c / a, 0.0, 1.0), 0.0 },
                                                { std::clamp((b - c) / a, 0.0, 1.0), 1.0 } };
    std::pair<double, double> nearest = ends[0];
    double least = 1e300;
    for (const auto& [s, t] : ends)
    {
      const double gap = (r + s * d1 - t * d2).squaredNorm();
      if (gap < least)
      {
        least = gap;
        nearest = { s, t };
      }
    }
    return nearest;
  }
  double s = denominator > 0.0 ? std::clamp((b * f - c * e) / denominator, 0.0, 1.0) : 0.0;
  double t = (b * s + f) / e;
  if (t < 0.0)
  {
    t = 0.0;
    s = std::clamp(-c / a, 0.0, 1.0);
  }
  else if (t > 1.0)
  {
    t = 1.0;
    s = std::clamp((b - c) / a, 0.0, 1.0);
  }
  return { s, t };
}

}  // namespace soft_body_sim
