#include "core/elements/spring_kind.h"

#include <algorithm>

namespace soft_body_sim
{
void SpringKind::ImplicitBlocks::analyze(const Model& model, BlockSystem& system)
{
  slot_.assign(model.springs.size(), -1);
  system.reservePairs(model.springs.size());
  for (std::size_t k = 0; k < model.springs.size(); ++k)
  {
    const Spring& s = model.springs[k];
    if (model.isFree(s.a) && model.isFree(s.b) && s.a != s.b)
      slot_[k] = system.addPair(s.a, s.b);
  }
}

void SpringKind::ImplicitBlocks::assemble(const NewtonPoint& point, BlockSystem& system)
{
  const Model& model = point.model;
  const double h = point.h;
  NodeArray& rhs = system.rhs();
  blocks_.resize(model.springs.size());
  // Each spring's axis as springAxis gives it, but with one division where it takes four (u = d / l,
  // then L / l below), in a loop of its own: short, so that the processor overlaps the square roots and
  // divisions of many springs (on a rope, they were most of the assembly's time). Until the next loop
  // makes the block's a and b, they hold the length and its reciprocal (0 if the ends coincide): no
  // arrays of their own (16 bytes a spring).
  for (std::size_t k = 0; k < model.springs.size(); ++k)
  {
    const Spring& s = model.springs[k];
    Block& block = blocks_[k];
    const Vec3 axis = point.x.col(s.a) - point.x.col(s.b);
    block.a = axis.norm();
    block.b = block.a < kMinSpringLength ? 0.0 : 1.0 / block.a;
    block.u = axis * block.b;
  }
  for (std::size_t k = 0; k < model.springs.size(); ++k)
  {
    const Spring& s = model.springs[k];
    Block& block = blocks_[k];
    const double length = block.a;
    const double inverse_length = block.b;
    if (inverse_length == 0.0)
    {
      block = Block{ Vec3::Zero(), 0.0, 0.0 };  // coincident ends: no force, no block
      continue;
    }
    const double transverse = std::max(0.0, 1.0 - s.rest_length * inverse_length);
    block.a = h * h * s.stiffness * (1.0 - transverse) + h * s.damping;
    block.b = h * h * s.stiffness * transverse;
    Eigen::Matrix3d diagonal = block.a * (block.u * block.u.transpose());
    diagonal.diagonal().array() += block.b;
    const Vec3 d = point.offset.col(s.a) - point.offset.col(s.b);
    const Vec3 k_offset = -s.stiffness * ((1.0 - transverse) * block.u.dot(d) * block.u + transverse * d);
    // h (f_a + K offset) on end a, its negative on end b (f_a as in accumulateSpringForces).
    const Vec3 impulse = h * (k_offset - springTension(s, block.u, length, point.v) * block.u);
    // The preconditioned A's largest eigenvalue over its smallest is about 1 + 4 (h^2 k + h c) / m
    // for the stiffest spring on its lightest free end (a chain's: (m + 4 h^2 k) / m).
    const double lightest = std::max(model.inverse_mass[s.a], model.inverse_mass[s.b]);
    system.noteCondition(1.0 + 4.0 * (h * h * s.stiffness + h * s.damping) * lightest, s.a, s.b);
    if (model.isFree(s.a))
    {
      rhs.col(s.a) += impulse;
      system.diagonal(s.a) += diagonal;
    }
    if (model.isFree(s.b))
    {
      rhs.col(s.b) -= impulse;
      system.diagonal(s.b) += diagonal;
    }
  }
}

void SpringKind::ImplicitBlocks::multiply(const Model& model, const NodeArray& p, NodeArray& out) const
{
  for (std::size_t k = 0; k < blocks_.size(); ++k)
  {
    const Block& block = blocks_[k];
    if (slot_[k] < 0)
      continue;  // an end pinned: no off-diagonal block
    const Spring& s = model.springs[k];
    const Vec3 p_a = p.col(s.a);
    const Vec3 p_b = p.col(s.b);
    out.col(s.a) -= block.a * block.u.dot(p_b) * block.u + block.b * p_b;
    out.col(s.b) -= block.a * block.u.dot(p_a) * block.u + block.b * p_a;
  }
}

}  // namespace soft_body_sim
