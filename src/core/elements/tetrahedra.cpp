#include "soft_body_sim/core/elements/tetrahedra.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/SVD>

#include "soft_body_sim/core/elements/forces.h"

namespace soft_body_sim
{
namespace
{
using Matrix3 = Eigen::Matrix3d;
using Vector9 = Eigen::Matrix<double, 9, 1>;

/// cof F = dJ/dF: its columns f1 x f2, f2 x f0, f0 x f1.
Matrix3 cofactor(const Matrix3& F)
{
  Matrix3 c;
  c.col(0) = F.col(1).cross(F.col(2));
  c.col(1) = F.col(2).cross(F.col(0));
  c.col(2) = F.col(0).cross(F.col(1));
  return c;
}

/// [a]x: the matrix of a x (.).
Matrix3 crossMatrix(const Vec3& a)
{
  Matrix3 m;
  m << 0.0, -a.z(), a.y(), a.z(), 0.0, -a.x(), -a.y(), a.x(), 0.0;
  return m;
}

/// The gradients g_a of the four linear shape functions (columns): rest_inverse's rows for nodes 1 to 3,
/// minus their sum for node 0, so that F = sum_a x_a g_a^T.
Eigen::Matrix<double, 3, 4> shapeGradients(const Tetrahedron& tet)
{
  Eigen::Matrix<double, 3, 4> g;
  g.rightCols<3>() = tet.rest_inverse.transpose();
  g.col(0) = -g.rightCols<3>().rowwise().sum();
  return g;
}

/// The part of Psi that depends on J alone, f(J) = -mu (J - 1) + lambda' / 2 (J - 1)^2 + p0 E(J) (E of
/// boyleGas, lambda' = lambda + mu; see tetrahedra.h), and its first two derivatives.
struct VolumeTerm
{
  double energy;     ///< f(J) [Pa]
  double slope;      ///< f'(J) [Pa]: the factor of cof F in P, and of J's Hessian in dP/dF
  double curvature;  ///< f''(J) [Pa]: the factor of cof F cof F^T in dP/dF
};
VolumeTerm volumeTerm(const Tetrahedron& tet, double J)
{
  const double lambda = tet.lambda + tet.mu;
  VolumeTerm term{ -tet.mu * (J - 1.0) + 0.5 * lambda * (J - 1.0) * (J - 1.0), lambda * (J - 1.0) - tet.mu, lambda };
  if (tet.pressure > 0.0)
  {
    const BoyleGas gas = boyleGas(J);
    term.energy += tet.pressure * gas.energy;
    term.slope += tet.pressure * gas.slope;
    term.curvature += tet.pressure * gas.curvature;
  }
  return term;
}

/// vec(U M V^T), column-major: the mode of F-space that M is in the frame of the SVD (U, V).
Vector9 mode(const Matrix3& U, const Matrix3& V, const Matrix3& M)
{
  const Matrix3 Q = U * M * V.transpose();
  return Eigen::Map<const Vector9>(Q.data());
}
}  // namespace

Lame lameParameters(double youngs_modulus, double poisson_ratio)
{
  const double E = youngs_modulus;
  const double nu = poisson_ratio;
  return { E / (2.0 * (1.0 + nu)), E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)) };
}

Tetrahedron makeTetrahedron(const std::array<int, 4>& nodes, const NodeArray& x, const Lame& lame)
{
  Tetrahedron tet;
  Matrix3 rest;
  for (int k = 0; k < 4; ++k)
    tet.nodes[k] = nodes[static_cast<std::size_t>(k)];
  for (int k = 0; k < 3; ++k)
    rest.col(k) = x.col(nodes[static_cast<std::size_t>(k + 1)]) - x.col(nodes[0]);
  const double det = rest.determinant();
  if (!(det > 0.0))
    throw std::invalid_argument("tetrahedron (" + std::to_string(nodes[0]) + ", " + std::to_string(nodes[1]) + ", " +
                                std::to_string(nodes[2]) + ", " + std::to_string(nodes[3]) +
                                ") has no positive rest volume (its nodes flat or negatively oriented)");
  tet.rest_inverse = rest.inverse();
  tet.rest_volume = det / 6.0;
  tet.mu = lame.mu;
  tet.lambda = lame.lambda;
  return tet;
}

Matrix3 deformationGradient(const Tetrahedron& tet, const NodeArray& x)
{
  Matrix3 ds;
  for (int k = 0; k < 3; ++k)
    ds.col(k) = x.col(tet.nodes[k + 1]) - x.col(tet.nodes[0]);
  return ds * tet.rest_inverse;
}

double strainEnergyDensity(const Tetrahedron& tet, const Matrix3& F)
{
  return 0.5 * tet.mu * (F.squaredNorm() - 3.0) + volumeTerm(tet, F.determinant()).energy;
}

Matrix3 firstPiolaStress(const Tetrahedron& tet, const Matrix3& F)
{
  return tet.mu * F + volumeTerm(tet, F.determinant()).slope * cofactor(F);
}

