#include "core/elements/tetrahedron_kind.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace soft_body_sim
{
void TetrahedronKind::ImplicitBlocks::analyze(const Model& model, BlockSystem& system)
{
  std::vector<std::size_t> per_body(model.bodies.size(), 0);
  for (const Tetrahedron& tet : model.tetrahedra)
    ++per_body[model.bodyOf(tet.nodes[0])];
  const std::size_t largest = per_body.empty() ? 0 : *std::max_element(per_body.begin(), per_body.end());
  solid_sweeps_ = kSweepsPerCubeRoot * std::cbrt(static_cast<double>(largest));
  slot_.assign(6 * model.tetrahedra.size(), -1);
  system.reservePairs(6 * model.tetrahedra.size());
  for (std::size_t k = 0; k < model.tetrahedra.size(); ++k)
    for (std::size_t p = 0; p < kFourNodePairs.size(); ++p)
    {
      const int a = model.tetrahedra[k].nodes[kFourNodePairs[p].first], b = model.tetrahedra[k].nodes[kFourNodePairs[p].second];
      if (model.isFree(a) && model.isFree(b))
        slot_[6 * k + p] = system.addPair(a, b);
    }
}

/// The blocks (the diagonal ones into the system's diagonal) and h (f + K offset) in rhs (K = -df/dx), and
/// the estimate of CG's sweeps on the largest solid (kSweepsPerCubeRoot).
void TetrahedronKind::ImplicitBlocks::assemble(const NewtonPoint& point, BlockSystem& system)
{
  const Model& model = point.model;
  if (model.tetrahedra.empty())
    return;
  const double h = point.h;
  const NodeArray& offset = point.offset;
  NodeArray& rhs = system.rhs();
  blocks_.resize(model.tetrahedra.size());
  Eigen::Matrix<double, 3, 4> force;
  for (std::size_t k = 0; k < model.tetrahedra.size(); ++k)
  {
    const Tetrahedron& tet = model.tetrahedra[k];
    Block& block = blocks_[k];
    tetForcesAndStiffness(tet, point.x, true, force, block.scaled);
    for (int a = 0; a < 4; ++a)
      block.nodes[a] = model.isFree(tet.nodes[a]) ? tet.nodes[a] : -1;
    // rhs_a += h f_a - h sum_b K_ab offset_b, over the free b (a pinned node's offset is 0).
    for (int a = 0; a < 4; ++a)
      if (block.nodes[a] >= 0)
        rhs.col(block.nodes[a]) += h * (force.col(a) - block.scaled.blocks[a] * offset.col(block.nodes[a]));
    for (std::size_t p = 0; p < kFourNodePairs.size(); ++p)
    {
      const int a = kFourNodePairs[p].first, b = kFourNodePairs[p].second;
      const Eigen::Matrix3d& k_ab = block.scaled.blocks[4 + p];
      if (block.nodes[a] >= 0)
        rhs.col(block.nodes[a]) -= h * (k_ab * offset.col(tet.nodes[b]));
      if (block.nodes[b] >= 0)
        rhs.col(block.nodes[b]) -= h * (k_ab.transpose() * offset.col(tet.nodes[a]));
    }
    for (Eigen::Matrix3d& k_ab : block.scaled.blocks)
      k_ab *= h * h;
    for (int a = 0; a < 4; ++a)
      if (block.nodes[a] >= 0)
        system.diagonal(block.nodes[a]) += block.scaled.blocks[a];
  }
  system.noteSolidSweeps(solid_sweeps_);
}

void TetrahedronKind::ImplicitBlocks::multiply(const Model&, const NodeArray& p, NodeArray& out) const
{
  for (const Block& block : blocks_)
    for (std::size_t pair = 0; pair < kFourNodePairs.size(); ++pair)
    {
      const int a = block.nodes[kFourNodePairs[pair].first], b = block.nodes[kFourNodePairs[pair].second];
      if (a < 0 || b < 0)
        continue;
      const Eigen::Matrix3d& k_ab = block.scaled.blocks[4 + pair];
      out.col(a) += k_ab * p.col(b);
      out.col(b) += k_ab.transpose() * p.col(a);
    }
}

}  // namespace soft_body_sim
