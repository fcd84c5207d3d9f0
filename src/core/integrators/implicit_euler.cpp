#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <unordered_map>
#include <utility>
#include <vector>

#include <Eigen/LU>

#include "block_tridiagonal_solver.h"
#include "integrator_kit.h"
#include "sparse_block_solver.h"
#include "soft_body_sim/core/forces.h"
#include "soft_body_sim/core/rods.h"
#include "soft_body_sim/core/surface_contacts.h"
#include "soft_body_sim/core/tetrahedra.h"

namespace soft_body_sim
{
namespace
{
using Matrix3 = Eigen::Matrix3d;

/// Backward Euler, v_{n+1} = v_n + h M^-1 f(x_n + h v_{n+1}, v_{n+1}), x_{n+1} = x_n + h v_{n+1},
/// solved by Newton's method as in Baraff & Witkin 1998 ("Large steps in cloth simulation"):
/// each iteration linearises f about (x_lin, v_k) and solves
///   (M - h D - h^2 K) dv = h f(x_lin, v_k) + h K (x_n + h v_k - x_lin) - M (v_k - v_n)
/// with K = df/dx, D = df/dv, directly (block tridiagonally on chains, BlockTridiagonalSolver, else by a
/// sparse LDL^T factorisation, SparseBlockSolver) or by preconditioned conjugate gradients, whichever
/// costs less (see solve): on a rope the direct solve is linear in the nodes, where conjugate gradients
/// needed hundreds of sweeps on a stiff, light chain (condition number ~ k h^2 / m). The first
/// iteration linearises at
/// x_lin = x_n (exactly Baraff & Witkin's step); later ones at x_lin = x_n + h v_k.
/// K's transverse term k (1 - L/l)(I - u u^T) is dropped when the spring is compressed (Choi & Ko
/// 2002) so that the matrix stays symmetric positive definite; the damping force's dependence on x is
/// neglected, as in Baraff & Witkin. Unconditionally stable on a linear spring; first order.
/// Pressure cells (jelly) enter f with F_k = p dA/dx_k and K with its Gauss-Newton part
///   K_kl = -(d^2E/dA^2) dA/dx_k dA/dx_l^T,
/// dropping p d^2A/dx_k dx_l, which is indefinite (A is bilinear in the positions) and vanishes at
/// rest; the kept part is the one that stiffens without bound as the cell is squeezed.
///
/// Rods (rods.h) enter f with their bending force -2 w J_k^T kb at each vertex (J_k = dkb/dx_k of its
/// three nodes, w its weight) and K with its Gauss-Newton part -2 w J_k^T J_l, dropping 2 w kb . d^2kb,
/// which vanishes straight and keeps K symmetric negative semi-definite; the damping -beta K v
/// (Rod::damping) enters D. Their twist's force -(G J twist / L) d(twist)/dx enters f only, explicitly:
/// its stiffness is rank one and couples every node of the rod (a dense block), and against the bending's
/// it is of order M_t l / (E I) for a twisting moment M_t, l / L near the critical twist of a long rod.
/// A rod's end moment (a couple on its last segment) enters f only, explicitly too: its stiffness M / l^2
/// is 2 pi l / L of the bending's E I / l^3 even at a full circle's moment 2 pi E I / L.
/// Tetrahedra (tetrahedra.h) enter f with their elastic forces and K with their stiffness projected onto
/// the positive semi-definite matrices per tetrahedron (tetForcesAndStiffness), so that A stays symmetric
/// positive definite through any strain and inversion.
/// A spring's 3x3 block is a u u^T + b I (below), a cell's h^2 S g_k g_l^T, a rod vertex's
/// (h^2 + h beta) 2 w J_k^T J_l, a tetrahedron's h^2 K_ab. The matrix's pattern (which
/// node pairs couple) depends only on the elements and which nodes are pinned: it is analysed
/// on the first step and after every model change, and each Newton iteration only writes its values and
/// factorises. Every array is sized once: a step allocates nothing after the first.
/// Other bodies' nodes touching a solid's surface are held on it in the same solve (addSurfaceHolds), their
/// blocks coupling a node to a triangle's three: those node pairs join the analysed pattern when they
/// first appear (placeHoldPairs).
class ImplicitEuler final : public ForceBasedIntegrator
{
public:
  explicit ImplicitEuler(LinearSolve linear_solve) : linear_solve_(linear_solve) {}

  void modelChanged() override { analyzed_ = false; }

  /// Solids (nodes of tetrahedra) feel the colliders inside the solve (see addSolidContacts).
  void stepWithContacts(const Model& model, State& state, double h, int iterations, const ContactQuery* contacts) override
  {
    contacts_ = model.tetrahedra.empty() ? nullptr : contacts;
    step(model, state, h, iterations);
    contacts_ = nullptr;
  }

  void step(const Model& model, State& state, double h, int iterations) override
  {
    const int n = model.nodeCount();
    start_x_ = state.position;
    start_v_ = state.velocity;
    if (!analyzed_)
      analyze(model);
    for (int k = 0; k < iterations; ++k)
    {
      const NodeArray& v_k = state.velocity;
      // x_lin and the offset x_n + h v_k - x_lin at which K acts: x_lin = x_n on the first iteration (the
      // offset h v_k), x_n + h v_k on the others (no offset).
      offset_.setZero(3, n);
      if (k > 0)
        linear_x_ = start_x_;
      for (int i = 0; i < n; ++i)
      {
        if (!model.isFree(i))
          continue;
        if (k == 0)
          offset_.col(i) = h * v_k.col(i);
        else
          linear_x_.col(i) += h * v_k.col(i);
      }
      assemble(model, k == 0 ? start_x_ : linear_x_, v_k, state.twist, h, k == 0);
      solve(model);
      for (int i = 0; i < n; ++i)
        if (model.isFree(i))
          state.velocity.col(i) += delta_v_.col(i);
      if (k + 1 < iterations)
        letGoPullingHolds(h);
    }
    noteHoldForces(h);
    for (int i = 0; i < n; ++i)
      if (model.isFree(i))
        state.position.col(i) = start_x_.col(i) + h * state.velocity.col(i);
    constraints_.apply(model, state, h, iterations);
    for (const Rod& rod : model.rods)
      updateRodTwists(rod, state.position, state.twist);
  }

private:
  /// A spring's block of M - h D - h^2 K: h^2 k (u u^T + t (I - u u^T)) + h c u u^T = a u u^T + b I,
  /// on the diagonal at both ends and negated off the diagonal.
  struct SpringBlock
  {
    Vec3 u;
    double a;
    double b;
  };

  /// A cell's blocks h^2 S g_k g_l^T (g_k = dA/dx_k of its free corners, zero for pinned ones).
  struct CellBlock
  {
    Vec3 g[4];
    double scale;  ///< h^2 S [N/m^3 s^2]
  };

  /// A rod vertex's blocks (h^2 + h beta) 2 w J_k^T J_l: its three nodes (before, at, after; -1 where the
  /// edge is a held end's ghost or the node is pinned) and their Jacobians J_k = dkb/dx_k.
  struct RodBlock
  {
    int nodes[3];
    Matrix3 jacobian[3];
    double scale;  ///< (h^2 + h beta) 2 w [N m^3 s^2]
  };

