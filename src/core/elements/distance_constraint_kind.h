// Distance constraints (Model::constraints): C = |x_a - x_b| - L, projected by XPBD (distance_constraints.h)
// in every integrator's constraint pass; compliance alpha makes one a spring of stiffness 1 / alpha.
#pragma once

#include <vector>

#include "core/elements/spring_kind.h"

namespace soft_body_sim
{
struct DistanceConstraintKind
{
  using Element = DistanceConstraint;
  /// Projected after implicit Euler's solve (the constraint pass), not in its system.
  using ImplicitBlocks = NoImplicitBlocks;
  static constexpr const char* kName = "distance constraints";
  static std::vector<DistanceConstraint>& of(Model& model) { return model.constraints; }
  static const std::vector<DistanceConstraint>& of(const Model& model) { return model.constraints; }
  static int bodyNode(const DistanceConstraint& c) { return c.a; }
  template <class Mine>
  static bool touches(const DistanceConstraint& c, Mine mine)
  {
    return mine(c.a) || mine(c.b);
  }
  static bool runsUnder(IntegratorType) { return true; }
  static constexpr bool kChangesAsHeld = false;
  /// C^2 / (2 alpha) (Macklin et al. 2016: the compliant constraint's potential); an inextensible one
  /// (alpha = 0) holds C = 0 and stores nothing.
  static double energy(const DistanceConstraint& c, const State& state)
  {
    if (!(c.compliance > 0.0))
      return 0.0;
    const double violation = (state.position.col(c.a) - state.position.col(c.b)).norm() - c.rest_length;
    return violation * violation / (2.0 * c.compliance);
  }
  /// Stiffness 1 / alpha scales as a spring's.
  static void scale(DistanceConstraint& c, const DistanceConstraint& built, const BodyScaling& scaling)
  {
    c.compliance = built.compliance / scaling.stiffness;
  }
  /// Each constraint's tension from the integrator (InternalForces::tension after the springs').
  static void addPulls(const Model& model, const State& state, const InternalForces& forces, NodeArray& pull)
  {
    const auto springs = static_cast<Eigen::Index>(model.springs.size());
    for (std::size_t k = 0; k < model.constraints.size(); ++k)
      SpringKind::pullAlong(state.position, model.constraints[k].a, model.constraints[k].b,
                            forces.tension[springs + static_cast<Eigen::Index>(k)], pull);
  }
};

}  // namespace soft_body_sim
