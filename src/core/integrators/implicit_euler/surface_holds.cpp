#include "core/integrators/implicit_euler/surface_holds.h"

#include <algorithm>
#include <cmath>

#include "core/contact/face_contacts.h"
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
  // A solid's surface samples, a triangle's in a run: the runs, and a hold for each sample at most.
  const std::vector<SurfaceSample>& samples = model.surface_samples;
  sample_force_.assign(samples.size(), 0.0);
  triangle_first_.clear();
  for (std::size_t s = 0; s < samples.size(); ++s)
    if (s == 0 || samples[s].triangle != samples[s - 1].triangle)
      triangle_first_.push_back(s);
  triangle_first_.push_back(samples.size());
  holds_.reserve(holds_.capacity() + samples.size());
  faces_ = !model.contact_triangles.empty();
  face_force_.clear();
}

void SurfaceHolds::findSamples(const NewtonPoint& point, const ContactQuery& colliders)
{
  const Model& model = point.model;
  const double h = point.h;
  const double margin = model.gravity.norm() * h * h;
  NodeContact contact;
  for (std::size_t t = 0; t + 1 < triangle_first_.size(); ++t)
  {
    // Where the triangle starts the sub-step (x) and where its velocities take it (x + h v).
    const std::array<int, 3>& triangle = model.surface_samples[triangle_first_[t]].triangle;
    std::array<Vec3, 3> start, end;
    double moved = 0.0;
    for (std::size_t k = 0; k < 3; ++k)
    {
      start[k] = point.x.col(triangle[k]);
      end[k] = start[k] + point.offset.col(triangle[k]);
      moved = std::max(moved, (end[k] - start[k]).norm());
    }
    const Vec3 centre = (start[0] + start[1] + start[2]) / 3.0;
    const double reach = std::sqrt(std::max(
        { (start[0] - centre).squaredNorm(), (start[1] - centre).squaredNorm(), (start[2] - centre).squaredNorm() }));
    if (!colliders.touching(model, triangle[0], centre, margin + moved + reach, contact))
      continue;
    // How far the shape moves in the sub-step (at the centre's velocity): a point that far outside at the
    // start can be in at its end.
    const double swept = h * contact.velocity.norm();
    // A point near a corner whose node is on the shape is left to that node's own hold (collider_holds.h):
    // both would push the same part of the surface.
    std::array<bool, 3> corner_held;
    for (std::size_t k = 0; k < 3; ++k)
    {
      NodeContact at_corner;
      corner_held[k] = colliders.touching(model, triangle[k], end[k], margin, at_corner);
    }
    // Where the shape is flat under the whole triangle (a plane, a box's face: every corner nearest to the
    // same shape along the same normal), a flat triangle's depth is greatest at a corner: its nodes meet it.
    NodeContact flat;
    bool flat_under = true;
    for (std::size_t k = 0; k < 3 && flat_under; ++k)
    {
      NodeContact at_corner;
      flat_under = colliders.touching(model, triangle[k], start[k], margin + moved + 2.0 * reach, at_corner) &&
                   (k == 0 || (at_corner.collider == flat.collider && at_corner.normal.dot(flat.normal) > kSameNormal));
      if (k == 0)
        flat = at_corner;
    }
    for (std::size_t s = triangle_first_[t]; s < triangle_first_[t + 1]; ++s)
    {
      const Vec3& weight = model.surface_samples[s].weight;
      if ((corner_held[0] && weight[0] >= kNearCorner) || (corner_held[1] && weight[1] >= kNearCorner) ||
          (corner_held[2] && weight[2] >= kNearCorner))
        continue;
      // The shape's nearest point and normal from where the point starts the sub-step, so that the side it
      // is pushed to is the side it came from (from x + h v, a point moving faster than the shape's radius
      // per sub-step would be pushed out through the far side); the depth at x + h v along that normal,
      // the shape moved on by its velocity there.
      const Vec3 q = weight[0] * start[0] + weight[1] * start[1] + weight[2] * start[2];
      const Vec3 predicted = weight[0] * end[0] + weight[1] * end[1] + weight[2] * end[2];
      if (!colliders.touching(model, triangle[0], q, margin + swept + (predicted - q).norm(), contact) ||
          (flat_under && contact.collider == flat.collider && contact.normal.dot(flat.normal) > kSameNormal))
        continue;
      const double depth = contact.depth + (h * contact.velocity - (predicted - q)).dot(contact.normal);
      // Held while it is in at x + h v, or, if it pushed in the last step, within |g| h^2 of that (a hold
      // that comes and goes every other sub-step sets a surface chattering). Not with a node's margin
      // (ColliderHolds) for every sample: the points of a flat face beside a round rod's line of contact
      // would be pulled onto the rod.
      if (!(depth > 0.0) && !(sample_force_[s] > 0.0 && depth > -margin))
        continue;
      // The collider takes the place of the surface hold's node p (weight 0, no node): the gap is -q.
      Hold c;
      c.touch = SurfaceTouch{ { triangle[0], triangle[0], triangle[1], triangle[2] },
                              { 0.0, -weight[0], -weight[1], -weight[2] },
                              -contact.normal,
                              -predicted,
                              depth,
                              contact.friction };
      c.nodes[0] = -1;
      for (std::size_t l = 1; l < 4; ++l)
        c.nodes[l] = model.isFree(c.touch.nodes[l]) ? c.touch.nodes[l] : -1;
      c.depth = c.scaled = 0.0;
      c.block.setZero();
      c.sample = static_cast<int>(s);
      c.contact = contact;
      holds_.push_back(c);
    }
  }
}