  /// A tetrahedron's blocks h^2 K_ab (TetStiffness's order) and its nodes (-1 where pinned).
  struct TetBlock
  {
    int nodes[4];
    TetStiffness scaled;
  };

  /// Fills the blocks of A = M - h D - h^2 K and rhs_ (see the class comment) at (x, v), the rods' twists
  /// counted on from `twist` (State::twist).
  void assemble(const Model& model, const NodeArray& x, const NodeArray& v, const Eigen::VectorXd& twist, double h,
                bool first_iteration)
  {
    const int n = model.nodeCount();
    rhs_.resize(3, n);
    diagonal_.resize(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i)
    {
      Matrix3& d = diagonal_[static_cast<std::size_t>(i)];
      if (!model.isFree(i))
      {
        // Pinned: dv = 0, an identity row.
        rhs_.col(i).setZero();
        d.setIdentity();
        continue;
      }
      // The external forces here; the springs' and cells' below, where their blocks are made.
      const double m = model.mass[i];
      const Vec3 f = m * model.gravity - m * model.drag * v.col(i);
      rhs_.col(i) = h * f - m * (v.col(i) - start_v_.col(i));
      d = (m * (1.0 + h * model.drag)) * Matrix3::Identity();
    }
    springs_.resize(model.springs.size());
    length_.resize(model.springs.size());
    inverse_length_.resize(model.springs.size());
    // Each spring's axis as springAxis gives it, but with one division where it takes four (u = d / l,
    // then L / l below), in a loop of its own: short, so that the processor overlaps the square roots and
    // divisions of many springs (on a rope, they were most of the assembly's time).
    for (std::size_t k = 0; k < model.springs.size(); ++k)
    {
      const Spring& s = model.springs[k];
      const Vec3 axis = x.col(s.a) - x.col(s.b);
      const double length = axis.norm();
      length_[k] = length;
      inverse_length_[k] = length < kMinSpringLength ? 0.0 : 1.0 / length;
      springs_[k].u = axis * inverse_length_[k];
    }
    condition_ = 1.0;
    for (std::size_t k = 0; k < model.springs.size(); ++k)
    {
      const Spring& s = model.springs[k];
      SpringBlock& block = springs_[k];
      const double inverse_length = inverse_length_[k];
      if (inverse_length == 0.0)
      {
        block = SpringBlock{ Vec3::Zero(), 0.0, 0.0 };  // coincident ends: no force, no block
        continue;
      }
      const double length = length_[k];
      // -df_a/dx_a of the spring (clamped, see above) is k ((1 - t) u u^T + t I) with t = (1 - L/l)^+, and
      // -df_a/dv_a of its dashpot c u u^T: the block h^2 k ((1 - t) u u^T + t I) + h c u u^T = a u u^T + b I.
      const double transverse = std::max(0.0, 1.0 - s.rest_length * inverse_length);
      block.a = h * h * s.stiffness * (1.0 - transverse) + h * s.damping;
      block.b = h * h * s.stiffness * transverse;
      Matrix3 diagonal = block.a * (block.u * block.u.transpose());
      diagonal.diagonal().array() += block.b;
      const Vec3 d = offset_.col(s.a) - offset_.col(s.b);
      const Vec3 k_offset =
          -s.stiffness * ((1.0 - transverse) * block.u.dot(d) * block.u + transverse * d);
      // h (f_a + K offset) on end a, its negative on end b (f_a as in accumulateSpringForces).
      const Vec3 impulse = h * (k_offset - springTension(s, block.u, length, v) * block.u);
      // The preconditioned A's largest eigenvalue over its smallest is about 1 + 4 (h^2 k + h c) / m
      // for the stiffest spring on its lightest free end (a chain's: (m + 4 h^2 k) / m). Springs only:
      // a jelly's stiff cells are left out, which can only make the direct path look dearer than it is.
      const double lightest = std::max(model.inverse_mass[s.a], model.inverse_mass[s.b]);
      condition_ = std::max(condition_, 1.0 + 4.0 * (h * h * s.stiffness + h * s.damping) * lightest);
      const bool a_free = model.isFree(s.a);
      const bool b_free = model.isFree(s.b);
      if (a_free)
      {
        rhs_.col(s.a) += impulse;
        diagonal_[static_cast<std::size_t>(s.a)] += diagonal;
      }
      if (b_free)
      {
        rhs_.col(s.b) -= impulse;
        diagonal_[static_cast<std::size_t>(s.b)] += diagonal;
      }
    }
    if (!model.cells.empty())
    {
      force_.setZero(3, n);
      accumulatePressureForces(model, x, force_);
      for (int i = 0; i < n; ++i)
        if (model.isFree(i))
          rhs_.col(i) += h * force_.col(i);
    }
    cells_.resize(model.cells.size());
    for (std::size_t k = 0; k < model.cells.size(); ++k)
      addCell(model, model.cells[k], x, h, cells_[k]);
    if (!model.rods.empty())
      addRods(model, x, v, twist, h);
    if (!model.tetrahedra.empty())
      addTetrahedra(model, x, h);
    if (contacts_ != nullptr)
      addSolidContacts(model, x, v, h, first_iteration);
    if (surface_contacts_.has_value())
      addSurfaceHolds(model, x, v, h, first_iteration);
  }

  /// A node of another body held on a solid's boundary triangle in the solve (addSurfaceHolds).
  struct SurfaceHold
  {
    SurfaceTouch touch;  ///< as found at the step's first Newton iteration (node p, triangle, weights, n)
    int nodes[4];        ///< p, then the triangle's three nodes, each -1 where pinned
    double weights[4];   ///< 1, -w_0, -w_1, -w_2: the gap x_p - q = sum_l weights_l x_l
    double depth;        ///< d [m] at this iteration's predicted positions
    double scaled;       ///< h^2 k [kg] in this iteration
    Matrix3 block;       ///< B = h^2 k n n^T + h c (I - n n^T); A gains weights_l weights_m B on (l, m)
  };

