// Pieces shared by the integrator implementations (private to the core library).
#pragma once

#include <memory>

#include "core/elements/distance_constraints.h"
#include "soft_body_sim/core/elements/forces.h"
#include "soft_body_sim/core/integrators/integrator.h"

namespace soft_body_sim
{
/// A ConstraintRow with what does not depend on the positions worked out: the reciprocal of its
/// denominator (1 + gamma)(w_a + w_b) + alpha~ (0 when the row cannot move: both ends pinned).
struct SweepRow
{
  int a;
  int b;
  double rest_length;
  double alpha_tilde;
  double gamma;
  double inverse_denominator;

  void carry(StateArchive& archive) { archive(a, b, rest_length, alpha_tilde, gamma, inverse_denominator); }
};

inline SweepRow sweepRow(const ConstraintRow& row, const Eigen::VectorXd& inverse_mass)
{
  const double w = inverse_mass[row.a] + inverse_mass[row.b];
  const double denominator = (1.0 + row.gamma) * w + row.alpha_tilde;
  const double inverse = w == 0.0 || denominator < 1e-300 ? 0.0 : 1.0 / denominator;
  return SweepRow{ row.a, row.b, row.rest_length, row.alpha_tilde, row.gamma, inverse };
}

/// The XPBD update of one ConstraintRow (distance_constraints.h), inline for the integrators' sweeps. Its cost is bounded
/// by the divider, so it takes one square root and one division per update: u = d (1 / |d|) rather
/// than three divisions, and the denominator's reciprocal from the row.
[[gnu::always_inline]] inline void projectDistance(const SweepRow& row, const Eigen::VectorXd& inverse_mass,
                                                   const NodeArray& x_prev, NodeArray& x, double& lambda)
{
  if (row.inverse_denominator == 0.0)
    return;
  const Vec3 d = x.col(row.a) - x.col(row.b);
  const double length = d.norm();
  if (length < kMinSpringLength)
    return;  // coincident nodes: the direction is undefined
  const Vec3 u = d * (1.0 / length);
  const double c = length - row.rest_length;
  // gradC . (x - x_prev): the constraint's rate over this (sub)step times h, for the damping term.
  const double c_rate_h =
      row.gamma == 0.0 ? 0.0 : u.dot((x.col(row.a) - x_prev.col(row.a)) - (x.col(row.b) - x_prev.col(row.b)));
  const double delta_lambda = (-c - row.alpha_tilde * lambda - row.gamma * c_rate_h) * row.inverse_denominator;
  lambda += delta_lambda;
  x.col(row.a) += (inverse_mass[row.a] * delta_lambda) * u;
  x.col(row.b) -= (inverse_mass[row.b] * delta_lambda) * u;
}

/// The distance-constraint pass of the force-based schemes: after the force step, project the
/// constraints and add the projection's displacement / h to the velocities, so that the constraint
/// impulse is kept in the motion (position-based post-stabilisation). Costs nothing without constraints.
class ConstraintPass
{
public:
  void apply(const Model& model, State& state, double h, int iterations)
  {
    if (model.constraints.empty())
      return;
    unprojected_ = state.position;
    project(model, h, iterations, unprojected_, state.position);
    for (int i = 0; i < model.nodeCount(); ++i)
      if (model.isFree(i))
        state.velocity.col(i) += (state.position.col(i) - unprojected_.col(i)) / h;
  }

  /// Projects the constraints of `x` (x_prev: the positions at the sub-step's start, for damping) and
  /// keeps the multipliers for tensions().
  void project(const Model& model, double h, int iterations, const NodeArray& x_prev, NodeArray& x)
  {
    if (model.constraints.empty())
      return;
    projectConstraints(model, h, iterations, x_prev, x, lambda_);
    h_ = h;
  }

  /// The constraints' tensions [N] in the last projection, -lambda / h^2 (a projection by w lambda u
  /// is the displacement h^2 w F of a force F = lambda u / h^2), into `tension`, one per constraint.
  void tensions(const Model& model, Eigen::Ref<Eigen::VectorXd> tension) const
  {
    if (lambda_.size() != static_cast<Eigen::Index>(model.constraints.size()) || h_ == 0.0)
      tension.setZero();
    else
      tension = -lambda_ / (h_ * h_);
  }

