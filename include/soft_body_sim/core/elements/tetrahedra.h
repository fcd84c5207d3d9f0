// Elasticity of soft solids (Model::tetrahedra, a scene's `type: volume`): linear tetrahedra of the stable
// neo-Hookean material of Smith, de Goes and Kim 2018 ("Stable Neo-Hookean Flesh Simulation"), in the
// form without their logarithmic term (their section 3.4; Macklin and Mueller 2021 use the same):
//   Psi(F) = mu / 2 (I_C - 3) - mu (J - 1) + lambda' / 2 (J - 1)^2,   I_C = |F|^2, J = det F,
// with lambda' = lambda + mu, so that at small strain Psi = mu |eps|^2 + lambda / 2 tr(eps)^2, linear
// elasticity with Lame parameters mu and lambda (Young's modulus E and Poisson's ratio nu as usual).
//
// Why this material: it is rest-stable (no stress at F = I), defined and smooth through inversion (J <= 0;
// a neo-Hookean log J is not, and corotational linear FEM has no restoring force out of an inverted
// state that it does not flip back by hand), and its volume term grows with lambda', so a nearly
// incompressible solid (nu = 0.49) keeps its volume under large stretch, where linear strain would let
// it lose (1 + e)(1 - nu e)^2 - 1 of it (2.4 % at 20 % stretch). It enters the implicit_euler Newton system
// with its Hessian projected onto the positive semi-definite matrices per tetrahedron by the analytic
// eigen-system of Smith et al. (tetStiffness), so the system stays symmetric positive definite at any
// strain, inverted tetrahedra included.
//
// Gas (a volume's `pressure` p0 > 0): each tetrahedron holds an ideal gas at rest pressure p0 in an
// atmosphere of p0, Boyle's law as in a jelly cell (forces.h's BoyleGas), so that Psi gains p0 E(J),
// E(J) = J - 1 - ln J: net pressure p0 (1/J - 1), bulk modulus p0 at small strain (an isothermal ideal
// gas's), and a barrier that grows without bound as a tetrahedron is squeezed flat (the jelly seed's
// pressure "that prevents it from collapsing", per element, in 3D: a closed-cell foam). Psi's J-part is
// then f(J) = -mu (J - 1) + lambda' / 2 (J - 1)^2 + p0 E(J), and the stress and eigen-system below hold
// with s = f'(J) and lambda' replaced by f''(J).
#pragma once

#include <array>

#include <Eigen/Core>

#include "soft_body_sim/core/integrators/integrator.h"
#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
/// The Lame parameters of Young's modulus E [Pa] > 0 and Poisson's ratio nu in [0, 0.5):
/// mu = E / (2 (1 + nu)), lambda = E nu / ((1 + nu)(1 - 2 nu)).
struct Lame
{
  double mu = 0.0;
  double lambda = 0.0;
};
Lame lameParameters(double youngs_modulus, double poisson_ratio);

/// The tetrahedron of nodes `nodes` at their rest positions in `x`, of the material `lame`. Throws
/// std::invalid_argument when its rest volume is not > 0 (nodes not positively oriented, or flat).
Tetrahedron makeTetrahedron(const std::array<int, 4>& nodes, const NodeArray& x, const Lame& lame);

/// F = D_s D_m^-1 of `tet` at positions x.
Eigen::Matrix3d deformationGradient(const Tetrahedron& tet, const NodeArray& x);

/// Psi(F) [Pa = J/m^3] of `tet`'s material.
double strainEnergyDensity(const Tetrahedron& tet, const Eigen::Matrix3d& F);

/// The first Piola-Kirchhoff stress P = dPsi/dF = mu F + f'(J) cof F [Pa], f'(J) = lambda' (J - 1) - mu
/// (+ p0 (1 - 1/J) with gas),
/// cof F = dJ/dF = [f1 x f2, f2 x f0, f0 x f1] (f_i F's columns).
Eigen::Matrix3d firstPiolaStress(const Tetrahedron& tet, const Eigen::Matrix3d& F);

/// dP/dF (9x9 on F's entries in column-major order), exactly, or projected onto the positive
/// semi-definite matrices (its negative eigenvalues set to 0) by the analytic eigen-system of Smith et al.
/// 2018: in the rotation-variant SVD F = U S V^T (U, V rotations, S's last entry negative when F inverts)
/// the six twist and flip modes U (e_i e_j^T -+ e_j e_i^T) V^T / sqrt 2 have eigenvalues
/// mu +- s sigma_k (s = f'(J), k the third index), and the three scaling modes U diag(w) V^T a 3x3 matrix
/// mu I + f''(J) pi pi^T + s [sigma_k off its diagonal] (pi_i = J / sigma_i).
using StressDerivative = Eigen::Matrix<double, 9, 9>;
StressDerivative stressDerivative(const Tetrahedron& tet, const Eigen::Matrix3d& F, bool project);

/// The energy V0 Psi(F) [J] of `tet` at positions x.
double tetEnergy(const Tetrahedron& tet, const NodeArray& x);

/// Adds every tetrahedron's elastic forces f_a = -V0 P g_a to `force` [N], g_a = dF^T/dx_a's vector (the
/// gradient of node a's linear shape function: D_m^-T's rows for nodes 1 to 3, minus their sum for node 0).
void accumulateTetForces(const Model& model, const NodeArray& x, NodeArray& force);

/// -df/dx of `tet` at x as its ten distinct 3x3 blocks K_ab = V0 sum_cd g_a[c] g_b[d] H_(.c),(.d): the
/// four diagonal ones (a = b = 0..3) then the six pairs (0,1) (0,2) (0,3) (1,2) (1,3) (2,3); K_ba = K_ab^T.
/// H = stressDerivative(..., project): projected, the 12x12 matrix is positive semi-definite.
struct TetStiffness
{
  Eigen::Matrix3d blocks[10];
};
/// The six pairs of four nodes, in the order of TetStiffness's off-diagonal blocks; also the order of a gas
/// cell's corner pairs and of a surface hold's node and triangle in implicit Euler's pattern.
constexpr std::array<std::pair<int, int>, 6> kFourNodePairs{ { { 0, 1 }, { 0, 2 }, { 0, 3 }, { 1, 2 }, { 1, 3 }, { 2, 3 } } };
/// Its forces (f_a, as accumulateTetForces adds them) and its stiffness at x.
void tetForcesAndStiffness(const Tetrahedron& tet, const NodeArray& x, bool project, Eigen::Matrix<double, 3, 4>& force,
                           TetStiffness& stiffness);


}  // namespace soft_body_sim
