// Springs (Model::springs): Hooke's law with a dashpot along the spring (model.h's Spring, forces.h's kernels).
#pragma once

#include <vector>

#include "core/integrators/implicit_euler/newton_system.h"
#include "soft_body_sim/core/elements/forces.h"
#include "soft_body_sim/core/integrators/integrator.h"
#include "soft_body_sim/core/material_scaling.h"

namespace soft_body_sim
{
struct SpringKind
{
  using Element = Spring;
  static constexpr const char* kName = "springs";
  static std::vector<Spring>& of(Model& model) { return model.springs; }
  static const std::vector<Spring>& of(const Model& model) { return model.springs; }
  static int bodyNode(const Spring& s) { return s.a; }
  template <class Mine>
  static bool touches(const Spring& s, Mine mine)
  {
    return mine(s.a) || mine(s.b);
  }
  static bool runsUnder(IntegratorType) { return true; }
  static constexpr bool kChangesAsHeld = false;
  /// k (|d| - L)^2 / 2.
  static double energy(const Spring& s, const State& state)
  {
    const double stretch = (state.position.col(s.a) - state.position.col(s.b)).norm() - s.rest_length;
    return 0.5 * s.stiffness * stretch * stretch;
  }
  static void scale(Spring& s, const Spring& built, const BodyScaling& scaling)
  {
    s.stiffness = built.stiffness * scaling.stiffness;
    s.damping = built.damping * scaling.damping;
  }
  /// Each spring's tension from the integrator (InternalForces::tension's first springs.size() entries).
  static void addPulls(const Model& model, const State& state, const InternalForces& forces, NodeArray& pull)
  {
    for (std::size_t k = 0; k < model.springs.size(); ++k)
      pullAlong(state.position, model.springs[k].a, model.springs[k].b, forces.tension[static_cast<Eigen::Index>(k)], pull);
  }

  /// A link of tension t [N] pulls its end a toward b and b toward a (nothing if they coincide).
  static void pullAlong(const NodeArray& x, int a, int b, double t, NodeArray& pull)
  {
    Vec3 u;
    double length;
    if (!springAxis(x, a, b, u, length))
      return;
    pull.col(a) -= t * u;
    pull.col(b) += t * u;
  }

  /// A spring's share of implicit Euler's Newton system (newton_system.h). -df_a/dx_a of the spring is
  /// k ((1 - t) u u^T + t I) with t = (1 - L/l)^+ (its transverse term k (1 - L/l)(I - u u^T) dropped when
  /// compressed, Choi & Ko 2002, so that A stays positive definite), and -df_a/dv_a of its dashpot c u u^T:
  /// its block h^2 k ((1 - t) u u^T + t I) + h c u u^T = a u u^T + b I sits on the diagonal at both ends
  /// and, negated, off it.
  class ImplicitBlocks
  {
  public:
    void analyze(const Model& model, BlockSystem& system);
    void assemble(const NewtonPoint& point, BlockSystem& system);
    void multiply(const Model& model, const NodeArray& p, NodeArray& out) const;
    void addToPreconditioner(const Model&, std::vector<Eigen::Matrix3d>&) const {}
    template <class Solver>
    void write(const Model&, Solver& solver) const
    {
      for (std::size_t k = 0; k < blocks_.size(); ++k)
      {
        const Block& block = blocks_[k];
        if (slot_[k] >= 0)
          solver.addOffDiagonal(static_cast<std::size_t>(slot_[k]),
                                -(block.a * block.u * block.u.transpose() + block.b * Eigen::Matrix3d::Identity()));
      }
    }

  private:
    struct Block
    {
      Vec3 u;
      double a;
      double b;
    };
    std::vector<Block> blocks_;  ///< per spring
    std::vector<int> slot_;      ///< per spring: its slot in the pattern, or -1 (an end pinned)
  };
};

}  // namespace soft_body_sim
