#include "core/integrators/implicit_euler/surface_holds.h"

#include <algorithm>

#include "core/integrators/implicit_euler/hold_friction.h"

namespace soft_body_sim
{
void SurfaceHolds::analyze(const Model& model, const BlockSystem& system)
{
  contacts_.emplace(model);
  if (model.tetrahedra.empty() || contacts_->empty())
    contacts_.reset();
  hold_force_.assign(static_cast<std::size_t>(model.nodeCount()), 0.0);
  holds_.clear();
  if (contacts_.has_value())
  {
    // A node touches at most one triangle of each solid.
    const std::size_t most = static_cast<std::size_t>(model.nodeCount()) * model.bodies.size();
    holds_.reserve(most);
    touches_.reserve(most);
  }
  element_pairs_ = system.pairCount();
  slot_of_pair_.clear();
}

void SurfaceHolds::assemble(const NewtonPoint& point, bool first_iteration, BlockSystem& system)
{
  if (!contacts_.has_value())
    return;
  if (first_iteration)
    find(point);
  const double h = point.h;
  const NodeArray& x = point.x;
  for (Hold& c : holds_)
  {
    const Vec3& n = c.touch.normal;
    Vec3 gap = Vec3::Zero(), relative = Vec3::Zero();
    double inverse_block = 0.0;
    const int all[4] = { c.touch.node, c.touch.triangle[0], c.touch.triangle[1], c.touch.triangle[2] };
    for (int l = 0; l < 4; ++l)
    {
      gap += c.weights[l] * (x.col(all[l]) + point.offset.col(all[l]));
      relative += c.weights[l] * point.v.col(all[l]);
      if (c.nodes[l] >= 0)
        inverse_block += c.weights[l] * c.weights[l] / (system.diagonal(c.nodes[l]).trace() / 3.0);
    }
    c.depth = c.touch.depth - n.dot(gap - c.touch.gap);
    c.scaled = 0.0;
    c.block.setZero();
    if (!(inverse_block > 0.0))
      continue;  // all four pinned
    const double block = 1.0 / inverse_block;  // b [kg]
    c.scaled = kContactStiffness * block;
    Vec3 push = (c.scaled / h * c.depth) * n;
    c.block = c.scaled * (n * n.transpose());
    const double normal_force = std::max(block * c.depth / (h * h), hold_force_[static_cast<std::size_t>(c.touch.node)]);
    Vec3 tangential;
    const double damping = frictionDamping(c.touch.friction, normal_force, relative, n, tangential);
    if (damping > 0.0)
    {
      push -= h * damping * tangential;
      c.block += h * damping * (Eigen::Matrix3d::Identity() - n * n.transpose());
    }
    for (int l = 0; l < 4; ++l)
      if (c.nodes[l] >= 0)
        system.rhs().col(c.nodes[l]) += c.weights[l] * push;
  }
}

void SurfaceHolds::find(const NewtonPoint& point)
{
  const Model& model = point.model;
  const double margin = model.gravity.norm() * point.h * point.h;
  predicted_ = point.x + point.offset;
  contacts_->find(model, point.x, predicted_, std::max(margin, 0.5 * contacts_->widestRadius()), touches_);
  holds_.clear();
  for (const SurfaceTouch& touch : touches_)
  {
    // A hold that pushed in the last step is kept while the node stays within half its radius (or |g| h^2)
    // of the surface: released as soon as the push has set it moving off, it would fall back in the next
    // step and be pushed out again, a bounce every other step (seen at 1/240 s on a rope over an edge).
    const double keep = std::max(margin, 0.5 * model.contact_radius[touch.node]);
    if (touch.depth <= (hold_force_[static_cast<std::size_t>(touch.node)] > 0.0 ? -keep : 0.0))
      continue;
    Hold c;
    c.touch = touch;
    c.depth = c.scaled = 0.0;  // assemble sets them, and the block, each iteration
    c.block.setZero();
    const int all[4] = { touch.node, touch.triangle[0], touch.triangle[1], touch.triangle[2] };
    for (int l = 0; l < 4; ++l)
    {
      c.weights[l] = l == 0 ? 1.0 : -touch.weight[l - 1];
      c.nodes[l] = model.isFree(all[l]) ? all[l] : -1;
    }
    holds_.push_back(c);
  }
}

void SurfaceHolds::placePairs(BlockSystem& system)
{
  const auto key = [](int a, int b) {
    return (static_cast<std::uint64_t>(std::min(a, b)) << 32) | static_cast<std::uint64_t>(std::max(a, b));
  };
  bool missing = false;
  for (const Hold& c : holds_)
    for (const auto& [l, m] : kFourNodePairs)
      missing = missing || (c.nodes[l] >= 0 && c.nodes[m] >= 0 && slot_of_pair_.count(key(c.nodes[l], c.nodes[m])) == 0);
  if (missing)
  {
    if (system.pairCount() - element_pairs_ > kKeptPairs * kFourNodePairs.size() * holds_.size())
    {
      system.truncatePairs(element_pairs_);
      slot_of_pair_.clear();
    }
    for (const Hold& c : holds_)
      for (const auto& [l, m] : kFourNodePairs)
        if (c.nodes[l] >= 0 && c.nodes[m] >= 0 && slot_of_pair_.emplace(key(c.nodes[l], c.nodes[m]), system.pairCount()).second)
          system.addPair(c.nodes[l], c.nodes[m]);
    system.analyzeSparse();
  }
  slots_.resize(kFourNodePairs.size() * holds_.size());
  for (std::size_t k = 0; k < holds_.size(); ++k)
    for (std::size_t p = 0; p < kFourNodePairs.size(); ++p)
    {
      const int a = holds_[k].nodes[kFourNodePairs[p].first], b = holds_[k].nodes[kFourNodePairs[p].second];
      slots_[kFourNodePairs.size() * k + p] = a >= 0 && b >= 0 ? static_cast<int>(slot_of_pair_.at(key(a, b))) : -1;
    }
}

void SurfaceHolds::multiply(const Model&, const NodeArray& p, NodeArray& out) const
{
  // The blocks in full, the diagonal ones too (they are not in the system's diagonal).
  for (const Hold& c : holds_)
  {
    Vec3 gap = Vec3::Zero();
    for (int l = 0; l < 4; ++l)
      if (c.nodes[l] >= 0)
        gap += c.weights[l] * p.col(c.nodes[l]);
    const Vec3 pushed = c.block * gap;
    for (int l = 0; l < 4; ++l)
      if (c.nodes[l] >= 0)
        out.col(c.nodes[l]) += c.weights[l] * pushed;
  }
}

void SurfaceHolds::addToPreconditioner(const Model&, std::vector<Eigen::Matrix3d>& diagonal) const
{
  for (const Hold& c : holds_)
    for (int l = 0; l < 4; ++l)
      if (c.nodes[l] >= 0)
        diagonal[static_cast<std::size_t>(c.nodes[l])] += (c.weights[l] * c.weights[l]) * c.block;
}

double SurfaceHolds::force(const Hold& hold, double h, const NodeArray& dv)
{
  Vec3 moved = Vec3::Zero();
  for (int l = 0; l < 4; ++l)
    if (hold.nodes[l] >= 0)
      moved += hold.weights[l] * dv.col(hold.nodes[l]);
  return hold.scaled / (h * h) * (hold.depth - h * hold.touch.normal.dot(moved));
}

void SurfaceHolds::letGoPulling(double h, const NodeArray& dv)
{
  if (!contacts_.has_value())
    return;
  holds_.erase(std::remove_if(holds_.begin(), holds_.end(), [&](const Hold& c) { return force(c, h, dv) < 0.0; }),
               holds_.end());
}

void SurfaceHolds::noteForces(double h, const NodeArray& dv)
{
  if (!contacts_.has_value())
    return;
  std::fill(hold_force_.begin(), hold_force_.end(), 0.0);
  for (const Hold& c : holds_)
    hold_force_[static_cast<std::size_t>(c.touch.node)] = force(c, h, dv);
}

}  // namespace soft_body_sim