  /// The surface holds of a step: as a solid's node is held on a collider (addSolidContacts), a node p of
  /// another body (a rope's, a cloth's, another solid's) whose predicted position lies within its contact
  /// radius of a solid's boundary triangle, or behind it (SurfaceContacts::find), or, if its hold pushed in
  /// the last step, within max(|g| h^2, r_p / 2) of that (findSurfaceHolds), is held by a one-sided spring
  /// on the gap
  /// g = n . (x_p - q) - r_p, q = sum_k w_k x_k the triangle's nearest point at weights w: the Jacobian of
  /// g is weights_l n^T on the four nodes, so the node and the triangle's nodes push each other apart with
  /// equal and opposite forces (momentum kept) and A gains h^2 k weights_l weights_m n n^T. k is
  /// kContactStiffness times the contact's effective mass b = 1 / sum_l weights_l^2 / b_l (b_l the free
  /// nodes' diagonal means): the solve leaves about 1 / kContactStiffness of the depth. Coulomb friction
  /// damps their relative velocity across n as on a collider, pressed by max(b d / h^2, the hold's force
  /// in the last step), the solid's `friction` (two solids': the mean).
  void addSurfaceHolds(const Model& model, const NodeArray& x, const NodeArray& v, double h, bool first_iteration)
  {
    if (first_iteration)
      findSurfaceHolds(model, x, h);
    for (SurfaceHold& c : surface_holds_)
    {
      const Vec3& n = c.touch.normal;
      Vec3 gap = Vec3::Zero(), relative = Vec3::Zero();
      double inverse_block = 0.0;
      const int all[4] = { c.touch.node, c.touch.triangle[0], c.touch.triangle[1], c.touch.triangle[2] };
      for (int l = 0; l < 4; ++l)
      {
        gap += c.weights[l] * (x.col(all[l]) + offset_.col(all[l]));
        relative += c.weights[l] * v.col(all[l]);
        if (c.nodes[l] >= 0)
          inverse_block += c.weights[l] * c.weights[l] / (diagonal_[static_cast<std::size_t>(c.nodes[l])].trace() / 3.0);
      }
      c.depth = c.touch.depth - n.dot(gap - c.touch.gap);
      c.scaled = 0.0;
      c.block.setZero();
      if (!(inverse_block > 0.0))
        continue;  // all four pinned
      const double block = 1.0 / inverse_block;  // b [kg]
      c.scaled = kContactStiffness * block;
      Vec3 push = (c.scaled / h * c.depth) * n;
      c.block = c.scaled * (n * n.transpose());
      const double normal_force =
          std::max(block * c.depth / (h * h), surface_hold_force_[static_cast<std::size_t>(c.touch.node)]);
      Vec3 tangential;
      const double damping = frictionDamping(c.touch.friction, normal_force, relative, n, tangential);
      if (damping > 0.0)
      {
        push -= h * damping * tangential;
        c.block += h * damping * (Matrix3::Identity() - n * n.transpose());
      }
      for (int l = 0; l < 4; ++l)
        if (c.nodes[l] >= 0)
          rhs_.col(c.nodes[l]) += c.weights[l] * push;
    }
  }

  /// The surface holds of a step (addSurfaceHolds), found at its first Newton iteration and kept through the
  /// others.
  void findSurfaceHolds(const Model& model, const NodeArray& x, double h)
  {
    const double margin = model.gravity.norm() * h * h;
    predicted_ = x + offset_;
    surface_contacts_->find(model, x, predicted_, std::max(margin, 0.5 * surface_contacts_->widestRadius()), touches_);
    surface_holds_.clear();
    for (const SurfaceTouch& touch : touches_)
    {
      // A hold that pushed in the last step is kept while the node stays within half its radius (or |g| h^2)
      // of the surface: released as soon as the push has set it moving off, it would fall back in the next
      // step and be pushed out again, a bounce every other step (seen at 1/240 s on a rope over an edge).
      const double keep = std::max(margin, 0.5 * model.contact_radius[touch.node]);
      if (touch.depth <= (surface_hold_force_[static_cast<std::size_t>(touch.node)] > 0.0 ? -keep : 0.0))
        continue;
      SurfaceHold c;
      c.touch = touch;
      const int all[4] = { touch.node, touch.triangle[0], touch.triangle[1], touch.triangle[2] };
      for (int l = 0; l < 4; ++l)
      {
        c.weights[l] = l == 0 ? 1.0 : -touch.weight[l - 1];
        c.nodes[l] = model.isFree(all[l]) ? all[l] : -1;
      }
      surface_holds_.push_back(c);
    }
  }

  /// k (d - h n . sum_l weights_l dv_l) [N]: the force surface hold `c` took in the Newton iteration just
  /// solved (> 0 pushing).
  double holdForce(const SurfaceHold& c, double h) const
  {
    Vec3 dv = Vec3::Zero();
    for (int l = 0; l < 4; ++l)
      if (c.nodes[l] >= 0)
        dv += c.weights[l] * delta_v_.col(c.nodes[l]);
    return c.scaled / (h * h) * (c.depth - h * c.touch.normal.dot(dv));
  }

  /// A solid's node held on a collider's surface in the solve (addSolidContacts).
  struct SolidContact
  {
    int node;
    NodeContact contact;  ///< as found at the step's first Newton iteration
    Vec3 found_at;        ///< [m] the node's predicted position then
    double found_depth;   ///< [m] its depth then, at the step's end (the surface moved on by h v_s)
    double depth;         ///< d [m] at the step's end, the node at this iteration's predicted position
    double scaled;        ///< h^2 k [kg] in this iteration
  };

  /// A solid's nodes that the step would carry into a collider meet it inside the solve, so that the whole
  /// solid decelerates in the step where it lands and rests on the surface without sinking into it step
  /// after step: the contact stage after the step (contact.h) stops only the nodes that reached the
  /// surface, so a solid landing fast (a cube dropped from 5 m, its bottom layer stopped within a step
  /// where the layer above moves more than its thickness) would turn its bottom tetrahedra inside out, and
  /// a resting one would fall freely in every solve and be pushed back only at its bottom nodes (measured:
  /// an 8 cm box sagging 1.8 mm at 4 ms steps, whatever its stiffness).
  /// A free node of a tetrahedron is held when its predicted position x + offset lies, at the step's end
  /// (the surface moved on by h v_s), inside a collider (ContactQuery) at a depth d > 0, or less than
  /// |g| h^2 outside it (d > -|g| h^2: resting on it) unless its hold pulled it at the end of the last
  /// step (it is leaving). It is held on the surface along the normal n by a spring of
  /// stiffness k with h^2 k = kContactStiffness times its diagonal block's mean eigenvalue b: the block
  /// gains h^2 k n n^T and rhs_ h k d n, so that the solve leaves about 1 / kContactStiffness of d.
  /// Coulomb friction acts in the same solve, as a damping of the velocity relative to the surface across
  /// n, of coefficient c = friction N / max(|v_t|, kStickSpeed), N the larger of b d / h^2, the force that
  /// stops the node's approach (its momentum b d / h over the step), and the force its hold took in the
  /// last step (noteHoldForces; a resting node's weight): the block gains h c (I - n n^T) and
  /// rhs_ -h c v_t. Sliding (h c << b) it takes friction N h / b of the tangential speed v_t, as
  /// Coulomb's law; where that is more than v_t (h c >> b) the node sticks. The contact stage then
  /// removes what depth remains. Other bodies keep the contact stage alone.
  void addSolidContacts(const Model& model, const NodeArray& x, const NodeArray& v, double h, bool first_iteration)
  {
    if (first_iteration)
      findSolidContacts(model, x, h);
    for (SolidContact& c : solid_contacts_)
    {
      const int i = c.node;
      const Vec3 n = c.contact.normal;
      // The same surface, planar about where it was found, at this iteration's predicted position.
      c.depth = c.found_depth - n.dot(x.col(i) + offset_.col(i) - c.found_at);
      Matrix3& d = diagonal_[static_cast<std::size_t>(i)];
      const double block = d.trace() / 3.0;  // b [kg]
      c.scaled = kContactStiffness * block;  // h^2 k
      rhs_.col(i) += (c.scaled / h * c.depth) * n;
      d += c.scaled * (n * n.transpose());
      // A hold that pulled in the last step (< 0) adds nothing: only the approach's force presses then.
      const double normal_force = std::max(block * c.depth / (h * h), hold_force_[static_cast<std::size_t>(i)]);
      Vec3 tangential;
      const double damping =
          frictionDamping(c.contact.friction, normal_force, v.col(i) - c.contact.velocity, n, tangential);
      if (!(damping > 0.0))
        continue;
      rhs_.col(i) -= h * damping * tangential;
      d += h * damping * (Matrix3::Identity() - n * n.transpose());
    }
  }

