// The elastic discrete catenary: the exact rest shape of a chain of springs pinned at both ends at equal
// height, for tests of ropes and chains. Independent of the simulator: a closed-form recurrence and a
// bisection on the horizontal tension.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace soft_body_sim::test
{
constexpr double kGravity = 9.81;  ///< [m/s^2], along -z

/// Segment j's tension vector [N] of a symmetric chain of `nodes` nodes of mass node_mass [kg] with
/// horizontal tension H [N]. Interior node j (mass m) is in equilibrium when the tension vectors of its
/// two segments differ by its weight: T_j = T_{j-1} + (0, 0, m g), so T_j = (H, 0, (j - (N - 2) / 2) m g).
inline Eigen::Vector3d catenaryTension(int nodes, double node_mass, double horizontal_tension, int j)
{
  return Eigen::Vector3d(horizontal_tension, 0.0, (j - (nodes - 2) / 2.0) * node_mass * kGravity);
}

/// Node positions [m], starting at the origin, of a chain with horizontal tension H [N] (see
/// discreteCatenary): segment j has length L + |T_j| / k along T_j / |T_j|.
inline Eigen::Matrix3Xd catenaryShape(int nodes, double node_mass, double stiffness, double rest,
                                      double horizontal_tension)
{
  Eigen::Matrix3Xd x = Eigen::Matrix3Xd::Zero(3, nodes);
  for (int j = 0; j + 1 < nodes; ++j)
  {
    const Eigen::Vector3d tension = catenaryTension(nodes, node_mass, horizontal_tension, j);
    x.col(j + 1) = x.col(j) + (rest + tension.norm() / stiffness) * tension.normalized();
  }
  return x;
}

/// The horizontal tension H [N] of the elastic discrete catenary of `nodes` nodes of mass node_mass [kg]
/// (interior ones; the pinned ends' masses do not matter) joined by springs of stiffness [N/m] and rest
/// length rest [m], pinned at both ends at equal height span [m] apart. The span sum_j s_j . x grows
/// monotonically with H, so bisection finds H to machine precision.
inline double catenaryHorizontalTension(int nodes, double node_mass, double stiffness, double rest, double span)
{
  double low = 0.0, high = 1e6;
  for (int k = 0; k < 200; ++k)
  {
    const double mid = 0.5 * (low + high);
    (catenaryShape(nodes, node_mass, stiffness, rest, mid)(0, nodes - 1) < span ? low : high) = mid;
  }
  return 0.5 * (low + high);
}

/// Node positions [m], starting at the origin and ending at (span, 0, 0), of that catenary.
inline Eigen::Matrix3Xd discreteCatenary(int nodes, double node_mass, double stiffness, double rest, double span)
{
  return catenaryShape(nodes, node_mass, stiffness, rest,
                       catenaryHorizontalTension(nodes, node_mass, stiffness, rest, span));
}

}  // namespace soft_body_sim::test
