#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <tuple>
#include <utility>

#include "core/elements/element_kinds.h"
#include "core/integrators/implicit_euler/collider_holds.h"
#include "core/integrators/implicit_euler/newton_system.h"
#include "core/integrators/implicit_euler/surface_holds.h"
#include "core/integrators/integrator_kit.h"
#include "soft_body_sim/core/elements/rods.h"

namespace soft_body_sim
{
namespace
{
/// Every element kind's ImplicitBlocks (element_kinds.h), in the registry's order.
template <class List>
struct ImplicitBlocksOf;
template <class... Kinds>
struct ImplicitBlocksOf<KindList<Kinds...>>
{
  using type = std::tuple<typename Kinds::ImplicitBlocks...>;
};
using KindBlocks = ImplicitBlocksOf<ElementKinds>::type;

template <class Tuple, class F>
void forEachOf(Tuple& tuple, F&& f)
{
  std::apply([&](auto&... blocks) { (f(blocks), ...); }, tuple);
}

/// Backward Euler, v_{n+1} = v_n + h M^-1 f(x_n + h v_{n+1}, v_{n+1}), x_{n+1} = x_n + h v_{n+1},
/// solved by Newton's method as in Baraff & Witkin 1998 ("Large steps in cloth simulation"):
/// each iteration linearises f about (x_lin, v_k) and solves
///   (M - h D - h^2 K) dv = h f(x_lin, v_k) + h K (x_n + h v_k - x_lin) - M (v_k - v_n)
/// with K = df/dx, D = df/dv (BlockSystem: directly, block tridiagonally on chains or by a sparse LDL^T, or
/// by preconditioned conjugate gradients, whichever costs less). The first iteration linearises at
/// x_lin = x_n (exactly Baraff & Witkin's step); later ones at x_lin = x_n + h v_k. With soft solids, the
/// iterations go on until the step's equations hold to a tolerance, within a cap (NewtonRule,
/// integrator_kit.h); elsewhere, and where other bodies can meet a solid's surface, `iterations` of them
/// (stepFixedCount). Every element kind adds
/// its forces and blocks (newton_system.h; springs, gas cells, rods and tetrahedra each say how they keep
/// A symmetric positive definite), the damping force's dependence on x neglected, as in Baraff & Witkin;
/// distance constraints are projected after the solve (the constraint pass). Unconditionally stable on a
/// linear spring; first order.
/// The matrix's pattern (which node pairs couple) depends only on the elements and which nodes are
/// pinned: it is analysed on the first step and after every model change, and each Newton iteration only
/// writes its values and factorises. Every array is sized once: a step allocates nothing after the first.
/// Contact on soft solids happens inside the same solve: a solid's nodes are held on the colliders
/// (collider_holds.h), other bodies' nodes on a solid's surface (surface_holds.h).
class ImplicitEuler final : public ForceBasedIntegrator
{
public:
  explicit ImplicitEuler(LinearSolve linear_solve) : system_(linear_solve) {}
  /// Between steps (contacts_ is null then): the pattern, the holds' forces, everything carried.
  std::unique_ptr<Integrator> clone() const override { return std::make_unique<ImplicitEuler>(*this); }
  bool assign(const Integrator& other) override { return assignIfSame(*this, other); }
  /// The pattern as it grew (the elements' pairs, then the holds' as they joined, which fix the
  /// factorisation's order and so its round-off), the holds and the sweeps CG took last (they steer the
  /// choice of solve); the analysis and the slots are made again from them and the model.
  void carry(StateArchive& archive, const Model& model) override
  {
    ForceBasedIntegrator::carry(archive, model);
    std::vector<std::pair<int, int>> pairs = system_.pairs();
    archive(analyzed_, pairs);
    if (archive.reading() && analyzed_)
    {
      analyze(model);
      const std::vector<std::pair<int, int>>& elements = system_.pairs();
      const std::size_t element_pairs = elements.size();
      if (pairs.size() < element_pairs || !std::equal(elements.begin(), elements.end(), pairs.begin()))
        throw std::invalid_argument("snapshot bytes: implicit_euler's pattern is not this model's");
      for (std::size_t k = element_pairs; k < pairs.size(); ++k)
        system_.addPair(pairs[k].first, pairs[k].second);
      if (pairs.size() > element_pairs)
        system_.analyzeSparse();
    }
    archive(collider_holds_, surface_holds_, system_.solidSweepsTaken());
  }

