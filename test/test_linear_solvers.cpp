// implicit_euler's linear solves. Its two direct solvers (SparseBlockSolver, BlockTridiagonalSolver)
// against a dense reference: random symmetric positive definite systems of 3x3 blocks with the pattern
// of a rope, a cloth (with shear and bending pairs) or chains, solved by Eigen's dense LDL^T of the same
// matrix, and the same solver reused after new values (the pattern analysed once); the block-tridiagonal
// solver also on the chains among other components, as conjugate gradients' preconditioner takes them. Then
// the integrator's direct and iterative paths on the same random states of a chain, a rope with bending
// springs, a cloth, and a rope beside a cloth: the same step to the conjugate gradients' tolerance.
#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "core/solvers/aggregation_multigrid.h"
#include "core/solvers/block_tridiagonal_solver.h"
#include "core/integrators/integrator_kit.h"
#include "core/solvers/sparse_block_solver.h"
#include "soft_body_sim/core/bodies/cloth.h"
#include "soft_body_sim/core/bodies/rope.h"
#include "soft_body_sim/core/world.h"

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
template <class Solver>
void fillRandom(std::mt19937& random, int nodes, const std::vector<std::pair<int, int>>& pairs, Solver& solver,
                Eigen::MatrixXd& dense)
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
  solver.start(std::vector<Matrix3>(static_cast<std::size_t>(nodes), Matrix3::Zero()));
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

/// The pattern analysed by either direct solver.
bool analyze(SparseBlockSolver& solver, int nodes, const std::vector<std::pair<int, int>>& pairs)
{
  return solver.analyze(nodes, pairs, kAnyWork);
}
bool analyze(BlockTridiagonalSolver& solver, int nodes, const std::vector<std::pair<int, int>>& pairs)
{
  return solver.analyze(nodes, pairs);
}