  /// The holds of a step (addSolidContacts), found at its first Newton iteration and kept through the others.
  void findSolidContacts(const Model& model, const NodeArray& x, double h)
  {
    NodeContact contact;
    solid_contacts_.clear();
    const double margin = model.gravity.norm() * h * h;
    for (int i = 0; i < model.nodeCount(); ++i)
    {
      if (!solid_node_[static_cast<std::size_t>(i)] || !model.isFree(i))
        continue;
      const Vec3 predicted = x.col(i) + offset_.col(i);
      if (!contacts_->touching(model, i, predicted, margin, contact))
        continue;
      const double depth = contact.depth + h * contact.velocity.dot(contact.normal);
      if (depth > (hold_force_[static_cast<std::size_t>(i)] < 0.0 ? 0.0 : -margin))
        solid_contacts_.push_back({ i, contact, predicted, depth, depth, 0.0 });
    }
  }

  /// k (d - h n . dv) [N]: the force hold `c` took in the Newton iteration just solved (> 0 pushing).
  double holdForce(const SolidContact& c, double h) const
  {
    return c.scaled / (h * h) * (c.depth - h * c.contact.normal.dot(delta_v_.col(c.node)));
  }

  /// Drops the holds that pulled in the Newton iteration just solved, for the step's later iterations: the
  /// ballistic prediction that found them holds every node that would cross the surface in the step, also
  /// those that the solid's own elasticity stops above it (a landing's second layer of nodes; held, it
  /// would be pressed onto the first, its tetrahedra flat).
  void letGoPullingHolds(double h)
  {
    if (contacts_ != nullptr)
      solid_contacts_.erase(std::remove_if(solid_contacts_.begin(), solid_contacts_.end(),
                                           [&](const SolidContact& c) { return holdForce(c, h) < 0.0; }),
                            solid_contacts_.end());
    if (surface_contacts_.has_value())
      surface_holds_.erase(std::remove_if(surface_holds_.begin(), surface_holds_.end(),
                                          [&](const SurfaceHold& c) { return holdForce(c, h) < 0.0; }),
                           surface_holds_.end());
  }

  /// The force each hold of the last Newton iteration took, k (d - h n . dv) at its node's new depth: where
  /// it pulled (< 0) the node is held in the next step only if it is carried into the surface
  /// (addSolidContacts), where it pushed it is the normal force of the node's friction in the next step (a
  /// node resting on the surface, whose predicted depth is about 0, presses on it with its share of the
  /// weight). Every other solid node may be held again, with no force known.
  void noteHoldForces(double h)
  {
    if (contacts_ != nullptr)
    {
      std::fill(hold_force_.begin(), hold_force_.end(), 0.0);
      for (const SolidContact& c : solid_contacts_)
        hold_force_[static_cast<std::size_t>(c.node)] = holdForce(c, h);
    }
    if (surface_contacts_.has_value())
    {
      std::fill(surface_hold_force_.begin(), surface_hold_force_.end(), 0.0);
      for (const SurfaceHold& c : surface_holds_)
        surface_hold_force_[static_cast<std::size_t>(c.touch.node)] = holdForce(c, h);
    }
  }

  /// Coulomb friction of a hold as a damping of its slip (addSolidContacts, addSurfaceHolds): the part v_t
  /// of the `relative` velocity across n into `tangential`, and c = friction N / max(|v_t|, kStickSpeed)
  /// [kg/s], 0 without friction or without a pressing force N. The hold's row gains -h c v_t, its block
  /// h c (I - n n^T).
  static double frictionDamping(double friction, double normal_force, const Vec3& relative, const Vec3& n,
                                Vec3& tangential)
  {
    tangential = relative - relative.dot(n) * n;
    if (!(friction > 0.0 && normal_force > 0.0))
      return 0.0;
    return friction * normal_force / std::max(tangential.norm(), kStickSpeed);
  }

  /// [m/s] below this tangential speed a solid's contact sticks (its friction's damping no longer grows).
  static constexpr double kStickSpeed = 1e-4;

  /// A held contact's stiffness relative to its node's diagonal block (see addSolidContacts).
  static constexpr double kContactStiffness = 1000.0;

  /// The tetrahedra's blocks (their diagonal ones into diagonal_) and h (f + K offset) in rhs_ (K = -df/dx).
  /// The condition estimate takes each node's block of one tetrahedron as a spring's (see condition_).
  void addTetrahedra(const Model& model, const NodeArray& x, double h)
  {
    tet_blocks_.resize(model.tetrahedra.size());
    Eigen::Matrix<double, 3, 4> force;
    for (std::size_t k = 0; k < model.tetrahedra.size(); ++k)
    {
      const Tetrahedron& tet = model.tetrahedra[k];
      TetBlock& block = tet_blocks_[k];
      tetForcesAndStiffness(tet, x, true, force, block.scaled);
      for (int a = 0; a < 4; ++a)
        block.nodes[a] = model.isFree(tet.nodes[a]) ? tet.nodes[a] : -1;
      // rhs_a += h f_a - h sum_b K_ab offset_b, over the free b (a pinned node's offset is 0).
      for (int a = 0; a < 4; ++a)
        if (block.nodes[a] >= 0)
          rhs_.col(block.nodes[a]) += h * (force.col(a) - block.scaled.blocks[a] * offset_.col(block.nodes[a]));
      for (std::size_t p = 0; p < kTetPairs.size(); ++p)
      {
        const int a = kTetPairs[p].first, b = kTetPairs[p].second;
        const Matrix3& k_ab = block.scaled.blocks[4 + p];
        if (block.nodes[a] >= 0)
          rhs_.col(block.nodes[a]) -= h * (k_ab * offset_.col(tet.nodes[b]));
        if (block.nodes[b] >= 0)
          rhs_.col(block.nodes[b]) -= h * (k_ab.transpose() * offset_.col(tet.nodes[a]));
      }
      for (Matrix3& k_ab : block.scaled.blocks)
        k_ab *= h * h;
      for (int a = 0; a < 4; ++a)
        if (block.nodes[a] >= 0)
        {
          diagonal_[static_cast<std::size_t>(block.nodes[a])] += block.scaled.blocks[a];
          condition_ = std::max(condition_, 1.0 + 4.0 * block.scaled.blocks[a].trace() * model.inverse_mass[tet.nodes[a]]);
        }
    }
  }