StressDerivative stressDerivative(const Tetrahedron& tet, const Matrix3& F, bool project)
{
  const VolumeTerm term = volumeTerm(tet, F.determinant());
  const double c = term.curvature;  // f''(J): lambda' without gas
  const double s = term.slope;      // f'(J), the factor of J's Hessian
  StressDerivative H;
  if (!project)
  {
    // mu I + c g g^T + s d(cof F)/dF, its 3x3 blocks d(cof_i)/d(f_j) (cof_0 = f1 x f2, ...).
    const Matrix3 cof = cofactor(F);
    const Vector9 g = Eigen::Map<const Vector9>(cof.data());
    H = tet.mu * StressDerivative::Identity() + c * g * g.transpose();
    const Matrix3 h0 = s * crossMatrix(F.col(0)), h1 = s * crossMatrix(F.col(1)), h2 = s * crossMatrix(F.col(2));
    H.block<3, 3>(0, 3) -= h2;
    H.block<3, 3>(0, 6) += h1;
    H.block<3, 3>(3, 0) += h2;
    H.block<3, 3>(3, 6) -= h0;
    H.block<3, 3>(6, 0) -= h1;
    H.block<3, 3>(6, 3) += h0;
    return H;
  }
  // The rotation-variant SVD: U and V rotations, the reflection (if any) in the last singular value.
  const Eigen::JacobiSVD<Matrix3> svd(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Matrix3 U = svd.matrixU(), V = svd.matrixV();
  Vec3 sigma = svd.singularValues();
  if (U.determinant() < 0.0)
  {
    U.col(2) = -U.col(2);
    sigma[2] = -sigma[2];
  }
  if (V.determinant() < 0.0)
  {
    V.col(2) = -V.col(2);
    sigma[2] = -sigma[2];
  }
  H.setZero();
  // Twist and flip modes: on (D_ij, D_ji) of D = U^T dF V the form is mu (a^2 + b^2) - 2 s sigma_k a b.
  const double root_half = std::sqrt(0.5);
  for (int k = 0; k < 3; ++k)
  {
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    Matrix3 twist = Matrix3::Zero(), flip = Matrix3::Zero();
    twist(i, j) = root_half;
    twist(j, i) = -root_half;
    flip(i, j) = root_half;
    flip(j, i) = root_half;
    const double twist_value = tet.mu + s * sigma[k];
    const double flip_value = tet.mu - s * sigma[k];
    if (twist_value > 0.0)
    {
      const Vector9 q = mode(U, V, twist);
      H.noalias() += twist_value * q * q.transpose();
    }
    if (flip_value > 0.0)
    {
      const Vector9 q = mode(U, V, flip);
      H.noalias() += flip_value * q * q.transpose();
    }
  }
  // Scaling modes: mu |d|^2 + c (pi . d)^2 + 2 s sum_{i<j} sigma_k d_i d_j on d = D's diagonal.
  const Vec3 pi(sigma[1] * sigma[2], sigma[2] * sigma[0], sigma[0] * sigma[1]);
  Matrix3 A = tet.mu * Matrix3::Identity() + c * pi * pi.transpose();
  for (int k = 0; k < 3; ++k)
  {
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    A(i, j) += s * sigma[k];
    A(j, i) += s * sigma[k];
  }
  const Eigen::SelfAdjointEigenSolver<Matrix3> scaling(A);
  for (int m = 0; m < 3; ++m)
  {
    const double value = scaling.eigenvalues()[m];
    if (!(value > 0.0))
      continue;
    const Vector9 q = mode(U, V, scaling.eigenvectors().col(m).asDiagonal().toDenseMatrix());
    H.noalias() += value * q * q.transpose();
  }
  return H;
}

double tetEnergy(const Tetrahedron& tet, const NodeArray& x)
{
  return tet.rest_volume * strainEnergyDensity(tet, deformationGradient(tet, x));
}

void accumulateTetForces(const Model& model, const NodeArray& x, NodeArray& force)
{
  for (const Tetrahedron& tet : model.tetrahedra)
  {
    const Eigen::Matrix<double, 3, 4> f =
        -tet.rest_volume * firstPiolaStress(tet, deformationGradient(tet, x)) * shapeGradients(tet);
    for (int a = 0; a < 4; ++a)
      force.col(tet.nodes[a]) += f.col(a);
  }
}

void tetForcesAndStiffness(const Tetrahedron& tet, const NodeArray& x, bool project, Eigen::Matrix<double, 3, 4>& force,
                           TetStiffness& stiffness)
{
  const Eigen::Matrix<double, 3, 4> g = shapeGradients(tet);
  const Matrix3 F = deformationGradient(tet, x);
  force = -tet.rest_volume * firstPiolaStress(tet, F) * g;
  const StressDerivative H = stressDerivative(tet, F, project);
  // H g_b: for each b and column c of F, sum_d g_b[d] H_(.c),(.d), so that K_ab = V0 sum_c g_a[c] (H g_b)_c.
  Matrix3 hg[4][3];
  for (int b = 0; b < 4; ++b)
    for (int c = 0; c < 3; ++c)
      hg[b][c] = g(0, b) * H.block<3, 3>(3 * c, 0) + g(1, b) * H.block<3, 3>(3 * c, 3) + g(2, b) * H.block<3, 3>(3 * c, 6);
  const auto block = [&](int a, int b) {
    return (tet.rest_volume * (g(0, a) * hg[b][0] + g(1, a) * hg[b][1] + g(2, a) * hg[b][2])).eval();
  };
  for (int a = 0; a < 4; ++a)
    stiffness.blocks[a] = block(a, a);
  for (std::size_t p = 0; p < kFourNodePairs.size(); ++p)
    stiffness.blocks[4 + p] = block(kFourNodePairs[p].first, kFourNodePairs[p].second);
}

}  // namespace soft_body_sim