void SurfaceHolds::findFaces(const NewtonPoint& point, const ContactQuery& colliders)
{
  const Model& model = point.model;
  const double margin = model.gravity.norm() * point.h * point.h;
  colliders.touchingFaces(model, point.x, predicted_, point.h, margin, faces_found_);
  for (std::size_t k = 0; k < faces_found_.size(); ++k)
  {
    const FaceContact& face = faces_found_[k];
    // Held while it is in at x + h v, or, if it pushed in the last step, within |g| h^2 of that.
    if (face.contact.depth > 0.0 || (lastForce(face) > 0.0 && face.contact.depth > -margin))
      holdFace(model, k);
  }
}

bool SurfaceHolds::findMissedFaces(const Model& model, const NodeArray& x, const NodeArray& v, double h,
                                   const ContactQuery& colliders)
{
  if (!faces_)
    return false;
  held_faces_.clear();
  for (const Hold& c : holds_)
    if (c.face >= 0)
    {
      const FaceContact& face = faces_found_[static_cast<std::size_t>(c.face)];
      held_faces_.emplace_back(face.triangle, face.contact.collider, face.feature);
    }
  std::sort(held_faces_.begin(), held_faces_.end());
  // Where the next Newton iteration linearises: x + h v, the pinned nodes where they are.
  predicted_ = x;
  for (int i = 0; i < model.nodeCount(); ++i)
    if (model.isFree(i))
      predicted_.col(i) += h * v.col(i);
  colliders.touchingFaces(model, x, predicted_, h, 0.0, faces_more_);
  bool found = false;
  for (const FaceContact& face : faces_more_)
  {
    // Missed: in by more than its thickness, so into the shape itself (a face keeps kFaceSag of it from the
    // shape); one that only came into its thickness is the contact stage's, as before the solve knew it.
    if (!(face.contact.depth > triangleThickness(model, model.contact_triangles[face.triangle])) ||
        std::binary_search(held_faces_.begin(), held_faces_.end(),
                           FaceKey{ face.triangle, face.contact.collider, face.feature }))
      continue;
    faces_found_.push_back(face);
    holdFace(model, faces_found_.size() - 1);
    found = true;
  }
  return found;
}

void SurfaceHolds::holdFace(const Model& model, std::size_t k)
{
  const FaceContact& face = faces_found_[k];
  const std::array<int, 3>& triangle = model.contact_triangles[face.triangle];
  const Vec3 predicted = face.weight[0] * predicted_.col(triangle[0]) + face.weight[1] * predicted_.col(triangle[1]) +
                         face.weight[2] * predicted_.col(triangle[2]);
  // As a sample's hold: the collider in p's place.
  Hold c;
  c.touch = SurfaceTouch{ { triangle[0], triangle[0], triangle[1], triangle[2] },
                          { 0.0, -face.weight[0], -face.weight[1], -face.weight[2] },
                          -face.contact.normal,
                          -predicted,
                          face.contact.depth,
                          face.contact.friction };
  c.nodes[0] = -1;
  for (std::size_t l = 1; l < 4; ++l)
    c.nodes[l] = face.weight[l - 1] != 0.0 && model.isFree(c.touch.nodes[l]) ? c.touch.nodes[l] : -1;
  c.depth = c.scaled = 0.0;
  c.block.setZero();
  c.face = static_cast<int>(k);
  c.contact = face.contact;
  holds_.push_back(c);
}