  void modelChanged() override { analyzed_ = false; }

  /// Solids (nodes of tetrahedra) and the cloths with face contacts (nodes of contact triangles) feel the
  /// colliders inside the solve (collider_holds.h).
  void stepWithContacts(const Model& model, State& state, double h, int iterations, ContactQuery* contacts) override
  {
    contacts_ = model.tetrahedra.empty() && model.contact_triangles.empty() ? nullptr : contacts;
    step(model, state, h, iterations);
    contacts_ = nullptr;
  }

  /// With soft solids (tetrahedra), Newton's iterations until the step's equations hold (NewtonRule,
  /// integrator_kit.h): at least `iterations`, at most NewtonRule::kMostIterations (or `iterations`). After
  /// each solve, the system is assembled at the new iterate, whose right-hand side is then the residual
  /// h f(x_n + h v_k, v_k) - M (v_k - v_n) (holds included); if it is small enough the step ends there, its
  /// solve spared. Without solids, and where other bodies can meet a solid's surface, `iterations` exactly
  /// (stepFixedCount).
  void step(const Model& model, State& state, double h, int iterations) override
  {
    const int n = model.nodeCount();
    start_x_ = state.position;
    start_v_ = state.velocity;
    if (!analyzed_)
      analyze(model);
    // One iteration can turn a fast-landing solid's tetrahedra inside out, which no later step undoes; chains
    // and cloths lose nothing to a fixed count and would pay for the rule (a stiff rope 2.5 times, a cloth
    // 1.3 times, measured).
    if (model.tetrahedra.empty() || surface_holds_.present())
    {
      stepFixedCount(model, state, h, iterations);
      return;
    }
    const int most = std::max(iterations, NewtonRule::kMostIterations);
    int solves = 0;
    // x_lin = x_n and the offset h v_n at which K acts on the first iteration (Baraff and Witkin's step).
    offset_.setZero(3, n);
    for (int i = 0; i < n; ++i)
      if (model.isFree(i))
        offset_.col(i) = h * state.velocity.col(i);
    assemble(NewtonPoint{ model, start_x_, state.velocity, state.twist, offset_, h }, true);
    for (;;)
    {
      solve(model);
      for (int i = 0; i < n; ++i)
        if (model.isFree(i))
          state.velocity.col(i) += delta_v_.col(i);
      ++solves;
      if (solves >= most)
        break;
      if (contacts_ != nullptr)
        collider_holds_.letGoPulling(h, delta_v_);
      assembleAtIterate(model, state, h);
      if (solves < iterations || !converged(model, state.velocity, h))
        continue;
      // Converged at the iterate: the holds' forces are the ones assembled there, no solve's change on top.
      delta_v_.setZero();
      break;
    }
    finishStep(model, state, h, iterations);
  }

private:
  /// Without soft solids, and where other bodies can meet a solid's surface (surface_holds.h), `iterations`
  /// Newton iterations exactly. With NewtonRule's there, a rope or a cloth resting on a cube did not come to rest (2 mm/s and 0.1 m/s left
  /// where the fixed count leaves below 1 mm/s, test_surface_contacts) and a rope landing on it at 1/60 s
  /// came within 0.14 of its radius (0.78 with the fixed count).
  void stepFixedCount(const Model& model, State& state, double h, int iterations)
  {
    const int n = model.nodeCount();
    int planned = iterations;
    for (int k = 0; k < planned; ++k)
    {
      const NodeArray& v_k = state.velocity;
      // x_lin and the offset x_n + h v_k - x_lin at which K acts: x_lin = x_n on the first iteration (the
      // offset h v_k), x_n + h v_k on the others (no offset), in the state's positions (linearPositions).
      offset_.setZero(3, n);
      if (k == 0)
      {
        for (int i = 0; i < n; ++i)
          if (model.isFree(i))
            offset_.col(i) = h * v_k.col(i);
      }
      else
        linearPositions(model, state, h);
      assemble(NewtonPoint{ model, k == 0 ? start_x_ : state.position, v_k, state.twist, offset_, h }, k == 0);
      solve(model);
      for (int i = 0; i < n; ++i)
        if (model.isFree(i))
          state.velocity.col(i) += delta_v_.col(i);
      // One more iteration where the velocities carry a triangle into a collider that no hold holds off
      // (findMissedFaces), at most kMissedFacePasses more.
      if (k + 1 == planned && planned < iterations + kMissedFacePasses && contacts_ != nullptr &&
          surface_holds_.findMissedFaces(model, start_x_, state.velocity, h, *contacts_))
        ++planned;
      if (k + 1 < planned)
      {
        if (contacts_ != nullptr)
          collider_holds_.letGoPulling(h, delta_v_);
        surface_holds_.letGoPulling(h, delta_v_);
      }
    }
    finishStep(model, state, h, iterations);
  }

