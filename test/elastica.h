// The elastica of a cantilever under its own weight: the exact large-deflection shape of a clamped,
// inextensible, unshearable rod, for tests and benchmarks of rods. Independent of the simulator: an
// ODE in the arc length integrated by RK4 and a shooting bisection on the curvature at the clamp.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Core>

namespace soft_body_sim::test
{
/// The elastica of a cantilever of bending stiffness E I [N m^2], weight per length w [N/m] and length L
/// [m], clamped horizontal at s = 0 and free at s = L:
///   E I theta'' = -w (L - s) cos theta,   theta(0) = 0,   theta'(L) = 0,
/// theta the downward angle of the tangent; solved by shooting on theta'(0) (bisection, RK4 of `steps`
/// steps) and integrated to the centre line (x(s), z(s)) relative to the clamp (z < 0: below it), sampled
/// at the arc lengths `at` [m] (linear interpolation between RK4 steps: error ~ (L / steps)^2 kappa).
inline std::vector<Eigen::Vector2d> elastica(double bending_stiffness, double weight, double length,
                                             const std::vector<double>& at, int steps = 20000)
{
  const double ds = length / steps;
  // State y = (theta, theta', x, z); returns it at every step.
  const auto integrate = [&](double curvature, std::vector<Eigen::Vector4d>* path) {
    Eigen::Vector4d y(0.0, curvature, 0.0, 0.0);
    const auto rate = [&](double s, const Eigen::Vector4d& q) {
      return Eigen::Vector4d(q[1], -weight * (length - s) * std::cos(q[0]) / bending_stiffness, std::cos(q[0]),
                             -std::sin(q[0]));
    };
    if (path)
      path->push_back(y);
    for (int k = 0; k < steps; ++k)
    {
      const double s = k * ds;
      const Eigen::Vector4d k1 = rate(s, y), k2 = rate(s + ds / 2, y + ds / 2 * k1),
                            k3 = rate(s + ds / 2, y + ds / 2 * k2), k4 = rate(s + ds, y + ds * k3);
      y += ds / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
      if (path)
        path->push_back(y);
    }
    return y;
  };
  // theta'(L) grows with theta'(0): bracket between 0 and the straight-down moment w L^2 / (2 E I).
  double low = 0.0, high = weight * length * length / (2.0 * bending_stiffness) * 1.01;
  for (int k = 0; k < 200 && high - low > 1e-15 * high; ++k)
  {
    const double mid = 0.5 * (low + high);
    (integrate(mid, nullptr)[1] > 0.0 ? high : low) = mid;
  }
  std::vector<Eigen::Vector4d> path;
  integrate(0.5 * (low + high), &path);
  std::vector<Eigen::Vector2d> points;
  for (double s : at)
  {
    const double index = s / ds;
    const int k = std::clamp(static_cast<int>(index), 0, steps - 1);
    const double u = index - k;
    points.push_back((1 - u) * path[static_cast<std::size_t>(k)].tail<2>() +
                     u * path[static_cast<std::size_t>(k) + 1].tail<2>());
  }
  return points;
}

}  // namespace soft_body_sim::test