  /// The rods' bending blocks (on the diagonal here; off it in multiply and solveDirectly) and their
  /// bending, damping and twist forces in rhs_: per vertex, with q = sum_l J_l offset_l and
  /// r = sum_l J_l v_l, rhs_k -= 2 w h J_k^T (kb + q + beta r); per interval between two stations,
  /// rhs_i -= h (G J twist / L) d(twist)/dx_i; and h times the rods' end moments.
  void addRods(const Model& model, const NodeArray& x, const NodeArray& v, const Eigen::VectorXd& twist, double h)
  {
    rod_blocks_.resize(rod_vertices_.size());
    for (std::size_t k = 0; k < rod_vertices_.size(); ++k)
    {
      const RodVertex& vertex = rod_vertices_[k];
      const Rod& rod = model.rods[static_cast<std::size_t>(rod_of_vertex_[k])];
      Vec3 e0, e1;
      vertexEdges(rod, vertex, x, e0, e1);
      const CurvatureBinormal bend = curvatureBinormal(e0, e1, rod.segment_length * rod.segment_length);
      RodBlock& block = rod_blocks_[k];
      // x_before enters e0 negatively, x_at e0 positively and e1 negatively, x_after e1 positively.
      block.nodes[0] = vertex.before;
      block.nodes[1] = vertex.at;
      block.nodes[2] = vertex.after;
      block.jacobian[0] = -bend.d_e0;
      block.jacobian[1] = (vertex.before < 0 ? Matrix3::Zero() : bend.d_e0) - (vertex.after < 0 ? Matrix3::Zero() : bend.d_e1);
      block.jacobian[2] = bend.d_e1;
      block.scale = 2.0 * vertex.weight * (h * h + h * rod.damping);
      Vec3 q = Vec3::Zero(), r = Vec3::Zero();
      for (int c = 0; c < 3; ++c)
      {
        if (block.nodes[c] < 0 || !model.isFree(block.nodes[c]))
        {
          block.nodes[c] = -1;
          continue;
        }
        q += block.jacobian[c] * offset_.col(block.nodes[c]);
        r += block.jacobian[c] * v.col(block.nodes[c]);
      }
      const Vec3 pull = 2.0 * vertex.weight * h * (bend.kb + q + rod.damping * r);
      for (int c = 0; c < 3; ++c)
      {
        const int node = block.nodes[c];
        if (node < 0)
          continue;
        rhs_.col(node) -= block.jacobian[c].transpose() * pull;
        diagonal_[static_cast<std::size_t>(node)] += block.scale * block.jacobian[c].transpose() * block.jacobian[c];
      }
    }
    force_.setZero(3, model.nodeCount());
    for (const Rod& rod : model.rods)
    {
      accumulateTwistForces(rod, x, twist, force_);
      accumulateRodEndMoment(rod, x, force_);
    }
    for (int i = 0; i < model.nodeCount(); ++i)
      if (model.isFree(i))
        rhs_.col(i) += h * force_.col(i);
  }

  /// Block Jacobi for conjugate gradients: the inverse of each node's full 3x3 diagonal block (springs'
  /// and cells'; SPD, so invertible).
  void buildPreconditioner(const Model& model)
  {
    const int n = model.nodeCount();
    preconditioner_.resize(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i)
      preconditioner_[static_cast<std::size_t>(i)] = diagonal_[static_cast<std::size_t>(i)];
    for (std::size_t k = 0; k < cells_.size(); ++k)
      for (int c = 0; c < 4; ++c)
        preconditioner_[static_cast<std::size_t>(model.cells[k].nodes[c])] +=
            cells_[k].scale * cells_[k].g[c] * cells_[k].g[c].transpose();
    for (const SurfaceHold& c : surface_holds_)
      for (int l = 0; l < 4; ++l)
        if (c.nodes[l] >= 0)
          preconditioner_[static_cast<std::size_t>(c.nodes[l])] += (c.weights[l] * c.weights[l]) * c.block;
    for (int i = 0; i < n; ++i)
    {
      Matrix3& p = preconditioner_[static_cast<std::size_t>(i)];
      p = p.inverse().eval();
    }
  }

  /// The cell's share of rhs_ (h K offset, with (K offset)_k = -S g_k sum_l g_l . offset_l) on its
  /// free corners, and its blocks (its corners' g, zero at a pinned one).
  void addCell(const Model& model, const PressureCell& cell, const NodeArray& x, double h, CellBlock& block)
  {
    const double stiffness = cellGas(cell, cellArea(cell, x, block.g)).stiffness;
    double g_dot_offset = 0.0;
    for (int k = 0; k < 4; ++k)
      g_dot_offset += block.g[k].dot(offset_.col(cell.nodes[k]));
    block.scale = h * h * stiffness;
    for (int k = 0; k < 4; ++k)
    {
      const int row = cell.nodes[k];
      if (!model.isFree(row))
      {
        block.g[k].setZero();
        continue;
      }
      rhs_.col(row) -= (h * stiffness * g_dot_offset) * block.g[k];
    }
  }

  /// out = A p.
  void multiply(const Model& model, const NodeArray& p, NodeArray& out) const
  {
    const int n = model.nodeCount();
    for (int i = 0; i < n; ++i)
      out.col(i) = diagonal_[static_cast<std::size_t>(i)] * p.col(i);
    for (std::size_t k = 0; k < springs_.size(); ++k)
    {
      const SpringBlock& block = springs_[k];
      if (spring_slot_[k] < 0)
        continue;  // an end pinned: no off-diagonal block
      const Spring& s = model.springs[k];
      const Vec3 p_a = p.col(s.a);
      const Vec3 p_b = p.col(s.b);
      out.col(s.a) -= block.a * block.u.dot(p_b) * block.u + block.b * p_b;
      out.col(s.b) -= block.a * block.u.dot(p_a) * block.u + block.b * p_a;
    }
    for (std::size_t k = 0; k < cells_.size(); ++k)
    {
      const CellBlock& block = cells_[k];
      const PressureCell& cell = model.cells[k];
      double g_dot_p = 0.0;
      for (int l = 0; l < 4; ++l)
        g_dot_p += block.g[l].dot(p.col(cell.nodes[l]));
      for (int l = 0; l < 4; ++l)
        out.col(cell.nodes[l]) += (block.scale * g_dot_p) * block.g[l];
    }
    for (const RodBlock& block : rod_blocks_)
      for (int c = 0; c < 3; ++c)
      {
        if (block.nodes[c] < 0)
          continue;
        Vec3 j_p = Vec3::Zero();  // sum over the vertex's other nodes of J_l p_l
        for (int l = 0; l < 3; ++l)
          if (l != c && block.nodes[l] >= 0)
            j_p += block.jacobian[l] * p.col(block.nodes[l]);
        out.col(block.nodes[c]) += block.scale * (block.jacobian[c].transpose() * j_p);
      }
    for (const TetBlock& block : tet_blocks_)
      for (std::size_t pair = 0; pair < kTetPairs.size(); ++pair)
      {
        const int a = block.nodes[kTetPairs[pair].first], b = block.nodes[kTetPairs[pair].second];
        if (a < 0 || b < 0)
          continue;
        const Matrix3& k_ab = block.scaled.blocks[4 + pair];
        out.col(a) += k_ab * p.col(b);
        out.col(b) += k_ab.transpose() * p.col(a);
      }
    // The surface holds' blocks in full, their diagonal ones too (they are not in diagonal_).
    for (const SurfaceHold& c : surface_holds_)
    {
      Vec3 gap = Vec3::Zero();
      for (int l = 0; l < 4; ++l)
        if (c.nodes[l] >= 0)
          gap += c.weights[l] * p.col(c.nodes[l]);
      const Vec3 pushed = c.block * gap;
      for (int l = 0; l < 4; ++l)
        if (c.nodes[l] >= 0)
          out.col(c.nodes[l]) += c.weights[l] * pushed;
    }
  }

