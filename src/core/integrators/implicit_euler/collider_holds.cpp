#include "core/integrators/implicit_euler/collider_holds.h"

#include <algorithm>

#include "core/integrators/implicit_euler/hold_friction.h"

namespace soft_body_sim
{
void ColliderHolds::analyze(const Model& model)
{
  held_node_.assign(static_cast<std::size_t>(model.nodeCount()), 0);
  hold_force_.assign(static_cast<std::size_t>(model.nodeCount()), 0.0);
  for (const Tetrahedron& tet : model.tetrahedra)
    for (const int node : tet.nodes)
      held_node_[static_cast<std::size_t>(node)] = 1;
  for (const std::array<int, 3>& triangle : model.contact_triangles)
    for (const int node : triangle)
      held_node_[static_cast<std::size_t>(node)] = 1;
  // Room for a hold on every node that can be held (no allocation in a step), not on every node: a cloth
  // without face contacts has none (a hold is 160 bytes).
  holds_.clear();
  holds_.shrink_to_fit();
  holds_.reserve(static_cast<std::size_t>(std::count(held_node_.begin(), held_node_.end(), 1)));
}

void ColliderHolds::assemble(const NewtonPoint& point, const ContactQuery& contacts, bool first_iteration,
                             BlockSystem& system)
{
  if (first_iteration)
    find(point, contacts);
  const double h = point.h;
  NodeArray& rhs = system.rhs();
  for (Hold& c : holds_)
  {
    const int i = c.node;
    const Vec3 n = c.contact.normal;
    // The same surface, planar about where it was found, at this iteration's predicted position.
    c.depth = c.found_depth - n.dot(point.x.col(i) + point.offset.col(i) - c.found_at);
    Eigen::Matrix3d& d = system.diagonal(i);
    const double block = d.trace() / 3.0;  // b [kg]
    c.scaled = kContactStiffness * block;  // h^2 k
    rhs.col(i) += (c.scaled / h * c.depth) * n;
    d += c.scaled * (n * n.transpose());
    // A hold that pulled in the last step (< 0) adds nothing: only the approach's force presses then.
    const double normal_force = std::max(block * c.depth / (h * h), hold_force_[static_cast<std::size_t>(i)]);
    c.damping = frictionDamping(c.contact.friction, normal_force, point.v.col(i) - c.contact.velocity, n, c.slip);
    if (!(c.damping > 0.0))
      continue;
    rhs.col(i) -= h * c.damping * c.slip;
    d += h * c.damping * (Eigen::Matrix3d::Identity() - n * n.transpose());
  }
}

void ColliderHolds::find(const NewtonPoint& point, const ContactQuery& contacts)
{
  const Model& model = point.model;
  NodeContact contact;
  holds_.clear();
  const double margin = model.gravity.norm() * point.h * point.h;
  for (int i = 0; i < model.nodeCount(); ++i)
  {
    if (!held_node_[static_cast<std::size_t>(i)] || !model.isFree(i))
      continue;
    const Vec3 start = point.x.col(i), predicted = start + point.offset.col(i);
    if (!contacts.touching(model, i, predicted, margin, contact))
      continue;
    // The normal from where the node starts the step, if the same collider is nearest there: the side it is
    // pushed to is the side it came from (from x + h v, a node carried past a thin rail's axis within the
    // step would be pushed out through its far side); the depth at x + h v along it, planar about the start.
    const Vec3 moved = predicted - start;
    NodeContact from_start;
    if (contacts.touching(model, i, start, margin + moved.norm() + point.h * contact.velocity.norm(), from_start) &&
        from_start.collider == contact.collider)
    {
      from_start.depth -= from_start.normal.dot(moved);
      contact = from_start;
    }
    const double depth = contact.depth + point.h * contact.velocity.dot(contact.normal);
    if (depth > (hold_force_[static_cast<std::size_t>(i)] < 0.0 ? 0.0 : -margin))
      holds_.push_back({ i, contact, predicted, depth, depth, 0.0, 0.0, Vec3::Zero() });
  }
}

double ColliderHolds::force(const Hold& hold, double h, const NodeArray& dv)
{
  return hold.scaled / (h * h) * (hold.depth - h * hold.contact.normal.dot(dv.col(hold.node)));
}

void ColliderHolds::letGoPulling(double h, const NodeArray& dv)
{
  holds_.erase(std::remove_if(holds_.begin(), holds_.end(), [&](const Hold& c) { return force(c, h, dv) < 0.0; }),
               holds_.end());
}

void ColliderHolds::noteForces(const Model& model, double h, const NodeArray& dv, ContactQuery& contacts)
{
  std::fill(hold_force_.begin(), hold_force_.end(), 0.0);
  for (const Hold& c : holds_)
  {
    const double normal_force = force(c, h, dv);
    hold_force_[static_cast<std::size_t>(c.node)] = normal_force;
    // The force the solve's rows applied (assemble): k (d - h n . dv) along n, and the friction damping's
    // -c (v_t + (I - n n^T) dv) across it; the collider takes the opposite impulse over h, at the surface
    // point under the node.
    const Vec3 n = c.contact.normal;
    const Vec3 across = dv.col(c.node) - n.dot(dv.col(c.node)) * n;
    const Vec3 on_node = normal_force * n - c.damping * (c.slip + across);
    const Vec3 point = c.found_at - (model.contact_radius[c.node] - c.found_depth) * n;
    contacts.receive(c.contact, point, -h * on_node);
  }
}

}  // namespace soft_body_sim
