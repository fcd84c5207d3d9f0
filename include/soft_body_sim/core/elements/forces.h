// Force and energy kernels shared by every force-based integrator.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

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

/// Spring s's tension [N] (> 0 stretched), k (|d| - rest_length) + c (v_a - v_b) . u, along its axis u
/// of length |d| (springAxis): it pulls each end toward the other with this force (see Spring).
inline double springTension(const Spring& s, const Vec3& u, double length, const NodeArray& v)
{
  return s.stiffness * (length - s.rest_length) + s.damping * (v.col(s.a) - v.col(s.b)).dot(u);
}

/// Springs [start, start + count) of SpringArrays join node a + i to node a + i + distance, i = 0 .. count - 1
/// (a cloth's row or column, a rope), so that the kernel loads and adds four consecutive nodes' columns at a
/// time: three loads of twelve doubles rather than a load per node and coordinate.
struct SpringRun
{
  std::uint32_t start = 0;
  std::uint32_t count = 0;
  int a = 0;         ///< end a of the run's first spring
  int distance = 0;  ///< b - a: 1 or 2 (each node an end of two consecutive springs), or at least kFarRun
};

/// The model's springs as accumulateSpringForces reads them: one array per field. First the runs
/// (SpringRun, their springs' ends ordered a < b), then the other springs in the order of a greedy edge
/// colouring, so that no two consecutive springs share a node (in model order each `force.col(a) += f` of a
/// rope or a cloth waits for the previous spring's store to the same node). A copy of the springs'
/// parameters: made again when the model changes.
struct SpringArrays
{
  std::vector<int> a;
  std::vector<int> b;
  std::vector<double> rest_length;  ///< [m]
  std::vector<double> stiffness;    ///< k [N/m]
  std::vector<double> damping;      ///< c [N s/m]
  std::vector<SpringRun> runs;      ///< over springs [0, run_springs)
  std::size_t run_springs = 0;

  std::size_t size() const { return a.size(); }

  /// A run's ends at least this far apart: four consecutive springs' b ends are none of the next four's a ends.
  static constexpr int kFarRun = 8;
  /// Shorter rows of consecutive springs are left to the colouring.
  static constexpr std::uint32_t kLeastRun = 8;
  /// Longer runs are cut (their parts ordered by their first node, so that a cloth's rows are visited row by
  /// row, its nodes in cache, rather than a column's springs across the whole cloth at once).
  static constexpr std::uint32_t kMostRun = 128;
};
SpringArrays springArrays(const Model& model);

/// Adds every spring's Hooke + dashpot force [N] to `force` (see Spring), the runs' first.
void accumulateSpringForces(const SpringArrays& springs, const NodeArray& x, const NodeArray& v, NodeArray& force);

/// Below this fraction a of its rest area (a cell) or volume (a tetrahedron) a gas's law continues as a
/// parabola (see BoyleGas).
constexpr double kCellBarrierArea = 0.1;

/// Boyle's law in an atmosphere of the rest pressure, per p0 and rest measure (area or volume) A0: at
/// a = A / A0 the gas's energy is p0 A0 E(a), its net pressure -p0 E'(a), with
///   a >= a_c:  E = a - 1 - ln a,   E' = 1 - 1/a,   E'' = 1 / a^2
///   a <  a_c:  the second-order Taylor continuation of E about a_c = kCellBarrierArea (C2 joint).
/// A jelly cell's gas (CellGas) and a volume's per-tetrahedron gas (tetrahedra.h) both follow it.
struct BoyleGas
{
  double energy;     ///< E(a) [-]
  double slope;      ///< E'(a), < 0 compressed: minus the net pressure per p0
  double curvature;  ///< E''(a), > 0
};
BoyleGas boyleGas(double a);

/// Signed area A [m^2] of a pressure cell (see PressureCell), the diagonal form of the shoelace formula:
///   A = 1/2 n . ((x_2 - x_0) x (x_3 - x_1)),
/// and, if `gradient` is given, dA/dx_k [m] for its four corners:
///   dA/dx_0 = -1/2 (x_3 - x_1) x n = -dA/dx_2,   dA/dx_1 = -1/2 n x (x_2 - x_0) = -dA/dx_3.
/// Each lies in the cell's plane, normal to the diagonal opposite its node. They sum to zero and A is
/// unchanged by rotations about n, so the pressure force below exerts no net force or torque.
double cellArea(const PressureCell& cell, const NodeArray& x, Vec3* gradient = nullptr);

/// The gas of a jelly cell at signed area A, with a = A / A0 (Boyle's law in an atmosphere of the
/// rest pressure p0, so that the cell is at rest at A0):
///   a >= a_c:  E = p0 A0 (a - 1 - ln a),   p = -dE/dA = p0 (1/a - 1),   dp/dA = -p0 / (A0 a^2)
///   a <  a_c:  the second-order Taylor continuation of E about a_c = kCellBarrierArea (C2 joint),
///              p = p0 (1/a_c - 1 + (a_c - a) / a_c^2),  dp/dA = -p0 / (A0 a_c^2)
/// and the force on corner k is F_k = p dA/dx_k.
/// Why this and not the seed's: the jelly seed pushes each node out from the cell's centroid in
/// proportion to the change of that distance. That force has no energy of the cell's shape, and once
/// nodes cross it points wherever the centroid-to-node line happens to point ("drives the structure
/// in improbable directions"). Here the force is minus the gradient of an energy of the signed area:
/// it only ever moves nodes so as to restore the area, it is consistent with potentialEnergy(), and
/// it grows without bound as the cell is squeezed (the log barrier: 9 p0 at a = 0.1), so a cell
/// cannot be flattened by any bounded energy. Should a large step still push a cell past its barrier,
/// the continuation keeps p > 0 and growing for a <= 0: an inverted cell is pushed back inside out
/// instead of being blown further apart. For small changes p ~ -p0 (A - A0) / A0: p0 is the cell's
/// 2D bulk modulus.
struct CellGas
{
  double energy;     ///< E [J]
  double pressure;   ///< p = -dE/dA [N/m]; > 0 pushes the outline outward
  double stiffness;  ///< d^2E/dA^2 = -dp/dA [N/m^3], > 0
};
CellGas cellGas(const PressureCell& cell, double area);

/// Adds every cell's pressure force F_k = p dA/dx_k [N] to `force` (nothing without cells).
void accumulatePressureForces(const Model& model, const NodeArray& x, NodeArray& force);

/// a(x, v) [m/s^2] of the model: gravity + F/m - drag v on free nodes, 0 on pinned ones; F is the
/// springs' force (`springs`: springArrays(model)) plus, when the model has cells, their pressure.
/// `force` is caller-owned scratch space so that the hot loop never allocates.
void computeAccelerations(const Model& model, const SpringArrays& springs, const NodeArray& x, const NodeArray& v,
                          NodeArray& force, NodeArray& acceleration);

/// Kinetic [J] of the free nodes.
double kineticEnergy(const Model& model, const State& state);
/// Potential [J]: the energy every element stores (each kind's, element_kinds.h: springs, compliant distance
/// constraints, gas cells, rods, tetrahedra) plus the gravitational energy -m g.x of the free nodes.
double potentialEnergy(const Model& model, const State& state);

/// The largest strain |l - L| / L [-] of any spring or distance constraint with a rest length L > 0
/// (l its length now); infinity if a length is not finite, 0 without any.
double maxStrain(const Model& model, const State& state);

}  // namespace soft_body_sim