  /// The holds' forces noted (delta_v_: the last solve's change on top of the holds as last assembled), the
  /// positions x_n + h v, the constraint pass, the rods' twists.
  void finishStep(const Model& model, State& state, double h, int iterations)
  {
    if (contacts_ != nullptr)
      collider_holds_.noteForces(model, h, delta_v_, *contacts_);
    surface_holds_.noteForces(h, delta_v_, contacts_);
    for (int i = 0; i < model.nodeCount(); ++i)
      if (model.isFree(i))
        state.position.col(i) = start_x_.col(i) + h * state.velocity.col(i);
    constraints_.apply(model, state, h, iterations);
    for (const Rod& rod : model.rods)
      updateRodTwists(rod, state.position, state.twist);
  }

  /// The pattern: every element kind's node pairs, then the surface holds' (which join as they appear).
  void analyze(const Model& model)
  {
    system_.clearPattern();
    forEachOf(kinds_, [&](auto& blocks) { blocks.analyze(model, system_); });
    collider_holds_.analyze(model);
    surface_holds_.analyze(model, system_);
    // A surface hold couples a node to a triangle of another body, which a chain's pattern has no place
    // for: where holds can arise, the sparse pattern is prepared too, for the steps that have any.
    system_.analyze(model.nodeCount(), surface_holds_.present());
    analyzed_ = true;
  }

  /// A = M - h D - h^2 K and rhs (see the class comment) at `point`: the masses' blocks and the external
  /// forces here, then every element kind's and every hold's.
  void assemble(const NewtonPoint& point, bool first_iteration)
  {
    const Model& model = point.model;
    const double h = point.h;
    system_.start(model.nodeCount());
    NodeArray& rhs = system_.rhs();
    for (int i = 0; i < model.nodeCount(); ++i)
    {
      Eigen::Matrix3d& d = system_.diagonal(i);
      if (!model.isFree(i))
      {
        // Pinned: dv = 0, an identity row.
        rhs.col(i).setZero();
        d.setIdentity();
        continue;
      }
      const double m = model.mass[i];
      const Vec3 f = m * model.gravity - m * model.drag * point.v.col(i);
      rhs.col(i) = h * f - m * (point.v.col(i) - start_v_.col(i));
      d = (m * (1.0 + h * model.drag)) * Eigen::Matrix3d::Identity();
    }
    forEachOf(kinds_, [&](auto& blocks) { blocks.assemble(point, system_); });
    if (contacts_ != nullptr)
      collider_holds_.assemble(point, *contacts_, first_iteration, system_);
    surface_holds_.assemble(point, first_iteration, system_, contacts_);
  }

