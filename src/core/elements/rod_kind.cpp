#include "core/elements/rod_kind.h"

namespace soft_body_sim
{
void RodKind::ImplicitBlocks::analyze(const Model& model, BlockSystem& system)
{
  vertices_.clear();
  rod_of_vertex_.clear();
  for (std::size_t r = 0; r < model.rods.size(); ++r)
  {
    appendRodVertices(model.rods[r], vertices_);
    rod_of_vertex_.resize(vertices_.size(), static_cast<int>(r));
  }
  slot_.assign(3 * vertices_.size(), -1);
  for (std::size_t k = 0; k < vertices_.size(); ++k)
  {
    const RodVertex& vertex = vertices_[k];
    const int nodes[3] = { vertex.before, vertex.at, vertex.after };
    for (std::size_t p = 0; p < kPairs.size(); ++p)
    {
      const int a = nodes[kPairs[p].first], b = nodes[kPairs[p].second];
      if (a >= 0 && b >= 0 && model.isFree(a) && model.isFree(b))
        slot_[3 * k + p] = system.addPair(a, b);
    }
  }
}

/// The bending blocks (on the diagonal here; off it in multiply and write) and the bending, damping and
/// twist forces in rhs: per vertex, with q = sum_l J_l offset_l and r = sum_l J_l v_l,
/// rhs_k -= 2 w h J_k^T (kb + q + beta r); per interval between two stations,
/// rhs_i -= h (G J twist / L) d(twist)/dx_i; and h times the rods' end moments.
void RodKind::ImplicitBlocks::assemble(const NewtonPoint& point, BlockSystem& system)
{
  const Model& model = point.model;
  if (model.rods.empty())
    return;
  const double h = point.h;
  const NodeArray& x = point.x;
  NodeArray& rhs = system.rhs();
  blocks_.resize(vertices_.size());
  for (std::size_t k = 0; k < vertices_.size(); ++k)
  {
    const RodVertex& vertex = vertices_[k];
    const Rod& rod = model.rods[static_cast<std::size_t>(rod_of_vertex_[k])];
    Vec3 e0, e1;
    vertexEdges(rod, vertex, x, e0, e1);
    const CurvatureBinormal bend = curvatureBinormal(e0, e1, rod.segment_length * rod.segment_length);
    Block& block = blocks_[k];
    // x_before enters e0 negatively, x_at e0 positively and e1 negatively, x_after e1 positively.
    block.nodes[0] = vertex.before;
    block.nodes[1] = vertex.at;
    block.nodes[2] = vertex.after;
    block.jacobian[0] = -bend.d_e0;
    block.jacobian[1] = (vertex.before < 0 ? Eigen::Matrix3d::Zero() : bend.d_e0) -
                        (vertex.after < 0 ? Eigen::Matrix3d::Zero() : bend.d_e1);
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
      q += block.jacobian[c] * point.offset.col(block.nodes[c]);
      r += block.jacobian[c] * point.v.col(block.nodes[c]);
    }
    const Vec3 pull = 2.0 * vertex.weight * h * (bend.kb + q + rod.damping * r);
    for (int c = 0; c < 3; ++c)
    {
      const int node = block.nodes[c];
      if (node < 0)
        continue;
      rhs.col(node) -= block.jacobian[c].transpose() * pull;
      system.diagonal(node) += block.scale * block.jacobian[c].transpose() * block.jacobian[c];
    }
  }
  force_.setZero(3, model.nodeCount());
  for (const Rod& rod : model.rods)
  {
    accumulateTwistForces(rod, x, point.twist, force_);
    accumulateRodEndMoment(rod, x, force_);
  }
  for (int i = 0; i < model.nodeCount(); ++i)
    if (model.isFree(i))
      rhs.col(i) += h * force_.col(i);
}

void RodKind::ImplicitBlocks::multiply(const Model&, const NodeArray& p, NodeArray& out) const
{
  for (const Block& block : blocks_)
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
}

}  // namespace soft_body_sim