  void precondition(const NodeArray& r, NodeArray& z) const
  {
    for (Eigen::Index i = 0; i < r.cols(); ++i)
      z.col(i) = preconditioner_[static_cast<std::size_t>(i)] * r.col(i);
  }

  static double dot(const NodeArray& a, const NodeArray& b) { return a.cwiseProduct(b).sum(); }

  /// delta_v_ = A^-1 rhs_ by preconditioned conjugate gradients from 0, stopped at a relative residual
  /// of kTolerance or after 2 * 3n iterations (the algorithm and the stopping rule of Eigen's
  /// ConjugateGradient), multiplying by the blocks directly, preconditioned by the inverse of each node's
  /// 3x3 diagonal block.
  void solveIteratively(const Model& model)
  {
    const Eigen::Index n = rhs_.cols();
    delta_v_.setZero(3, n);
    residual_ = rhs_;
    const double rhs_norm2 = rhs_.squaredNorm();
    if (rhs_norm2 == 0.0)
      return;
    const double threshold = std::max(kTolerance * kTolerance * rhs_norm2, std::numeric_limits<double>::min());
    double residual_norm2 = rhs_norm2;
    if (residual_norm2 < threshold)
      return;  // rhs so small (near underflow) that any iteration would divide by zero
    direction_.resize(3, n);
    z_.resize(3, n);
    product_.resize(3, n);
    precondition(residual_, direction_);
    double r_dot_z = dot(residual_, direction_);
    const Eigen::Index max_iterations = 2 * 3 * n;
    for (Eigen::Index iteration = 0; iteration < max_iterations; ++iteration)
    {
      multiply(model, direction_, product_);
      const double alpha = r_dot_z / dot(direction_, product_);
      delta_v_ += alpha * direction_;
      residual_ -= alpha * product_;
      residual_norm2 = residual_.squaredNorm();
      if (residual_norm2 < threshold)
        break;
      precondition(residual_, z_);
      const double previous_r_dot_z = r_dot_z;
      r_dot_z = dot(residual_, z_);
      direction_ = z_ + (r_dot_z / previous_r_dot_z) * direction_;
    }
  }

  /// CG stops at a relative residual of 1e-12: far below the scheme's O(h) error; without it CG would
  /// iterate to machine precision (up to 6n sweeps).
  static constexpr double kTolerance = 1e-12;

  /// The node pairs whose blocks of A may be non-zero, one slot each: every spring with both ends free,
  /// then every pair of free corners of every cell (six per cell, in kFourNodePairs' order).
  void analyze(const Model& model)
  {
    std::vector<std::pair<int, int>>& pairs = pairs_;
    pairs.clear();
    spring_slot_.assign(model.springs.size(), -1);
    for (std::size_t k = 0; k < model.springs.size(); ++k)
    {
      const Spring& s = model.springs[k];
      if (model.isFree(s.a) && model.isFree(s.b) && s.a != s.b)
      {
        spring_slot_[k] = static_cast<int>(pairs.size());
        pairs.emplace_back(s.a, s.b);
      }
    }
    cell_slot_.assign(6 * model.cells.size(), -1);
    for (std::size_t k = 0; k < model.cells.size(); ++k)
      for (std::size_t p = 0; p < kFourNodePairs.size(); ++p)
      {
        const int a = model.cells[k].nodes[kFourNodePairs[p].first], b = model.cells[k].nodes[kFourNodePairs[p].second];
        if (model.isFree(a) && model.isFree(b) && a != b)
        {
          cell_slot_[6 * k + p] = static_cast<int>(pairs.size());
          pairs.emplace_back(a, b);
        }
      }
    rod_vertices_.clear();
    rod_of_vertex_.clear();
    for (std::size_t r = 0; r < model.rods.size(); ++r)
    {
      appendRodVertices(model.rods[r], rod_vertices_);
      rod_of_vertex_.resize(rod_vertices_.size(), static_cast<int>(r));
    }
    rod_slot_.assign(3 * rod_vertices_.size(), -1);
    for (std::size_t k = 0; k < rod_vertices_.size(); ++k)
    {
      const RodVertex& vertex = rod_vertices_[k];
      const int nodes[3] = { vertex.before, vertex.at, vertex.after };
      for (std::size_t p = 0; p < kRodPairs.size(); ++p)
      {
        const int a = nodes[kRodPairs[p].first], b = nodes[kRodPairs[p].second];
        if (a >= 0 && b >= 0 && model.isFree(a) && model.isFree(b))
        {
          rod_slot_[3 * k + p] = static_cast<int>(pairs.size());
          pairs.emplace_back(a, b);
        }
      }
    }
    solid_node_.assign(static_cast<std::size_t>(model.nodeCount()), 0);
    hold_force_.assign(static_cast<std::size_t>(model.nodeCount()), 0.0);
    solid_contacts_.clear();
    solid_contacts_.reserve(static_cast<std::size_t>(model.nodeCount()));
    for (const Tetrahedron& tet : model.tetrahedra)
      for (const int node : tet.nodes)
        solid_node_[static_cast<std::size_t>(node)] = 1;
    surface_contacts_.emplace(model);
    if (model.tetrahedra.empty() || surface_contacts_->empty())
      surface_contacts_.reset();
    surface_hold_force_.assign(static_cast<std::size_t>(model.nodeCount()), 0.0);
    surface_holds_.clear();
    if (surface_contacts_.has_value())
    {
      // A node touches at most one triangle of each solid.
      const std::size_t most = static_cast<std::size_t>(model.nodeCount()) * model.bodies.size();
      surface_holds_.reserve(most);
      touches_.reserve(most);
    }
    tet_slot_.assign(6 * model.tetrahedra.size(), -1);
    for (std::size_t k = 0; k < model.tetrahedra.size(); ++k)
      for (std::size_t p = 0; p < kTetPairs.size(); ++p)
      {
        const int a = model.tetrahedra[k].nodes[kTetPairs[p].first], b = model.tetrahedra[k].nodes[kTetPairs[p].second];
        if (model.isFree(a) && model.isFree(b))
        {
          tet_slot_[6 * k + p] = static_cast<int>(pairs.size());
          pairs.emplace_back(a, b);
        }
      }
    base_pairs_ = pairs.size();
    hold_slot_.clear();
    // A surface hold couples a node to a triangle of another body, which a chain's pattern has no place
    // for: where holds can arise, the sparse pattern is prepared too, for the steps that have any.
    chains_ = linear_solve_ != LinearSolve::Iterative && chain_solver_.analyze(model.nodeCount(), pairs);
    factorable_ = (chains_ && !surface_contacts_.has_value()) ||
                  (linear_solve_ != LinearSolve::Iterative &&
                   solver_.analyze(model.nodeCount(), pairs,
                                   linear_solve_ == LinearSolve::Direct ? kAnyWork : kMaxFactorWork));
    analyzed_ = true;
  }

