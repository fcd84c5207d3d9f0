// Rods' bending and twisting (Model::rods, a `type: rod` body's; rods.h). Their stretching is springs.
#pragma once

#include <array>
#include <utility>
#include <vector>

#include "core/integrators/implicit_euler/newton_system.h"
#include "soft_body_sim/core/elements/rods.h"
#include "soft_body_sim/core/material_scaling.h"

namespace soft_body_sim
{
struct RodKind
{
  using Element = Rod;
  static constexpr const char* kName = "rods (type: rod)";
  static std::vector<Rod>& of(Model& model) { return model.rods; }
  static const std::vector<Rod>& of(const Model& model) { return model.rods; }
  static int bodyNode(const Rod& rod) { return rod.first; }
  /// A rod lies within one body, whose nodes are all in one integrator group: its first node tells.
  template <class Mine>
  static bool touches(const Rod& rod, Mine mine)
  {
    return mine(rod.first);
  }
  static bool runsUnder(IntegratorType integrator) { return integrator == IntegratorType::ImplicitEuler; }
  /// Its stations (clamps, holds) come and go as it is held: what it was built with is kept from the start.
  static constexpr bool kChangesAsHeld = true;
  static double energy(const Rod& rod, const State& state) { return rodEnergy(rod, state.position, state.twist); }
  /// E I and G J scale with the stretching's E (and G), beta with the dashpots.
  static void scale(Rod& rod, const Rod& built, const BodyScaling& scaling)
  {
    rod.bending_stiffness = built.bending_stiffness * scaling.stiffness;
    rod.twisting_stiffness = built.twisting_stiffness * scaling.stiffness;
    rod.damping = built.damping * scaling.damping;
  }
  /// Bending and twisting forces at the state (the integrator keeps no multipliers for them).
  static void addPulls(const Model& model, const State& state, const InternalForces&, NodeArray& pull)
  {
    for (const Rod& rod : model.rods)
      accumulateRodForces(rod, state.position, state.twist, pull);
  }

  /// A rod's share of implicit Euler's Newton system (newton_system.h). Its bending force -2 w J_k^T kb at
  /// each vertex (J_k = dkb/dx_k of its three nodes, w its weight) enters f, and K its Gauss-Newton part
  /// -2 w J_k^T J_l, dropping 2 w kb . d^2kb, which vanishes straight and keeps K symmetric negative
  /// semi-definite; the damping -beta K v (Rod::damping) enters D: a vertex's blocks are
  /// (h^2 + h beta) 2 w J_k^T J_l. Its twist's force -(G J twist / L) d(twist)/dx enters f only, explicitly:
  /// its stiffness is rank one and couples every node of the rod (a dense block), and against the bending's
  /// it is of order M_t l / (E I) for a twisting moment M_t, l / L near the critical twist of a long rod.
  /// Its end moment (a couple on its last segment) enters f only, explicitly too: its stiffness M / l^2 is
  /// 2 pi l / L of the bending's E I / l^3 even at a full circle's moment 2 pi E I / L.
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
        for (std::size_t p = 0; p < kPairs.size(); ++p)
          if (slot_[3 * k + p] >= 0)
            solver.addOffDiagonal(static_cast<std::size_t>(slot_[3 * k + p]),
                                  block.scale * block.jacobian[kPairs[p].first].transpose() * block.jacobian[kPairs[p].second]);
      }
    }

  private:
    /// A vertex's three nodes (before, at, after; -1 where the edge is a held end's ghost or the node is
    /// pinned) and their Jacobians J_k = dkb/dx_k.
    struct Block
    {
      int nodes[3];
      Eigen::Matrix3d jacobian[3];
      double scale;  ///< (h^2 + h beta) 2 w [N m^3 s^2]
    };
    /// The three node pairs of a vertex (before, at, after).
    static constexpr std::array<std::pair<int, int>, 3> kPairs{ { { 0, 1 }, { 0, 2 }, { 1, 2 } } };
    std::vector<RodVertex> vertices_;  ///< every rod's bending vertices (appendRodVertices)
    std::vector<int> rod_of_vertex_;   ///< per vertex: its rod's index in Model::rods
    std::vector<Block> blocks_;        ///< per vertex
    std::vector<int> slot_;            ///< per vertex, three: each node pair's slot, or -1
    NodeArray force_;                  ///< the rods' twisting forces and end moments [N]
  };
};

}  // namespace soft_body_sim