void SurfaceHolds::assemble(const NewtonPoint& point, bool first_iteration, BlockSystem& system,
                            const ContactQuery* colliders)
{
  if (!present())
    return;
  if (first_iteration)
    find(point, colliders);
  const double h = point.h;
  const NodeArray& x = point.x;
  for (Hold& c : holds_)
  {
    const Vec3& n = c.touch.normal;
    Vec3 gap = Vec3::Zero(), relative = Vec3::Zero();
    double inverse_block = 0.0;
    for (std::size_t l = 0; l < 4; ++l)
    {
      const int node = c.touch.nodes[l];
      const double weight = c.touch.weights[l];
      gap += weight * (x.col(node) + point.offset.col(node));
      relative += weight * point.v.col(node);
      if (c.nodes[l] >= 0)
        inverse_block += weight * weight /
                         (c.onCollider() ? point.model.mass[c.nodes[l]] : system.diagonal(c.nodes[l]).trace() / 3.0);
    }
    c.depth = c.touch.depth - n.dot(gap - c.touch.gap);
    c.scaled = 0.0;
    c.block.setZero();
    if (!(inverse_block > 0.0))
      continue;  // all four pinned
    const double block = 1.0 / inverse_block;  // b [kg]
    // A triangle's point on a collider: no stiffer than at sub-steps of kStiffestSampleStep.
    const double shorter = h < kStiffestSampleStep ? (h * h) / (kStiffestSampleStep * kStiffestSampleStep) : 1.0;
    c.scaled = (c.onCollider() ? kContactStiffness * shorter : kContactStiffness) * block;
    Vec3 push = (c.scaled / h * c.depth) * n;
    c.block = c.scaled * (n * n.transpose());
    if (c.onCollider())
      relative += c.contact.velocity;
    const double known = c.sample >= 0  ? sample_force_[static_cast<std::size_t>(c.sample)]
                         : c.face >= 0 ? lastForce(faces_found_[static_cast<std::size_t>(c.face)])
                                       : lastForce(c.touch);
    const double normal_force = std::max(block * c.depth / (h * h), known);
    Vec3 tangential;
    const double damping = frictionDamping(c.touch.friction, normal_force, relative, n, tangential);
    c.damping = damping;
    c.slip = tangential;
    if (damping > 0.0)
    {
      push -= h * damping * tangential;
      c.block += h * damping * (Eigen::Matrix3d::Identity() - n * n.transpose());
    }
    for (int l = 0; l < 4; ++l)
      if (c.nodes[l] >= 0)
        system.rhs().col(c.nodes[l]) += c.touch.weights[l] * push;
  }
}

void SurfaceHolds::find(const NewtonPoint& point, const ContactQuery* colliders)
{
  const Model& model = point.model;
  const double margin = model.gravity.norm() * point.h * point.h;
  holds_.clear();
  predicted_ = point.x + point.offset;
  if (colliders != nullptr && !sample_force_.empty())
    findSamples(point, *colliders);
  if (colliders != nullptr && faces_)
    findFaces(point, *colliders);
  if (!contacts_.has_value())
    return;
  contacts_->find(model, point.x, predicted_, std::max(margin, 0.5 * contacts_->widestRadius()), touches_);
  for (const SurfaceTouch& touch : touches_)
  {
    // A hold that pushed in the last step is kept while the node stays within half its radius (or |g| h^2)
    // of the surface: released as soon as the push has set it moving off, it would fall back in the next
    // step and be pushed out again, a bounce every other step (seen at 1/240 s on a rope over an edge).
    const double keep = std::max(margin, 0.5 * model.contact_radius[touch.nodes[0]]);
    if (touch.depth <= (lastForce(touch) > 0.0 ? -keep : 0.0))
      continue;
    Hold c;
    c.touch = touch;
    c.depth = c.scaled = 0.0;  // assemble sets them, and the block, each iteration
    c.block.setZero();
    // A node of weight 0 (a segment's point fills the triangle's third place with it) takes no part.
    for (std::size_t l = 0; l < 4; ++l)
      c.nodes[l] = touch.weights[l] != 0.0 && model.isFree(touch.nodes[l]) ? touch.nodes[l] : -1;
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
        gap += c.touch.weights[l] * p.col(c.nodes[l]);
    const Vec3 pushed = c.block * gap;
    for (int l = 0; l < 4; ++l)
      if (c.nodes[l] >= 0)
        out.col(c.nodes[l]) += c.touch.weights[l] * pushed;
  }
}