  void carry(StateArchive& archive) { archive(lambda_, h_); }

private:
  NodeArray unprojected_;
  Eigen::VectorXd lambda_;
  double h_ = 0.0;  ///< [s] of the last projection; 0 = none yet
};

/// The springs' tensions by the spring law and the cells' pressures by the gas law at `state`, and 0 for
/// each constraint (see Integrator::internalForces).
void stateInternalForces(const Model& model, const State& state, InternalForces& forces);

/// Integrator::assign for an integrator of type T: `self` becomes a copy of `other` if it is a T too.
template <typename T>
bool assignIfSame(T& self, const Integrator& other)
{
  const auto* same = dynamic_cast<const T*>(&other);
  if (same == nullptr)
    return false;
  self = *same;
  return true;
}

/// A force-based scheme: springs and dashpots as forces, constraints by its ConstraintPass.
class ForceBasedIntegrator : public Integrator
{
public:
  void internalForces(const Model& model, const State& state, InternalForces& forces) const override
  {
    stateInternalForces(model, state, forces);
    constraints_.tensions(model, forces.tension.tail(static_cast<Eigen::Index>(model.constraints.size())));
  }
  /// The springs' arrays are not carried: read into a world whose model had other springs (another
  /// material scaling), they are made again from the model read.
  void carry(StateArchive& archive, const Model& /*model*/) override
  {
    archive(constraints_);
    if (archive.reading())
      springs_ = SpringArrays{};
  }
  /// The springs' arrays are made again for the changed model (their parameters, their ends).
  void modelChanged() override
  {
    springs_ = SpringArrays{};
    invalidate();
  }

protected:
  /// computeAccelerations with the springs' arrays (springArrays), made at the first call and again after
  /// the model changed. Not carried: a restored world makes the same arrays from its model.
  void accelerations(const Model& model, const NodeArray& x, const NodeArray& v, NodeArray& force,
                     NodeArray& acceleration)
  {
    if (springs_.size() != model.springs.size())
      springs_ = springArrays(model);
    computeAccelerations(model, springs_, x, v, force, acceleration);
  }

  ConstraintPass constraints_;

private:
  SpringArrays springs_;
};

std::unique_ptr<Integrator> makeExplicitEuler();
std::unique_ptr<Integrator> makeSemiImplicitEuler();
std::unique_ptr<Integrator> makeVerlet();
std::unique_ptr<Integrator> makeVelocityVerlet();
std::unique_ptr<Integrator> makeRk4();
std::unique_ptr<Integrator> makeImplicitEuler();
/// How implicit_euler solves its linear systems: the cheaper path (its default), or one path always
/// (Direct: block tridiagonal on chains, else sparse LDL^T at any cost; Iterative: conjugate gradients
/// preconditioned by block Jacobi; Multigrid: conjugate gradients preconditioned by a multigrid cycle), for
/// tests and benchmarks that compare them.
enum class LinearSolve
{
  Cheaper,
  Direct,
  Iterative,
  Multigrid,
};
std::unique_ptr<Integrator> makeImplicitEuler(LinearSolve solve);
/// When implicit_euler's Newton iterations stop in a scene with soft solids (implicit_euler.cpp): after at
/// least StepSettings::iterations of them, once the step's equations hold to kTolerance, or after
/// kMostIterations (or `iterations`, if more); without solids, or where other bodies can meet a solid's
/// surface, after `iterations`. The test is on the residual r = h f(x_n + h v, v) - M (v - v_n) of the
/// iterate v: the Newton system's matrix A is at least M (each kind keeps its blocks positive
/// semi-definite), so v's error v - v* = A^-1 r has |v - v*|_M <= |r|_M^-1, and the step stops once that
/// bound, as a mass-weighted RMS speed sqrt(sum |r_i|^2 / m_i / sum m_i), is at most allowedResidualSpeed.
struct NewtonRule
{
  /// The velocity error a step keeps, relative to its speed scale |g| h + max |v_i - v_n,i| (what gravity
  /// adds in a step, plus the most any node's velocity changed in it): 1e-3, so that in a falling or resting
  /// scene the error in a node's travel over the step, h |v - v*|, is a thousandth of the |g| h^2 within
  /// which a node counts as resting on a collider (collider_holds.h).
  static constexpr double kTolerance = 1e-3;
  /// Round-off's share: the residual of an exact step is not 0 but the round-off of positions and forces,
  /// measured ~1e-12 of the speed of a cube falling at 10 m/s 5 m from the origin; 1e-9 of the fastest node's
  /// speed, and 1e-12 m/s, stay above it where the scale above vanishes (no gravity, nothing accelerating).
  static constexpr double kRoundOff = 1e-9;
  static constexpr double kRoundOffSpeed = 1e-12;  ///< [m/s]
  /// The most Newton iterations a step takes (unless StepSettings::iterations asks for more).
  static constexpr int kMostIterations = 10;

  /// [m/s] the residual speed a converged step may keep: gravity_speed = |g| h, largest_change =
  /// max |v_i - v_n,i|, fastest = max |v_i| [m/s].
  static double allowedResidualSpeed(double gravity_speed, double largest_change, double fastest)
  {
    return kTolerance * (gravity_speed + largest_change) + kRoundOff * fastest + kRoundOffSpeed;
  }
};
std::unique_ptr<Integrator> makeXpbd();

}  // namespace soft_body_sim
