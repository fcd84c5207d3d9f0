// Tetrahedra of soft solids (Model::tetrahedra, a `type: volume` body's): stable neo-Hookean with an optional
// gas (tetrahedra.h).
#pragma once

#include <algorithm>
#include <iterator>
#include <vector>

#include "core/integrators/implicit_euler/newton_system.h"
#include "soft_body_sim/core/elements/tetrahedra.h"
#include "soft_body_sim/core/material_scaling.h"

namespace soft_body_sim
{
struct TetrahedronKind
{
  using Element = Tetrahedron;
  static constexpr const char* kName = "soft solids (type: volume)";
  static std::vector<Tetrahedron>& of(Model& model) { return model.tetrahedra; }
  static const std::vector<Tetrahedron>& of(const Model& model) { return model.tetrahedra; }
  static int bodyNode(const Tetrahedron& tet) { return tet.nodes[0]; }
  template <class Mine>
  static bool touches(const Tetrahedron& tet, Mine mine)
  {
    return std::any_of(std::begin(tet.nodes), std::end(tet.nodes), mine);
  }
  static bool runsUnder(IntegratorType integrator) { return integrator == IntegratorType::ImplicitEuler; }
  static constexpr bool kChangesAsHeld = false;
  static double energy(const Tetrahedron& tet, const State& state) { return tetEnergy(tet, state.position); }
  /// mu and lambda scale with E (Poisson's ratio kept), the gas's p0 as a jelly cell's.
  static void scale(Tetrahedron& tet, const Tetrahedron& built, const BodyScaling& scaling)
  {
    tet.mu = built.mu * scaling.stiffness;
    tet.lambda = built.lambda * scaling.stiffness;
    tet.pressure = built.pressure * scaling.pressure;
  }
  /// Elastic (and gas) forces at the state.
  static void addPulls(const Model& model, const State& state, const InternalForces&, NodeArray& pull)
  {
    accumulateTetForces(model, state.position, pull);
  }

  /// A tetrahedron's share of implicit Euler's Newton system (newton_system.h): its elastic forces, and its
  /// stiffness projected onto the positive semi-definite matrices per tetrahedron (tetForcesAndStiffness),
  /// so that A stays symmetric positive definite through any strain and inversion: blocks h^2 K_ab.
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
        for (std::size_t p = 0; p < kFourNodePairs.size(); ++p)
          if (slot_[6 * k + p] >= 0)
            solver.addOffDiagonal(static_cast<std::size_t>(slot_[6 * k + p]), blocks_[k].scaled.blocks[4 + p]);
    }

  private:
    /// Its blocks h^2 K_ab (TetStiffness's order) and its nodes (-1 where pinned).
    struct Block
    {
      int nodes[4];
      TetStiffness scaled;
    };
    /// Conjugate gradients' sweeps on a solid grow with the tetrahedra across it, the cube root of its
    /// count, hardly with the step (bench_step BM_SoftBox/iterative on the box of 1,243 to 12,362
    /// tetrahedra at 1/60 and 4 ms: 13.6 to 16 times that root).
    static constexpr double kSweepsPerCubeRoot = 15.0;

    std::vector<Block> blocks_;    ///< per tetrahedron
    std::vector<int> slot_;        ///< per tetrahedron, six: each node pair's slot, or -1
    double solid_sweeps_ = 0.0;    ///< CG's sweeps on the body with the most tetrahedra (kSweepsPerCubeRoot)
  };
};

}  // namespace soft_body_sim
