// Gas cells (Model::cells, a jelly's): Boyle's law on a quadrilateral's signed area (forces.h's cellGas).
#pragma once

#include <algorithm>
#include <iterator>
#include <vector>

#include "core/integrators/implicit_euler/newton_system.h"
#include "soft_body_sim/core/elements/forces.h"
#include "soft_body_sim/core/elements/tetrahedra.h"
#include "soft_body_sim/core/integrators/integrator.h"
#include "soft_body_sim/core/material_scaling.h"

namespace soft_body_sim
{
struct GasCellKind
{
  using Element = PressureCell;
  static constexpr const char* kName = "gas cells";
  static std::vector<PressureCell>& of(Model& model) { return model.cells; }
  static const std::vector<PressureCell>& of(const Model& model) { return model.cells; }
  static int bodyNode(const PressureCell& cell) { return cell.nodes[0]; }
  template <class Mine>
  static bool touches(const PressureCell& cell, Mine mine)
  {
    return std::any_of(std::begin(cell.nodes), std::end(cell.nodes), mine);
  }
  static bool runsUnder(IntegratorType) { return true; }
  static constexpr bool kChangesAsHeld = false;
  static double energy(const PressureCell& cell, const State& state)
  {
    return cellGas(cell, cellArea(cell, state.position)).energy;
  }
  static void scale(PressureCell& cell, const PressureCell& built, const BodyScaling& scaling)
  {
    cell.pressure = built.pressure * scaling.pressure;
  }
  /// Each cell's pressure from the integrator (InternalForces::pressure) on its corners: p dA/dx_k.
  static void addPulls(const Model& model, const State& state, const InternalForces& forces, NodeArray& pull)
  {
    Vec3 gradient[4];
    for (std::size_t k = 0; k < model.cells.size(); ++k)
    {
      cellArea(model.cells[k], state.position, gradient);
      for (int corner = 0; corner < 4; ++corner)
        pull.col(model.cells[k].nodes[corner]) += forces.pressure[static_cast<Eigen::Index>(k)] * gradient[corner];
    }
  }

  /// A cell's share of implicit Euler's Newton system (newton_system.h): its force F_k = p dA/dx_k, and
  /// its blocks h^2 S g_k g_l^T, g_k = dA/dx_k, S = d^2E/dA^2: the Gauss-Newton part of K,
  ///   K_kl = -S dA/dx_k dA/dx_l^T,
  /// dropping p d^2A/dx_k dx_l, which is indefinite (A is bilinear in the positions) and vanishes at rest;
  /// the kept part is the one that stiffens without bound as the cell is squeezed. Its blocks, diagonal
  /// ones too, stay here (rank one per cell), apart from the system's diagonal.
  class ImplicitBlocks
  {
  public:
    void analyze(const Model& model, BlockSystem& system);
    void assemble(const NewtonPoint& point, BlockSystem& system);
    void multiply(const Model& model, const NodeArray& p, NodeArray& out) const;
    void addToPreconditioner(const Model& model, std::vector<Eigen::Matrix3d>& diagonal) const;
    template <class Solver>
    void write(const Model& model, Solver& solver) const
    {
      for (std::size_t k = 0; k < blocks_.size(); ++k)
      {
        const Block& block = blocks_[k];
        const PressureCell& cell = model.cells[k];
        for (int c = 0; c < 4; ++c)
          if (model.isFree(cell.nodes[c]))
            solver.addDiagonal(cell.nodes[c], block.scale * block.g[c] * block.g[c].transpose());
        for (std::size_t p = 0; p < kFourNodePairs.size(); ++p)
          if (slot_[6 * k + p] >= 0)
            solver.addOffDiagonal(static_cast<std::size_t>(slot_[6 * k + p]),
                                  block.scale * block.g[kFourNodePairs[p].first] * block.g[kFourNodePairs[p].second].transpose());
      }
    }

  private:
    /// g_k = dA/dx_k of its free corners, zero for pinned ones.
    struct Block
    {
      Vec3 g[4];
      double scale;  ///< h^2 S [N/m^3 s^2]
    };
    std::vector<Block> blocks_;  ///< per cell
    std::vector<int> slot_;      ///< per cell, six: each corner pair's slot, or -1
    NodeArray force_;            ///< the cells' pressure forces [N]
  };
};

}  // namespace soft_body_sim