  /// Gives every node pair of every surface hold (the node with the triangle's three, and those among
  /// themselves) a slot of solver_ (hold_slots_, six per hold in kFourNodePairs' order, -1 where a node is
  /// pinned). A pair not yet in the pattern has the pattern analysed again with it, the pairs of earlier
  /// holds kept unless they are more than kKeptHoldPairs times the present holds' (then only these):
  /// resting contact keeps its pattern from step to step, sliding contact pays an analysis when it
  /// reaches a new triangle, and pairs of contacts long gone do not pile up.
  void placeHoldPairs(const Model& model)
  {
    const auto key = [](int a, int b) {
      return (static_cast<std::uint64_t>(std::min(a, b)) << 32) | static_cast<std::uint64_t>(std::max(a, b));
    };
    bool missing = false;
    for (const SurfaceHold& c : surface_holds_)
      for (const auto& [l, m] : kFourNodePairs)
        missing = missing || (c.nodes[l] >= 0 && c.nodes[m] >= 0 && hold_slot_.count(key(c.nodes[l], c.nodes[m])) == 0);
    if (missing)
    {
      if (pairs_.size() - base_pairs_ > kKeptHoldPairs * kFourNodePairs.size() * surface_holds_.size())
      {
        pairs_.resize(base_pairs_);
        hold_slot_.clear();
      }
      for (const SurfaceHold& c : surface_holds_)
        for (const auto& [l, m] : kFourNodePairs)
          if (c.nodes[l] >= 0 && c.nodes[m] >= 0 && hold_slot_.emplace(key(c.nodes[l], c.nodes[m]), pairs_.size()).second)
            pairs_.emplace_back(c.nodes[l], c.nodes[m]);
      factorable_ = solver_.analyze(model.nodeCount(), pairs_,
                                    linear_solve_ == LinearSolve::Direct ? kAnyWork : kMaxFactorWork);
    }
    hold_slots_.resize(kFourNodePairs.size() * surface_holds_.size());
    for (std::size_t k = 0; k < surface_holds_.size(); ++k)
      for (std::size_t p = 0; p < kFourNodePairs.size(); ++p)
      {
        const int a = surface_holds_[k].nodes[kFourNodePairs[p].first], b = surface_holds_[k].nodes[kFourNodePairs[p].second];
        hold_slots_[kFourNodePairs.size() * k + p] = a >= 0 && b >= 0 ? static_cast<int>(hold_slot_.at(key(a, b))) : -1;
      }
  }

  /// delta_v_ = A^-1 rhs_: directly, A written from the blocks of assemble into the analysed pattern (block
  /// tridiagonal where the free nodes form chains and no surface hold joins them to a solid in this step,
  /// else sparse), or by conjugate gradients where they cost
  /// less (see kDirectWorkPerRootCondition). A chain's factorisation costs about as much as one CG sweep, so
  /// a chain always takes the direct path.
  void solve(const Model& model)
  {
    if (!analyzed_)
      analyze(model);
    if (chains_ && surface_holds_.empty())
    {
      solveDirectly(model, chain_solver_);
      return;
    }
    if (!surface_holds_.empty() && linear_solve_ != LinearSolve::Iterative)
      placeHoldPairs(model);
    const bool cheaper_by_cg = linear_solve_ == LinearSolve::Cheaper &&
                               solver_.factorWork() / solver_.matrixEntries() >
                                   kDirectWorkPerRootCondition * std::sqrt(condition_);
    if (!factorable_ || cheaper_by_cg)
    {
      buildPreconditioner(model);
      solveIteratively(model);
      return;
    }
    solveDirectly(model, solver_);
  }

  /// Writes A into `solver` (BlockTridiagonalSolver or SparseBlockSolver, analysed with the slots of
  /// analyze, and placeHoldPairs for surface holds), factorises it and solves for delta_v_.
  template <class Solver>
  void solveDirectly(const Model& model, Solver& solver)
  {
    solver.start(diagonal_);
    for (std::size_t k = 0; k < springs_.size(); ++k)
    {
      const SpringBlock& block = springs_[k];
      if (spring_slot_[k] >= 0)
        solver.addOffDiagonal(static_cast<std::size_t>(spring_slot_[k]),
                              -(block.a * block.u * block.u.transpose() + block.b * Matrix3::Identity()));
    }
    for (std::size_t k = 0; k < cells_.size(); ++k)
    {
      const CellBlock& block = cells_[k];
      const PressureCell& cell = model.cells[k];
      for (int c = 0; c < 4; ++c)
        if (model.isFree(cell.nodes[c]))
          solver.addDiagonal(cell.nodes[c], block.scale * block.g[c] * block.g[c].transpose());
      for (std::size_t p = 0; p < kFourNodePairs.size(); ++p)
        if (cell_slot_[6 * k + p] >= 0)
          solver.addOffDiagonal(static_cast<std::size_t>(cell_slot_[6 * k + p]),
                                block.scale * block.g[kFourNodePairs[p].first] * block.g[kFourNodePairs[p].second].transpose());
    }
    for (std::size_t k = 0; k < rod_blocks_.size(); ++k)
    {
      const RodBlock& block = rod_blocks_[k];
      for (std::size_t p = 0; p < kRodPairs.size(); ++p)
        if (rod_slot_[3 * k + p] >= 0)
          solver.addOffDiagonal(static_cast<std::size_t>(rod_slot_[3 * k + p]),
                                block.scale * block.jacobian[kRodPairs[p].first].transpose() *
                                    block.jacobian[kRodPairs[p].second]);
    }
    for (std::size_t k = 0; k < tet_blocks_.size(); ++k)
      for (std::size_t p = 0; p < kTetPairs.size(); ++p)
        if (tet_slot_[6 * k + p] >= 0)
          solver.addOffDiagonal(static_cast<std::size_t>(tet_slot_[6 * k + p]), tet_blocks_[k].scaled.blocks[4 + p]);
    // A surface hold's blocks weights_l weights_m B (only ever in the sparse pattern: see analyze's chains_).
    for (std::size_t k = 0; k < surface_holds_.size(); ++k)
    {
      const SurfaceHold& c = surface_holds_[k];
      for (int l = 0; l < 4; ++l)
        if (c.nodes[l] >= 0)
          solver.addDiagonal(c.nodes[l], (c.weights[l] * c.weights[l]) * c.block);
      for (std::size_t p = 0; p < kFourNodePairs.size(); ++p)
        if (hold_slots_[kFourNodePairs.size() * k + p] >= 0)
          solver.addOffDiagonal(static_cast<std::size_t>(hold_slots_[kFourNodePairs.size() * k + p]),
                                (c.weights[kFourNodePairs[p].first] * c.weights[kFourNodePairs[p].second]) * c.block);
    }
    // A is symmetric positive definite by construction (the transverse stiffness of compressed springs
    // and the indefinite part of the gas's Hessian are dropped, see above), unless the state is not
    // finite: then the step is not finite either, and the divergence guard (guard.h) takes it.
    if (solver.factorize())
      solver.solve(rhs_, delta_v_);
    else
      delta_v_.setConstant(3, model.nodeCount(), std::numeric_limits<double>::quiet_NaN());
  }

