// The stable neo-Hookean tetrahedron (tetrahedra.h) against truths that do not come from it: finite
// differences of its energy and forces, linear elasticity's stress at small strain, a rotation's zero
// stress, the closed-form energy of a uniaxial stretch, and a brute-force projection of its exact Hessian
// by a numerical eigen-decomposition.
#include <cmath>
#include <random>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "soft_body_sim/core/elements/tetrahedra.h"

namespace soft_body_sim::test
{
namespace
{
using Matrix3 = Eigen::Matrix3d;
using Matrix12 = Eigen::Matrix<double, 12, 12>;

/// A tetrahedron of irregular shape (edges 0.6 to 1.4 cm), its nodes 0..3 of `x`, of E = 1e5 Pa and `nu`.
Tetrahedron irregularTetrahedron(NodeArray& x, double nu)
{
  x.resize(3, 4);
  x.col(0) = Vec3(0.0, 0.0, 0.0);
  x.col(1) = Vec3(0.011, 0.002, -0.001);
  x.col(2) = Vec3(0.003, 0.009, 0.001);
  x.col(3) = Vec3(0.002, 0.003, 0.012);
  return makeTetrahedron({ 0, 1, 2, 3 }, x, lameParameters(1.0e5, nu));
}

/// x moved by the deformation F about node 0 and then by a random perturbation of scale `noise` [m].
NodeArray deformed(const NodeArray& rest, const Matrix3& F, double noise, std::mt19937& random)
{
  std::normal_distribution<double> normal(0.0, noise);
  NodeArray x(3, 4);
  for (int a = 0; a < 4; ++a)
    x.col(a) = F * (rest.col(a) - rest.col(0)) + Vec3(normal(random), normal(random), normal(random));
  return x;
}

/// The 12x12 matrix of the ten blocks.
Matrix12 assembled(const TetStiffness& k)
{
  Matrix12 m;
  for (int a = 0; a < 4; ++a)
    m.block<3, 3>(3 * a, 3 * a) = k.blocks[a];
  for (std::size_t p = 0; p < kFourNodePairs.size(); ++p)
  {
    const int a = kFourNodePairs[p].first, b = kFourNodePairs[p].second;
    m.block<3, 3>(3 * a, 3 * b) = k.blocks[4 + p];
    m.block<3, 3>(3 * b, 3 * a) = k.blocks[4 + p].transpose();
  }
  return m;
}

/// The materials to test: Poisson's ratios 0, 0.3 and 0.49 without gas, and 0.3 with a gas of p0 = 2e5 Pa,
/// five times the shear modulus, so that the gas's terms dominate.
struct Material
{
  double nu;
  double pressure;
};
const std::vector<Material> kMaterials{ { 0.0, 0.0 }, { 0.3, 0.0 }, { 0.49, 0.0 }, { 0.3, 2.0e5 } };

/// irregularTetrahedron of `material`.
Tetrahedron irregularTetrahedron(NodeArray& x, const Material& material)
{
  Tetrahedron tet = irregularTetrahedron(x, material.nu);
  tet.pressure = material.pressure;
  return tet;
}

/// Deformations to test at: stretched, sheared, compressed, near flat and inverted (J < 0).
std::vector<Matrix3> deformations()
{
  std::vector<Matrix3> f;
  f.push_back(Matrix3::Identity());
  f.push_back(Vec3(1.3, 0.9, 0.95).asDiagonal());
  Matrix3 shear = Matrix3::Identity();
  shear(0, 1) = 0.4;
  shear(2, 0) = -0.2;
  f.push_back(shear);
  f.push_back(Vec3(0.6, 0.7, 0.5).asDiagonal());
  f.push_back(Vec3(1.0, 1.0, 0.05).asDiagonal());
  f.push_back(Vec3(1.0, 1.0, -0.3).asDiagonal());
  f.push_back(Eigen::AngleAxisd(0.7, Vec3(1.0, 2.0, -0.5).normalized()).toRotationMatrix() * Vec3(1.2, -0.8, 0.9).asDiagonal());
  return f;
}
}  // namespace

TEST(Tetrahedra, LameParametersOfYoungsModulusAndPoissonsRatio)
{
  // E = 2.5 mu at nu = 0.25, where lambda = mu.
  const Lame lame = lameParameters(1.0, 0.25);
  EXPECT_NEAR(lame.mu, 0.4, 1e-15);
  EXPECT_NEAR(lame.lambda, 0.4, 1e-15);
  EXPECT_EQ(lameParameters(3.0, 0.0).lambda, 0.0);
  EXPECT_NEAR(lameParameters(3.0, 0.0).mu, 1.5, 1e-15);
}

TEST(Tetrahedra, RestVolumeIsTheTetrahedronsAndAFlatOrInvertedOneIsRefused)
{
  NodeArray x;
  const Tetrahedron tet = irregularTetrahedron(x, 0.3);
  const Vec3 u = x.col(1) - x.col(0), v = x.col(2) - x.col(0), w = x.col(3) - x.col(0);
  EXPECT_NEAR(tet.rest_volume, u.cross(v).dot(w) / 6.0, 1e-20);
  EXPECT_TRUE(deformationGradient(tet, x).isApprox(Matrix3::Identity(), 1e-12));
  EXPECT_THROW(makeTetrahedron({ 0, 2, 1, 3 }, x, lameParameters(1.0, 0.3)), std::invalid_argument);
  x.col(3) = x.col(0) + 0.5 * u + 0.3 * v;
  EXPECT_THROW(makeTetrahedron({ 0, 1, 2, 3 }, x, lameParameters(1.0, 0.3)), std::invalid_argument);
}

TEST(Tetrahedra, ARotationCarriesNoStressAndNoEnergy)
{
  NodeArray x;
  const Tetrahedron tet = irregularTetrahedron(x, 0.45);
  const Matrix3 R = Eigen::AngleAxisd(2.1, Vec3(0.3, -1.0, 0.4).normalized()).toRotationMatrix();
  EXPECT_NEAR(strainEnergyDensity(tet, R), 0.0, 1e-9 * tet.mu);
  EXPECT_LT(firstPiolaStress(tet, R).norm(), 1e-12 * tet.mu);
}

TEST(Tetrahedra, SmallStrainStressIsLinearElasticitys)
{
  // F = I + e with a small symmetric strain e: P = 2 mu e + lambda tr(e) I + O(|e|^2).
  NodeArray x;
  for (const double nu : { 0.0, 0.3, 0.49 })
  {
    const Tetrahedron tet = irregularTetrahedron(x, nu);
    Matrix3 e;
    e << 3.0, 1.0, -0.5, 1.0, -2.0, 0.7, -0.5, 0.7, 1.5;
    e *= 1e-6;
    const Matrix3 linear = 2.0 * tet.mu * e + tet.lambda * e.trace() * Matrix3::Identity();
    const Matrix3 P = firstPiolaStress(tet, Matrix3::Identity() + e);
    // The second-order terms are of (mu + lambda) |e|^2: 1e-12 of the moduli here, 1e-6 of the stress.
    EXPECT_LT((P - linear).norm(), 1e-5 * linear.norm()) << "nu = " << nu;
  }
}

TEST(Tetrahedra, AGasIsAnIsothermalIdealGasInAnAtmosphereOfItsRestPressure)
{
  NodeArray x;
  Tetrahedron tet = irregularTetrahedron(x, 0.3);
  tet.pressure = 2.0e5;
  // At small strain the gas adds its bulk modulus p0 (an isothermal ideal gas's) to lambda's:
  // P = 2 mu e + (lambda + p0) tr(e) I + O(|e|^2).
  Matrix3 e;
  e << 3.0, 1.0, -0.5, 1.0, -2.0, 0.7, -0.5, 0.7, 1.5;
  e *= 1e-6;
  const Matrix3 linear = 2.0 * tet.mu * e + (tet.lambda + tet.pressure) * e.trace() * Matrix3::Identity();
  EXPECT_LT((firstPiolaStress(tet, Matrix3::Identity() + e) - linear).norm(), 1e-5 * linear.norm());
  // A rotation compresses no gas.
  const Matrix3 R = Eigen::AngleAxisd(2.1, Vec3(0.3, -1.0, 0.4).normalized()).toRotationMatrix();
  EXPECT_LT(firstPiolaStress(tet, R).norm(), 1e-12 * tet.mu);
  // At any volume ratio J above the barrier, the gas alone (no solid) pushes with Boyle's law: Cauchy stress
  // sigma = P F^T / J = -(p0 / J - p0) I, the absolute pressure p0 / J less the atmosphere's p0.
  tet.mu = 0.0;
  tet.lambda = 0.0;
  for (const double J : { 0.2, 0.5, 0.9, 1.5, 3.0 })
  {
    const Matrix3 F = std::cbrt(J) * Matrix3::Identity();
    const Matrix3 sigma = firstPiolaStress(tet, F) * F.transpose() / J;
    EXPECT_TRUE(sigma.isApprox(-(tet.pressure / J - tet.pressure) * Matrix3::Identity(), 1e-12)) << "J = " << J;
  }
}

TEST(Tetrahedra, UniaxialStretchEnergyHasItsClosedForm)
{
  NodeArray x;
  const Tetrahedron tet = irregularTetrahedron(x, 0.3);
  const double a = 1.25;  // F = diag(a, 1, 1): I_C = a^2 + 2, J = a
  const double expected = 0.5 * tet.mu * (a * a - 1.0) - tet.mu * (a - 1.0) + 0.5 * (tet.lambda + tet.mu) * (a - 1.0) * (a - 1.0);
  EXPECT_NEAR(strainEnergyDensity(tet, Vec3(a, 1.0, 1.0).asDiagonal()), expected, 1e-12 * tet.mu);
  std::mt19937 random(1);
  EXPECT_NEAR(tetEnergy(tet, deformed(x, Vec3(a, 1.0, 1.0).asDiagonal(), 0.0, random)),
              tet.rest_volume * expected, 1e-12 * tet.mu * tet.rest_volume);
}

TEST(Tetrahedra, ForcesAreTheEnergysGradientAndTheStiffnessTheForcesDerivative)
{
  // Central differences with step d: errors of d^2 times the third derivative, ~1e-8 relative here.
  NodeArray rest;
  std::mt19937 random(7);
  for (const Material& material : kMaterials)
  {
    const Tetrahedron tet = irregularTetrahedron(rest, material);
    Model model;
    model.tetrahedra.push_back(tet);
    for (const Matrix3& F : deformations())
    {
      const NodeArray x = deformed(rest, F, 1e-4, random);
      NodeArray force = NodeArray::Zero(3, 4);
      accumulateTetForces(model, x, force);
      Eigen::Matrix<double, 3, 4> f;
      TetStiffness k;
      tetForcesAndStiffness(tet, x, false, f, k);
      EXPECT_TRUE(f.isApprox(force, 1e-14)) << F;
      const Matrix12 K = assembled(k);
      const double d = 1e-7;
      Matrix12 numeric;
      for (int a = 0; a < 4; ++a)
        for (int r = 0; r < 3; ++r)
        {
          NodeArray plus = x, minus = x;
          plus(r, a) += d;
          minus(r, a) -= d;
          EXPECT_NEAR(-(tetEnergy(tet, plus) - tetEnergy(tet, minus)) / (2.0 * d), force(r, a), 1e-6 * force.norm() + 1e-9)
              << "nu = " << material.nu << ", p0 = " << material.pressure << ", F =\n" << F;
          NodeArray f_plus = NodeArray::Zero(3, 4), f_minus = NodeArray::Zero(3, 4);
          accumulateTetForces(model, plus, f_plus);
          accumulateTetForces(model, minus, f_minus);
          const NodeArray column = -(f_plus - f_minus) / (2.0 * d);
          numeric.col(3 * a + r) = Eigen::Map<const Eigen::Matrix<double, 12, 1>>(column.data());
        }
      EXPECT_LT((K - numeric).norm(), 1e-6 * K.norm())
          << "nu = " << material.nu << ", p0 = " << material.pressure << ", F =\n" << F;
      // A translation moves no force: every block row sums to zero.
      for (int a = 0; a < 4; ++a)
        EXPECT_LT((K.block<3, 3>(3 * a, 0) + K.block<3, 3>(3 * a, 3) + K.block<3, 3>(3 * a, 6) + K.block<3, 3>(3 * a, 9)).norm(),
                  1e-9 * K.norm());
    }
  }
}

TEST(Tetrahedra, TheProjectedStressDerivativeIsTheExactOnesEigenvaluesClampedAtZero)
{
  // Brute force: the exact 9x9 dP/dF decomposed numerically, its negative eigenvalues set to 0.
  NodeArray rest;
  for (const Material& material : kMaterials)
  {
    const Tetrahedron tet = irregularTetrahedron(rest, material);
    int indefinite = 0;
    for (const Matrix3& F : deformations())
    {
      const StressDerivative exact = stressDerivative(tet, F, false);
      const Eigen::SelfAdjointEigenSolver<StressDerivative> eigen(exact);
      indefinite += eigen.eigenvalues().minCoeff() < -1e-9 * tet.mu;
      const StressDerivative clamped =
          eigen.eigenvectors() * eigen.eigenvalues().cwiseMax(0.0).asDiagonal() * eigen.eigenvectors().transpose();
      EXPECT_LT((stressDerivative(tet, F, true) - clamped).norm(), 1e-9 * exact.norm())
          << "nu = " << material.nu << ", p0 = " << material.pressure << ", F =\n" << F;
    }
    // The cases include indefinite ones (compressed, flat, inverted), where the projection changes something.
    EXPECT_GE(indefinite, 3) << "nu = " << material.nu << ", p0 = " << material.pressure;
  }
}

TEST(Tetrahedra, TheProjectedStiffnessIsPositiveSemiDefiniteEvenInverted)
{
  NodeArray rest;
  std::mt19937 random(3);
  for (const Material& material : { kMaterials[2], kMaterials[3] })
  {
    const Tetrahedron tet = irregularTetrahedron(rest, material);
    for (const Matrix3& F : deformations())
    {
      Eigen::Matrix<double, 3, 4> f;
      TetStiffness k;
      tetForcesAndStiffness(tet, deformed(rest, F, 1e-3, random), true, f, k);
      const Matrix12 K = assembled(k);
      EXPECT_GE(Eigen::SelfAdjointEigenSolver<Matrix12>(K).eigenvalues().minCoeff(), -1e-9 * K.norm())
          << "p0 = " << material.pressure << ", F =\n" << F;
    }
  }
}

}  // namespace soft_body_sim::test