  /// The blocks that the element kinds and the surface holds keep, as BlockSystem::solve asks for them.
  struct Blocks
  {
    const Model& model;
    const KindBlocks& kinds;
    const SurfaceHolds& holds;

    void multiply(const NodeArray& p, NodeArray& out) const
    {
      std::apply([&](const auto&... blocks) { (blocks.multiply(model, p, out), ...); }, kinds);
      holds.multiply(model, p, out);
    }
    void addToPreconditioner(std::vector<Eigen::Matrix3d>& diagonal) const
    {
      std::apply([&](const auto&... blocks) { (blocks.addToPreconditioner(model, diagonal), ...); }, kinds);
      holds.addToPreconditioner(model, diagonal);
    }
    template <class Solver>
    void write(Solver& solver) const
    {
      std::apply([&](const auto&... blocks) { (blocks.write(model, solver), ...); }, kinds);
      holds.write(model, solver);
    }
  };

  /// delta_v_ = A^-1 rhs; the block-tridiagonal solve serves the steps without surface holds.
  void solve(const Model& model)
  {
    if (!surface_holds_.empty() && !system_.iterativeOnly())
      surface_holds_.placePairs(system_);
    system_.solve(Blocks{ model, kinds_, surface_holds_ }, surface_holds_.empty(), delta_v_);
  }

  /// x_lin = x_n + h v_k, the point of the iterations after the first, in the state's positions: they are
  /// x_n + h v at the step's end (finishStep), and nothing reads them in between (x_n is start_x_).
  void linearPositions(const Model& model, State& state, double h) const
  {
    for (int i = 0; i < model.nodeCount(); ++i)
      if (model.isFree(i))
        state.position.col(i) = start_x_.col(i) + h * state.velocity.col(i);
  }

  /// The system at the iterate v_k: linearised at x_lin = x_n + h v_k (the offset 0), its rhs the residual.
  void assembleAtIterate(const Model& model, State& state, double h)
  {
    offset_.setZero();
    linearPositions(model, state, h);
    assemble(NewtonPoint{ model, state.position, state.velocity, state.twist, offset_, h }, false);
  }

  /// NewtonRule's test on the assembled residual r (rhs): sqrt(sum |r_i|^2 / m_i / sum m_i) at most
  /// NewtonRule::allowedResidualSpeed, over the free nodes.
  bool converged(const Model& model, const NodeArray& v, double h) const
  {
    const NodeArray& r = system_.rhs();
    double weighted_residual = 0.0, mass = 0.0, largest_change = 0.0, fastest = 0.0;
    for (int i = 0; i < model.nodeCount(); ++i)
    {
      if (!model.isFree(i))
        continue;
      weighted_residual += r.col(i).squaredNorm() * model.inverse_mass[i];
      mass += model.mass[i];
      largest_change = std::max(largest_change, (v.col(i) - start_v_.col(i)).norm());
      fastest = std::max(fastest, v.col(i).norm());
    }
    if (!(mass > 0.0))
      return true;  // nothing free: nothing to solve for
    return std::sqrt(weighted_residual / mass) <=
           NewtonRule::allowedResidualSpeed(model.gravity.norm() * h, largest_change, fastest);
  }

  /// The most Newton iterations a step adds for face contacts its solve alone ran into.
  static constexpr int kMissedFacePasses = 2;

  BlockSystem system_;
  KindBlocks kinds_;
  ColliderHolds collider_holds_;
  SurfaceHolds surface_holds_;
  bool analyzed_ = false;  ///< the system holds the pattern of the current model
  NodeArray start_x_, start_v_, offset_;
  NodeArray delta_v_;
  ContactQuery* contacts_ = nullptr;  ///< the colliders during a step with contacts on solids or cloths
};
}  // namespace

std::unique_ptr<Integrator> makeImplicitEuler() { return makeImplicitEuler(LinearSolve::Cheaper); }

std::unique_ptr<Integrator> makeImplicitEuler(LinearSolve solve) { return std::make_unique<ImplicitEuler>(solve); }

}  // namespace soft_body_sim