  /// Which solve is cheaper. A conjugate-gradient sweep costs one multiply-add per entry of A, and CG's
  /// sweeps to a relative residual of 1e-12 grow like the square root of the preconditioned condition
  /// number (condition_); a factorisation costs its work per entry. So the direct path is taken while
  /// work per entry <= C sqrt(condition). The bound ln(2e12) / 2 = 14 sweeps per square root of the
  /// condition would give C = 14, but CG converges faster than its bound on these spectra and a sparse
  /// factorisation's multiply-add costs more than a sweep's: measured on the benchmark cloth at
  /// dt = 1/60 s (bench_step BM_ClothLinearSolveAt60Hz, condition ~840), direct is 1.4 times faster at
  /// 100 nodes (61 per entry, 2.1 sqrt(condition)) and CG 1.1 times faster at 324 (169 per entry,
  /// 5.8 sqrt(condition)), 1.8 times at 1,024: C = 4 switches between them. On a rope with bending
  /// springs the factor has no fill (2.9 per entry) and a stiff rope is badly conditioned (k = 1e6 N/m,
  /// 1 g nodes, dt = 1/60 s: ~1e6): always direct, and linear in the length. At small steps the mass
  /// dominates the matrix (condition ~1) and CG serves every cloth.
  static constexpr double kDirectWorkPerRootCondition = 4.0;
  /// No factorisation is even prepared beyond this work per entry (a 100,000-node cloth would need
  /// 0.75 GB for its factor).
  static constexpr double kMaxFactorWork = 2000.0;
  static constexpr double kAnyWork = std::numeric_limits<double>::infinity();

  /// How many times the present surface holds' node pairs the pattern keeps of earlier holds' (placeHoldPairs).
  static constexpr std::size_t kKeptHoldPairs = 4;

  /// The six pairs of four nodes: a cell's corners, a surface hold's node and triangle.
  static constexpr std::array<std::pair<int, int>, 6> kFourNodePairs{ { { 0, 1 }, { 0, 2 }, { 0, 3 }, { 1, 2 }, { 1, 3 }, { 2, 3 } } };

  /// The three node pairs of a rod vertex (before, at, after).
  static constexpr std::array<std::pair<int, int>, 3> kRodPairs{ { { 0, 1 }, { 0, 2 }, { 1, 2 } } };

  NodeArray start_x_, start_v_, linear_x_, offset_;
  NodeArray force_;  ///< the cells' pressure forces [N], then the rods' twisting forces and end moments
  NodeArray rhs_, delta_v_;
  NodeArray residual_, direction_, z_, product_;  ///< conjugate gradients' vectors
  std::vector<Matrix3> diagonal_;        ///< per node: mass and spring blocks of A
  std::vector<Matrix3> preconditioner_;  ///< per node: the inverse of A's full diagonal block (CG)
  std::vector<SpringBlock> springs_;
  std::vector<double> length_;          ///< per spring: its length [m]
  std::vector<double> inverse_length_;  ///< per spring: 1 / its length [1/m], 0 if its ends coincide
  std::vector<CellBlock> cells_;
  const LinearSolve linear_solve_;
  SparseBlockSolver solver_;
  BlockTridiagonalSolver chain_solver_;
  bool analyzed_ = false;          ///< the solvers hold the pattern of the current model
  bool chains_ = false;            ///< the free nodes form chains: chain_solver_ solves (steps without surface holds)
  bool factorable_ = true;         ///< the pattern is prepared for the direct solve (see kMaxFactorWork)
  double condition_ = 1.0;         ///< estimate of block-Jacobi preconditioned A's condition number
  std::vector<int> spring_slot_;   ///< per spring: its slot in solver_, or -1 (not coupled)
  std::vector<int> cell_slot_;     ///< per cell, six: each corner pair's slot, or -1
  std::vector<RodVertex> rod_vertices_;  ///< every rod's bending vertices (appendRodVertices)
  std::vector<int> rod_of_vertex_;       ///< per rod vertex: its rod's index in Model::rods
  std::vector<RodBlock> rod_blocks_;     ///< per rod vertex
  std::vector<int> rod_slot_;            ///< per rod vertex, three: each node pair's slot, or -1
  std::vector<TetBlock> tet_blocks_;     ///< per tetrahedron
  std::vector<int> tet_slot_;            ///< per tetrahedron, six: each node pair's slot, or -1
  std::vector<std::pair<int, int>> pairs_;  ///< solver_'s slots: the elements' (analyze), then the holds'
  std::size_t base_pairs_ = 0;              ///< how many of pairs_ are the elements'
  std::unordered_map<std::uint64_t, std::size_t> hold_slot_;  ///< a surface hold's node pair -> its slot
  std::vector<int> hold_slots_;             ///< per surface hold, six: each node pair's slot, or -1
  std::vector<char> solid_node_;         ///< per node: a node of a tetrahedron
  /// per node: [N] the force its hold took in the last step (> 0 pushing, < 0 pulling: let go for a step),
  /// 0 without a hold
  std::vector<double> hold_force_;
  std::vector<SolidContact> solid_contacts_;  ///< the solids' holds of the last Newton iteration
  const ContactQuery* contacts_ = nullptr;  ///< the colliders during a step with contacts on solids
  std::optional<SurfaceContacts> surface_contacts_;  ///< the solids' surfaces, made in analyze if it can find anything
  std::vector<SurfaceTouch> touches_;                  ///< what it found at a step's first iteration
  std::vector<SurfaceHold> surface_holds_;             ///< the holds of the last Newton iteration
  /// per node: [N] the force its surface hold took in the last step (as hold_force_)
  std::vector<double> surface_hold_force_;
  NodeArray predicted_;  ///< x + h v where surface holds are found [m]
};
}  // namespace

std::unique_ptr<Integrator> makeImplicitEuler() { return makeImplicitEuler(LinearSolve::Cheaper); }

std::unique_ptr<Integrator> makeImplicitEuler(LinearSolve solve) { return std::make_unique<ImplicitEuler>(solve); }

}  // namespace soft_body_sim