template <class Solver>
void expectSolvesLikeDense(int nodes, const std::vector<std::pair<int, int>>& pairs, const char* what)
{
  SCOPED_TRACE(what);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  Solver solver;
  ASSERT_TRUE(analyze(solver, nodes, pairs));
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

TEST(SparseBlockSolver, SolvesRandomRopeSystemsLikeADenseFactorisation)
{
  expectSolvesLikeDense<SparseBlockSolver>(60, ropePairs(60), "rope");
}

TEST(SparseBlockSolver, SolvesRandomClothSystemsLikeADenseFactorisation)
{
  expectSolvesLikeDense<SparseBlockSolver>(11 * 9, clothPairs(11, 9), "cloth");
}

/// Chains of 1 to `longest` nodes (each length once: the factorisation from both ends meets in the
/// middle of even and odd lengths alike), in shuffled node numbers, with pairs named either way round,
/// a pair given twice, and every node in some chain.
std::vector<std::pair<int, int>> shuffledChains(int longest, int& nodes)
{
  std::mt19937 random(3);
  nodes = longest * (longest + 1) / 2;
  std::vector<int> label(static_cast<std::size_t>(nodes));
  for (int i = 0; i < nodes; ++i)
    label[static_cast<std::size_t>(i)] = i;
  std::shuffle(label.begin(), label.end(), random);
  std::vector<std::pair<int, int>> pairs;
  int first = 0;
  for (int length = 1; length <= longest; ++length)
  {
    for (int i = first; i + 1 < first + length; ++i)
    {
      const int a = label[static_cast<std::size_t>(i)], b = label[static_cast<std::size_t>(i + 1)];
      pairs.emplace_back(i % 2 == 0 ? std::pair<int, int>{ a, b } : std::pair<int, int>{ b, a });
    }
    first += length;
  }
  pairs.push_back(pairs.back());
  return pairs;
}

TEST(BlockTridiagonalSolver, SolvesRandomChainSystemsLikeADenseFactorisation)
{
  std::vector<std::pair<int, int>> rope;
  for (int i = 0; i + 1 < 60; ++i)
    rope.emplace_back(i, i + 1);
  expectSolvesLikeDense<BlockTridiagonalSolver>(60, rope, "rope");
  int nodes = 0;
  const std::vector<std::pair<int, int>> chains = shuffledChains(12, nodes);
  expectSolvesLikeDense<BlockTridiagonalSolver>(nodes, chains, "chains of 1 to 12 nodes");
}

TEST(BlockTridiagonalSolver, DeclinesBranchesAndCycles)
{
  BlockTridiagonalSolver solver;
  EXPECT_FALSE(solver.analyze(4, { { 0, 1 }, { 0, 2 }, { 0, 3 } }));           // a node with three neighbours
  EXPECT_FALSE(solver.analyze(4, { { 0, 1 }, { 1, 2 }, { 2, 0 } }));           // a triangle (node 3 alone)
  EXPECT_FALSE(solver.analyze(100, ropePairs(100)));                          // bending pairs
  EXPECT_TRUE(solver.analyze(4, { { 0, 1 }, { 1, 0 }, { 2, 3 } }));            // a pair twice, two chains
  EXPECT_THROW(solver.analyze(3, { { 0, 3 } }), std::invalid_argument);
  EXPECT_THROW(solver.analyze(3, { { 1, 1 } }), std::invalid_argument);
}

// The chains among a pattern that is not all chains: only the components that are paths of two nodes or
// more. A is block diagonal over its components, so the chains' part of its dense solution is the chains'
// solve; the other nodes' columns of x are left as they were.
TEST(BlockTridiagonalSolver, SolvesTheChainsAmongOtherComponentsAndLeavesTheOtherNodes)
{
  const std::vector<std::pair<int, int>> pairs = {
    { 0, 1 }, { 1, 2 }, { 3, 2 }, { 3, 4 }, { 4, 5 },  // a chain 0-5, one pair named the other way round
    { 6, 7 }, { 6, 8 }, { 6, 9 },                      // a star: 6 has three neighbours
    { 10, 11 }, { 11, 12 }, { 12, 10 },                // a triangle
    { 14, 15 }, { 15, 16 }, { 16, 17 }, { 16, 18 },    // a chain that ends in a branch (16)
    { 19, 20 }, { 20, 19 },                            // a chain of two, its pair given twice
  };                                                   // 13 alone
  constexpr int nodes = 21;
  const std::vector<int> on_chains = { 0, 1, 2, 3, 4, 5, 19, 20 };
  BlockTridiagonalSolver solver;
  ASSERT_TRUE(solver.analyzeChains(nodes, pairs));
  for (int i = 0; i < nodes; ++i)
    EXPECT_EQ(solver.onPath(i), std::count(on_chains.begin(), on_chains.end(), i) == 1) << "node " << i;
  std::mt19937 random(5);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  Eigen::MatrixXd dense;
  fillRandom(random, nodes, pairs, solver, dense);
  NodeArray rhs(3, nodes);
  for (int i = 0; i < nodes; ++i)
    rhs.col(i) = Vec3(value(random), value(random), value(random));
  ASSERT_TRUE(solver.factorize());
  NodeArray x = NodeArray::Constant(3, nodes, 7.0);
  solver.solve(rhs, x);
  const Eigen::VectorXd reference = dense.ldlt().solve(Eigen::Map<const Eigen::VectorXd>(rhs.data(), 3 * nodes));
  for (int i = 0; i < nodes; ++i)
    if (solver.onPath(i))
      EXPECT_LT((x.col(i) - reference.segment<3>(3 * i)).norm(), 1e-10 * reference.norm()) << "node " << i;
    else
      EXPECT_EQ(x.col(i), Vec3::Constant(7.0)) << "node " << i;
  // No chain of two nodes or more: nothing to solve.
  EXPECT_FALSE(solver.analyzeChains(100, clothPairs(10, 10)));
  EXPECT_FALSE(solver.analyzeChains(3, { { 0, 1 }, { 1, 2 }, { 2, 0 } }));
  EXPECT_FALSE(solver.analyzeChains(2, {}));
}

TEST(BlockTridiagonalSolver, RefusesAMatrixThatIsNotPositiveDefinite)
{
  BlockTridiagonalSolver solver;
  ASSERT_TRUE(solver.analyze(3, { { 0, 1 }, { 1, 2 } }));
  // Positive diagonal blocks, but the coupling makes the second pivot negative: A is indefinite.
  solver.start({ Matrix3::Identity(), Matrix3::Identity(), Matrix3::Identity() });
  solver.addOffDiagonal(0, 2.0 * Matrix3::Identity());
  EXPECT_FALSE(solver.factorize());
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
  solver.start({ Matrix3::Identity(), -Matrix3::Identity() });
  EXPECT_FALSE(solver.factorize());
}

TEST(SparseBlockSolver, RefusesAPairOutOfRangeOrOfOneNode)
{
  SparseBlockSolver solver;
  EXPECT_THROW(solver.analyze(3, { { 0, 3 } }, kAnyWork), std::invalid_argument);
  EXPECT_THROW(solver.analyze(3, { { 1, 1 } }, kAnyWork), std::invalid_argument);
}

/// An upper bound on the condition number of implicit Euler's matrix A = M + h c u u^T + h^2 K+ at any
/// state (K+: the spring Hessians with compressed springs' transverse part dropped, positive
/// semidefinite): its eigenvalues are at least the smallest node mass, and at most the largest
/// Gershgorin row sum, m_i + 2 sum over node i's springs of (h^2 k + h c).
double conditionBound(const Model& model, double h)
{
  std::vector<double> row(static_cast<std::size_t>(model.nodeCount()), 0.0);
  for (const Spring& s : model.springs)
    for (const int node : { s.a, s.b })
      row[static_cast<std::size_t>(node)] += 2.0 * (h * h * s.stiffness + h * s.damping);
  double smallest = INFINITY, largest = 0.0;
  for (int i = 0; i < model.nodeCount(); ++i)
    if (model.isFree(i))
    {
      smallest = std::min(smallest, model.mass[i]);
      largest = std::max(largest, model.mass[i] + row[static_cast<std::size_t>(i)]);
    }
  return largest / smallest;
}

/// A random SPD system's product A x, by its dense matrix (AggregationMultigrid's fine level).
class DenseProduct final : public AggregationMultigrid::FineProduct
{
public:
  explicit DenseProduct(const Eigen::MatrixXd& a) : a_(a) {}
  void operator()(const NodeArray& x, NodeArray& out) const override
  {
    out.resize(3, x.cols());
    Eigen::Map<Eigen::VectorXd>(out.data(), out.size()) = a_ * Eigen::Map<const Eigen::VectorXd>(x.data(), x.size());
  }

private:
  const Eigen::MatrixXd& a_;
};

NodeArray randomNodes(std::mt19937& random, int nodes)
{
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  NodeArray x(3, nodes);
  for (int i = 0; i < nodes; ++i)
    x.col(i) = Vec3(value(random), value(random), value(random));
  return x;
}

double dotNodes(const NodeArray& a, const NodeArray& b) { return a.cwiseProduct(b).sum(); }

// At most 24 nodes the one level is solved by its dense factorisation: the cycle is A^-1.
TEST(AggregationMultigrid, IsTheInverseOnASystemWithinItsDenseLevel)
{
  std::mt19937 random(5);
  const std::vector<std::pair<int, int>> pairs = clothPairs(4, 5);
  AggregationMultigrid multigrid;
  multigrid.analyze(20, pairs);
  Eigen::MatrixXd dense;
  fillRandom(random, 20, pairs, multigrid, dense);
  ASSERT_TRUE(multigrid.setup());
  EXPECT_EQ(multigrid.levelCount(), 1u);
  const NodeArray r = randomNodes(random, 20);
  NodeArray z(3, 20);
  multigrid.apply(r, z, DenseProduct(dense));
  const Eigen::VectorXd reference = dense.ldlt().solve(Eigen::Map<const Eigen::VectorXd>(r.data(), r.size()));
  EXPECT_LT((Eigen::Map<const Eigen::VectorXd>(z.data(), z.size()) - reference).norm(), 1e-10 * reference.norm());
}

// What conjugate gradients need of their preconditioner M (one V-cycle): symmetric and positive definite;
// and what makes it a multigrid cycle rather than any SPD operator: the error e of an iterate, after a
// cycle on its residual (e - M A e), is smaller in A's norm (the smoothers and the coarse correction are
// each contractions there). On random SPD systems on a 30 x 30 cloth's pattern, with coarse levels.
TEST(AggregationMultigrid, IsASymmetricPositiveDefiniteContraction)
{
  std::mt19937 random(3);
  constexpr int kSide = 30, kNodes = kSide * kSide;
  const std::vector<std::pair<int, int>> pairs = clothPairs(kSide, kSide);
  AggregationMultigrid multigrid;
  multigrid.analyze(kNodes, pairs);
  Eigen::MatrixXd dense;
  for (int trial = 0; trial < 3; ++trial)
  {
    fillRandom(random, kNodes, pairs, multigrid, dense);
    ASSERT_TRUE(multigrid.setup());
    EXPECT_GE(multigrid.levelCount(), 2u);
    EXPECT_LE(multigrid.coarsestNodes(), 24);
    const DenseProduct product(dense);
    const auto cycle = [&](const NodeArray& r) {
      NodeArray z(3, kNodes);
      multigrid.apply(r, z, product);
      return z;
    };
    const auto energy = [&](const NodeArray& e) {
      NodeArray ae;
      product(e, ae);
      return dotNodes(e, ae);
    };
    const NodeArray r1 = randomNodes(random, kNodes), r2 = randomNodes(random, kNodes);
    const NodeArray z1 = cycle(r1), z2 = cycle(r2);
    EXPECT_NEAR(dotNodes(r1, z2), dotNodes(r2, z1), 1e-12 * r1.norm() * z2.norm());
    EXPECT_GT(dotNodes(r1, z1), 0.0);
    EXPECT_GT(dotNodes(r2, z2), 0.0);
    const NodeArray e = randomNodes(random, kNodes);
    NodeArray ae;
    product(e, ae);
    const NodeArray after = e - cycle(ae);
    EXPECT_LT(energy(after), energy(e));
  }
}

TEST(AggregationMultigrid, RefusesAMatrixThatIsNotPositiveDefinite)
{
  const std::vector<std::pair<int, int>> pairs = clothPairs(10, 10);
  AggregationMultigrid multigrid;
  multigrid.analyze(100, pairs);
  multigrid.start(std::vector<Matrix3>(100, Matrix3::Identity()));
  multigrid.addDiagonal(37, -2.0 * Matrix3::Identity());
  EXPECT_FALSE(multigrid.setup());
}

/// From random states of `bodies` (every free node moved by up to 0.3 of `spacing` [m] in each axis, so
/// that springs are both stretched and compressed, and given a random velocity of up to 1 m/s), one
/// implicit Euler step of 1/60 s solved directly and one solved by conjugate gradients (`iterative`:
/// LinearSolve::Iterative, or Cheaper where the rule takes them). CG stops at a relative residual of
/// 1e-12, so its velocity change differs from the exact one by at most condition(A) 1e-12 relative; the
/// direct solve's rounding error (condition times 1e-16) is far below.
void expectDirectAndIterativeAgree(const std::vector<BodyDef>& bodies, double spacing,
                                   LinearSolve iterative_solve = LinearSolve::Iterative)
{
  SCOPED_TRACE(bodies.front().name);
  SceneDef scene;
  scene.physics.integrator = IntegratorType::ImplicitEuler;
  scene.bodies = bodies;
  const World world = buildWorld(scene);
  const Model& model = world.model();
  constexpr double h = 1.0 / 60.0;
  const double condition = conditionBound(model, h);
  ASSERT_GT(condition, 100.0);  // a system CG does not solve in a few sweeps
  std::mt19937 random(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 3; ++trial)
  {
    State start = world.state();
    for (int i = 0; i < model.nodeCount(); ++i)
      if (model.isFree(i))
      {
        start.position.col(i) += 0.3 * spacing * Vec3(unit(random), unit(random), unit(random));
        start.velocity.col(i) = Vec3(unit(random), unit(random), unit(random));
      }
    State direct = start, iterative = start;
    makeImplicitEuler(LinearSolve::Direct)->step(model, direct, h, 1);
    makeImplicitEuler(iterative_solve)->step(model, iterative, h, 1);
    const double change = (direct.velocity - start.velocity).norm();
    ASSERT_GT(change, 0.0);
    EXPECT_LT((direct.velocity - iterative.velocity).norm(), condition * 1e-12 * change)
        << "condition bound " << condition;
  }
}

/// An nx x ny cloth of `mass` [kg] on soft springs (structural 100 N/m, shear 50, bending 10), hanging
/// from its first row's two corners.
ClothDef softCloth(int nx, int ny, double mass)
{
  ClothDef cloth;
  cloth.nx = nx;
  cloth.ny = ny;
  cloth.mass = mass;
  cloth.structural = SpringParameters{ 100.0, 0.02 };
  cloth.shear = SpringParameters{ 50.0, 0.01 };
  cloth.bending = SpringParameters{ 10.0, 0.0 };
  cloth.pinned = { 0, nx - 1 };
  return cloth;
}

/// A chain of 60 nodes of 1 g on 1 cm links of 1e4 N/m, pinned at one end, 2 m above a softCloth.
BodyDef stiffChain()
{
  RopeDef chain;
  chain.nodes = 60;
  chain.from = Vec3(0.0, 0.0, 2.0);
  chain.to = Vec3(0.59, 0.0, 2.0);
  chain.mass = 0.06;
  chain.stiffness = 1e4;
  chain.damping = 0.05;
  chain.pinned = { 0 };
  return buildRope("chain", chain);
}

TEST(ImplicitEulerLinearSolve, DirectAndIterativePathsGiveTheSameStep)
{
  RopeDef chain;  // 40 nodes of 1 g on springs of 1000 N/m: block tridiagonal
  chain.nodes = 40;
  chain.mass = 0.04;
  chain.stiffness = 1000.0;
  chain.damping = 0.05;
  chain.pinned = { 0 };
  expectDirectAndIterativeAgree({ buildRope("chain", chain) }, 1.0 / 39.0);
  RopeDef rope = chain;  // with bending springs: the sparse factorisation
  rope.bending = 100.0;
  expectDirectAndIterativeAgree({ buildRope("rope with bending", rope) }, 1.0 / 39.0);
  // 10 x 8 nodes of 1 g
  expectDirectAndIterativeAgree({ buildCloth("cloth", softCloth(10, 8, 0.08)) }, 1.0 / 9.0);
}

// A cloth large enough that the rule takes conjugate gradients (32 x 32 nodes at 1/60 s), beside a stiff
// chain, which their preconditioner solves exactly (BlockSystem, chain_preconditioner_): the step the
// factorisation gives.
TEST(ImplicitEulerLinearSolve, ConjugateGradientsWithTheChainsSolvedInThePreconditionerGiveTheDirectStep)
{
  expectDirectAndIterativeAgree({ buildCloth("cloth beside a chain", softCloth(32, 32, 0.5)), stiffChain() }, 1.0 / 31.0,
                                LinearSolve::Cheaper);
}

// Conjugate gradients preconditioned by the multigrid cycle (LinearSolve::Multigrid) give the direct
// step on a cloth, on a rope with bending springs (its levels coarsen a line) and on a cloth beside a stiff
// chain; and a 48 x 48 cloth, past kMultigridNodes and stiff enough for block Jacobi's sweeps to cost more
// than the cycle's (h^2 k / m = 128), is given them by the rule (Cheaper), with the same step.
TEST(ImplicitEulerLinearSolve, MultigridConjugateGradientsGiveTheDirectStep)
{
  expectDirectAndIterativeAgree({ buildCloth("cloth", softCloth(10, 8, 0.08)) }, 1.0 / 9.0, LinearSolve::Multigrid);
  RopeDef rope;  // 200 nodes of 1 g on springs of 1000 N/m and bending springs
  rope.nodes = 200;
  rope.mass = 0.2;
  rope.stiffness = 1000.0;
  rope.damping = 0.05;
  rope.bending = 100.0;
  rope.pinned = { 0 };
  expectDirectAndIterativeAgree({ buildRope("rope with bending", rope) }, 1.0 / 199.0, LinearSolve::Multigrid);
  expectDirectAndIterativeAgree({ buildCloth("cloth beside a chain", softCloth(32, 32, 0.5)), stiffChain() }, 1.0 / 31.0,
                                LinearSolve::Multigrid);
  expectDirectAndIterativeAgree({ buildCloth("large cloth", softCloth(48, 48, 0.5)) }, 1.0 / 47.0, LinearSolve::Cheaper);
}

}  // namespace
}  // namespace soft_body_sim::test
