// SparseBlockSolver (implicit Euler's direct solve) against a dense reference: random symmetric positive
// definite systems of 3x3 blocks with the pattern of a rope, a cloth (with shear and bending pairs) and
// a jelly's cells, solved by Eigen's dense LDL^T of the same matrix, and the same solver reused after new
// values (the pattern analysed once).
#include <random>
#include <utility>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "../src/core/integrators/sparse_block_solver.h"

namespace soft_body_sim::test
{
namespace
{
using Matrix3 = Eigen::Matrix3d;
constexpr double kAnyWork = 1e300;

std::vector<std::pair<int, int>> ropePairs(int nodes)
{
  std::vector<std::pair<int, int>> pairs;
  for (int i = 0; i + 1 < nodes; ++i)
    pairs.emplace_back(i, i + 1);
  for (int i = 0; i + 2 < nodes; ++i)
    pairs.emplace_back(i + 2, i);  // bending springs, given the other way round
  return pairs;
}

std::vector<std::pair<int, int>> clothPairs(int nx, int ny)
{
  std::vector<std::pair<int, int>> pairs;
  const auto at = [nx](int x, int y) { return y * nx + x; };
  for (int y = 0; y < ny; ++y)
    for (int x = 0; x < nx; ++x)
    {
      if (x + 1 < nx)
        pairs.emplace_back(at(x, y), at(x + 1, y));
      if (y + 1 < ny)
        pairs.emplace_back(at(x, y), at(x, y + 1));
      if (x + 1 < nx && y + 1 < ny)
      {
        pairs.emplace_back(at(x, y), at(x + 1, y + 1));
        pairs.emplace_back(at(x + 1, y), at(x, y + 1));
      }
      if (x + 2 < nx)
        pairs.emplace_back(at(x, y), at(x + 2, y));
    }
  // A cell's six corner pairs repeat some of the above: a repeated pair shares its block.
  pairs.emplace_back(at(0, 0), at(1, 0));
  return pairs;
}

/// Fills `solver` and `dense` with the same random SPD matrix on `pairs`: random off-diagonal blocks,
/// and diagonal blocks that dominate them (a random SPD block plus the sum of the norms of its row).
void fillRandom(std::mt19937& random, int nodes, const std::vector<std::pair<int, int>>& pairs,
                SparseBlockSolver& solver, Eigen::MatrixXd& dense)
{
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  const auto randomBlock = [&] {
    Matrix3 m;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        m(r, c) = value(random);
    return m;
  };
  dense.setZero(3 * nodes, 3 * nodes);
  solver.clear();
  std::vector<double> row_weight(static_cast<std::size_t>(nodes), 0.0);
  for (std::size_t k = 0; k < pairs.size(); ++k)
  {
    const auto [a, b] = pairs[k];
    const Matrix3 block = 1e3 * randomBlock();  // stiff couplings, as k h^2 against light masses
    solver.addOffDiagonal(k, block);
    dense.block<3, 3>(3 * a, 3 * b) += block;
    dense.block<3, 3>(3 * b, 3 * a) += block.transpose();
    row_weight[static_cast<std::size_t>(a)] += 3.0 * block.cwiseAbs().maxCoeff();
    row_weight[static_cast<std::size_t>(b)] += 3.0 * block.cwiseAbs().maxCoeff();
  }
  for (int i = 0; i < nodes; ++i)
  {
    const Matrix3 r = randomBlock();
    const Matrix3 block = r * r.transpose() + (1e-3 + row_weight[static_cast<std::size_t>(i)]) * Matrix3::Identity();
    solver.addDiagonal(i, block);
    dense.block<3, 3>(3 * i, 3 * i) += block;
  }
}

void expectSolvesLikeDense(int nodes, const std::vector<std::pair<int, int>>& pairs, const char* what)
{
  SCOPED_TRACE(what);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  SparseBlockSolver solver;
  ASSERT_TRUE(solver.analyze(nodes, pairs, kAnyWork));
  Eigen::MatrixXd dense;
  for (int trial = 0; trial < 3; ++trial)  // new values in the same pattern
  {
    fillRandom(random, nodes, pairs, solver, dense);
    NodeArray rhs(3, nodes);
    for (int i = 0; i < nodes; ++i)
      rhs.col(i) = Vec3(value(random), value(random), value(random));
    ASSERT_TRUE(solver.factorize());
    NodeArray x;
    solver.solve(rhs, x);
    const Eigen::VectorXd reference = dense.ldlt().solve(Eigen::Map<const Eigen::VectorXd>(rhs.data(), 3 * nodes));
    const Eigen::Map<const Eigen::VectorXd> got(x.data(), 3 * nodes);
    // Both are backward stable: they agree to the matrix's condition number times the rounding error.
    EXPECT_LT((got - reference).norm(), 1e-10 * reference.norm());
    // And the residual is at rounding level.
    EXPECT_LT((dense * got - Eigen::Map<const Eigen::VectorXd>(rhs.data(), 3 * nodes)).norm(),
              1e-12 * dense.norm() * got.norm());
  }
}

TEST(SparseBlockSolver, SolvesRandomRopeSystemsLikeADenseFactorisation) { expectSolvesLikeDense(60, ropePairs(60), "rope"); }

TEST(SparseBlockSolver, SolvesRandomClothSystemsLikeADenseFactorisation)
{
  expectSolvesLikeDense(11 * 9, clothPairs(11, 9), "cloth");
}

// The work analyze counts is that of the factor Eigen builds: on a rope (a path of nodes, in AMD's order
// the rope's own) no fill, so each block column of L holds one block, or two with bending pairs; on a
// 2D grid the fill grows with the size, and past the caller's limit analyze declines.
TEST(SparseBlockSolver, CountsTheFactorisationWorkAndDeclinesPastTheLimit)
{
  SparseBlockSolver rope;
  ASSERT_TRUE(rope.analyze(100, ropePairs(100), kAnyWork));
  // At most two blocks below each diagonal block: scalar columns of at most 6 + 2, 1, 0 entries.
  EXPECT_LE(rope.factorWork(), 100.0 * (81.0 + 64.0 + 49.0));
  SparseBlockSolver small, large;
  ASSERT_TRUE(small.analyze(100, clothPairs(10, 10), kAnyWork));
  ASSERT_TRUE(large.analyze(1600, clothPairs(40, 40), kAnyWork));
  const double small_ratio = small.factorWork() / small.matrixEntries();
  const double large_ratio = large.factorWork() / large.matrixEntries();
  EXPECT_GT(large_ratio, 2.0 * small_ratio);
  SparseBlockSolver declined;
  EXPECT_FALSE(declined.analyze(1600, clothPairs(40, 40), 0.5 * large_ratio));
}

TEST(SparseBlockSolver, RefusesAMatrixThatIsNotPositiveDefinite)
{
  SparseBlockSolver solver;
  ASSERT_TRUE(solver.analyze(2, { { 0, 1 } }, kAnyWork));
  solver.clear();
  solver.addDiagonal(0, Matrix3::Identity());
  solver.addDiagonal(1, -Matrix3::Identity());
  EXPECT_FALSE(solver.factorize());
}

TEST(SparseBlockSolver, RefusesAPairOutOfRangeOrOfOneNode)
{
  SparseBlockSolver solver;
  EXPECT_THROW(solver.analyze(3, { { 0, 3 } }, kAnyWork), std::invalid_argument);
  EXPECT_THROW(solver.analyze(3, { { 1, 1 } }, kAnyWork), std::invalid_argument);
}

}  // namespace
}  // namespace soft_body_sim::test
