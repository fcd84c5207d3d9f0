#include "core/elements/gas_cell_kind.h"

namespace soft_body_sim
{
void GasCellKind::ImplicitBlocks::analyze(const Model& model, BlockSystem& system)
{
  slot_.assign(6 * model.cells.size(), -1);
  for (std::size_t k = 0; k < model.cells.size(); ++k)
    for (std::size_t p = 0; p < kFourNodePairs.size(); ++p)
    {
      const int a = model.cells[k].nodes[kFourNodePairs[p].first], b = model.cells[k].nodes[kFourNodePairs[p].second];
      if (model.isFree(a) && model.isFree(b) && a != b)
        slot_[6 * k + p] = system.addPair(a, b);
    }
}

void GasCellKind::ImplicitBlocks::assemble(const NewtonPoint& point, BlockSystem& system)
{
  const Model& model = point.model;
  const double h = point.h;
  NodeArray& rhs = system.rhs();
  if (!model.cells.empty())
  {
    force_.setZero(3, model.nodeCount());
    accumulatePressureForces(model, point.x, force_);
    for (int i = 0; i < model.nodeCount(); ++i)
      if (model.isFree(i))
        rhs.col(i) += h * force_.col(i);
  }
  blocks_.resize(model.cells.size());
  // Each cell's share of h K offset, (K offset)_k = -S g_k sum_l g_l . offset_l, on its free corners.
  for (std::size_t k = 0; k < model.cells.size(); ++k)
  {
    const PressureCell& cell = model.cells[k];
    Block& block = blocks_[k];
    const double stiffness = cellGas(cell, cellArea(cell, point.x, block.g)).stiffness;
    double g_dot_offset = 0.0;
    for (int c = 0; c < 4; ++c)
      g_dot_offset += block.g[c].dot(point.offset.col(cell.nodes[c]));
    block.scale = h * h * stiffness;
    for (int c = 0; c < 4; ++c)
    {
      const int row = cell.nodes[c];
      if (!model.isFree(row))
      {
        block.g[c].setZero();
        continue;
      }
      rhs.col(row) -= (h * stiffness * g_dot_offset) * block.g[c];
    }
  }
}

void GasCellKind::ImplicitBlocks::multiply(const Model& model, const NodeArray& p, NodeArray& out) const
{
  for (std::size_t k = 0; k < blocks_.size(); ++k)
  {
    const Block& block = blocks_[k];
    const PressureCell& cell = model.cells[k];
    double g_dot_p = 0.0;
    for (int l = 0; l < 4; ++l)
      g_dot_p += block.g[l].dot(p.col(cell.nodes[l]));
    for (int l = 0; l < 4; ++l)
      out.col(cell.nodes[l]) += (block.scale * g_dot_p) * block.g[l];
  }
}

void GasCellKind::ImplicitBlocks::addToPreconditioner(const Model& model, std::vector<Eigen::Matrix3d>& diagonal) const
{
  for (std::size_t k = 0; k < blocks_.size(); ++k)
    for (int c = 0; c < 4; ++c)
      diagonal[static_cast<std::size_t>(model.cells[k].nodes[c])] += blocks_[k].scale * blocks_[k].g[c] * blocks_[k].g[c].transpose();
}

}  // namespace soft_body_sim