void SurfaceHolds::addToPreconditioner(const Model&, std::vector<Eigen::Matrix3d>& diagonal) const
{
  for (const Hold& c : holds_)
    for (int l = 0; l < 4; ++l)
      if (c.nodes[l] >= 0)
        diagonal[static_cast<std::size_t>(c.nodes[l])] += (c.touch.weights[l] * c.touch.weights[l]) * c.block;
}

double SurfaceHolds::lastForce(const SurfaceTouch& touch) const
{
  if (touch.edges < 0)
    return hold_force_[static_cast<std::size_t>(touch.nodes[0])];
  const auto found = std::lower_bound(edge_force_.begin(), edge_force_.end(), touch.edges,
                                      [](const auto& known, std::int64_t edges) { return known.first < edges; });
  return found != edge_force_.end() && found->first == touch.edges ? found->second : 0.0;
}

double SurfaceHolds::lastForce(const FaceContact& face) const
{
  const FaceKey key{ face.triangle, face.contact.collider, face.feature };
  const auto found = std::lower_bound(face_force_.begin(), face_force_.end(), key,
                                      [](const auto& known, const FaceKey& wanted) { return known.first < wanted; });
  return found != face_force_.end() && found->first == key ? found->second : 0.0;
}

double SurfaceHolds::force(const Hold& hold, double h, const NodeArray& dv)
{
  Vec3 moved = Vec3::Zero();
  for (int l = 0; l < 4; ++l)
    if (hold.nodes[l] >= 0)
      moved += hold.touch.weights[l] * dv.col(hold.nodes[l]);
  return hold.scaled / (h * h) * (hold.depth - h * hold.touch.normal.dot(moved));
}

void SurfaceHolds::letGoPulling(double h, const NodeArray& dv)
{
  if (!present())
    return;
  holds_.erase(std::remove_if(holds_.begin(), holds_.end(), [&](const Hold& c) { return force(c, h, dv) < 0.0; }),
               holds_.end());
}

void SurfaceHolds::noteForces(double h, const NodeArray& dv, ContactQuery* colliders)
{
  if (!present())
    return;
  std::fill(hold_force_.begin(), hold_force_.end(), 0.0);
  std::fill(sample_force_.begin(), sample_force_.end(), 0.0);
  edge_force_.clear();
  face_force_.clear();
  for (const Hold& c : holds_)
  {
    const double normal_force = force(c, h, dv);
    if (!c.onCollider())
    {
      if (c.touch.edges >= 0)
        edge_force_.emplace_back(c.touch.edges, normal_force);
      else
        hold_force_[static_cast<std::size_t>(c.touch.nodes[0])] = normal_force;
      continue;
    }
    if (c.sample >= 0)
      sample_force_[static_cast<std::size_t>(c.sample)] = normal_force;
    else
    {
      const FaceContact& face = faces_found_[static_cast<std::size_t>(c.face)];
      face_force_.emplace_back(FaceKey{ face.triangle, face.contact.collider, face.feature }, normal_force);
    }
    if (colliders == nullptr)
      continue;
    // On the triangle's point: the push along the collider's normal and friction's pull towards its velocity.
    Vec3 moved = Vec3::Zero();
    for (int l = 1; l < 4; ++l)
      if (c.nodes[l] >= 0)
        moved += c.touch.weights[l] * dv.col(c.nodes[l]);
    const Vec3 n = c.touch.normal;
    const Vec3 on_point = normal_force * c.contact.normal + c.damping * (c.slip + moved - n.dot(moved) * n);
    colliders->receive(c.contact, -c.touch.gap - c.touch.depth * c.contact.normal, -h * on_point);
  }
  std::sort(edge_force_.begin(), edge_force_.end());
  std::sort(face_force_.begin(), face_force_.end());
}

}  // namespace soft_body_sim
