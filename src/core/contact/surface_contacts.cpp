#include "core/contact/surface_contacts.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>
#include <utility>

#include "core/contact/closest_points.h"
#include "core/contact/face_contacts.h"

namespace soft_body_sim
{
namespace
{
/// Whether `at` lies in the box [low, high].
bool inBox(const Vec3& at, const Vec3& low, const Vec3& high)
{
  return (at.array() >= low.array()).all() && (at.array() <= high.array()).all();
}

/// The box (least, most) around an edge of nodes a and b, now (x) and predicted.
std::pair<Vec3, Vec3> sweptBox(int a, int b, const NodeArray& x, const NodeArray& predicted)
{
  return { x.col(a).cwiseMin(x.col(b)).cwiseMin(predicted.col(a)).cwiseMin(predicted.col(b)),
           x.col(a).cwiseMax(x.col(b)).cwiseMax(predicted.col(a)).cwiseMax(predicted.col(b)) };
}

/// The box (low, high) around a body's nodes now (x) and predicted, widened by `widen` [m]; not finite if a
/// position is not (the divergence guard's case).
std::pair<Vec3, Vec3> bodyBox(const BodyRange& body, const NodeArray& x, const NodeArray& predicted, double widen)
{
  Vec3 low = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 high = -low;
  for (int p = body.first; p < body.first + body.count; ++p)
  {
    low = low.cwiseMin(x.col(p)).cwiseMin(predicted.col(p));
    high = high.cwiseMax(x.col(p)).cwiseMax(predicted.col(p));
  }
  return { low.array() - widen, high.array() + widen };
}

/// Of the touches from `first` on (one edge's against another body's), only the kEdgeTouches deepest: an
/// edge holds on a few others (a rope bent over a rim touches it with two segments), as a node on its
/// nearest triangle. In the tangle a long step leaves, every pair of near edges would hold, and the solve
/// would take all their couplings (seen: 4876 pairs in a cloth over a cube that had diverged).
void keepDeepest(std::vector<SurfaceTouch>& touches, std::size_t first)
{
  constexpr std::size_t kEdgeTouches = 2;
  if (touches.size() <= first + kEdgeTouches)
    return;
  const auto from = touches.begin() + static_cast<std::ptrdiff_t>(first);
  std::partial_sort(from, from + kEdgeTouches, touches.end(),
                    [](const SurfaceTouch& a, const SurfaceTouch& b) { return a.depth > b.depth; });
  touches.erase(from + static_cast<std::ptrdiff_t>(kEdgeTouches), touches.end());
}
}  // namespace

TrianglePoint nearestOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c)
{
  // Ericson's walk over the Voronoi regions: a corner, an edge or the face.
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0)
    return { a, Vec3(1.0, 0.0, 0.0) };
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3)
    return { b, Vec3(0.0, 1.0, 0.0) };
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0)
  {
    const double v = d1 / (d1 - d3);
    return { a + v * ab, Vec3(1.0 - v, v, 0.0) };
  }
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6)
    return { c, Vec3(0.0, 0.0, 1.0) };
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0)
  {
    const double w = d2 / (d2 - d6);
    return { a + w * ac, Vec3(1.0 - w, 0.0, w) };
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
  {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return { b + w * (c - b), Vec3(0.0, 1.0 - w, w) };
  }
  const double denominator = 1.0 / (va + vb + vc);
  const double v = vb * denominator, w = vc * denominator;
  return { a + v * ab + w * ac, Vec3(1.0 - v - w, v, w) };
}

SurfaceContacts::SurfaceContacts(const Model& model)
  : widest_(model.contact_radius.size() > 0 ? model.contact_radius.maxCoeff() : 0.0)
{
  if (model.bodies.size() < 2)
    return;
  for (std::size_t b = 0; b < model.bodies.size(); ++b)
    if (!model.bodies[b].surface.empty())
      solids_.push_back(b);
  if (solids_.empty())
    return;
  // Each body's run of contact triangles, then of segments (a body's are consecutive), of the bodies with
  // no surface.
  const auto addRuns = [&](std::size_t count, const auto& first_node, bool triangles) {
    for (std::size_t t = 0; t < count;)
    {
      const std::size_t body = model.bodyOf(first_node(t));
      std::size_t end = t + 1;
      while (end < count && model.bodyOf(first_node(end)) == body)
        ++end;
      if (model.bodies[body].surface.empty())
        thin_.push_back({ body, triangles, t, end });
      t = end;
    }
  };
  addRuns(model.contact_triangles.size(), [&](std::size_t t) { return model.contact_triangles[t][0]; }, true);
  addRuns(model.contact_segments.size(), [&](std::size_t s) { return model.contact_segments[s].first; }, false);
  if (solids_.size() < 2 && thin_.empty())
    return;  // no edges meet
  // Each body's edges, each once, with a solid's triangles on either side.
  edges_first_.push_back(0);
  std::vector<std::tuple<int, int, int>> sides;  // (lower node, higher node, triangle)
  const auto add = [&](const std::array<int, 3>* triangles, std::size_t count, bool solid) {
    sides.clear();
    for (std::size_t t = 0; t < count; ++t)
      for (int k = 0; k < 3; ++k)
        sides.emplace_back(std::min(triangles[t][k], triangles[t][(k + 1) % 3]),
                           std::max(triangles[t][k], triangles[t][(k + 1) % 3]), static_cast<int>(t));
    std::sort(sides.begin(), sides.end());
    for (std::size_t i = 0; i < sides.size();)
    {
      std::size_t j = i + 1;
      while (j < sides.size() && std::get<0>(sides[j]) == std::get<0>(sides[i]) &&
             std::get<1>(sides[j]) == std::get<1>(sides[i]))
        ++j;
      edges_.push_back({ std::get<0>(sides[i]), std::get<1>(sides[i]), solid ? std::get<2>(sides[i]) : -1,
                         solid && j > i + 1 ? std::get<2>(sides[i + 1]) : -1 });
      i = j;
    }
    edges_first_.push_back(edges_.size());
  };
  for (const std::size_t s : solids_)
    add(model.bodies[s].surface.data(), model.bodies[s].surface.size(), true);
  for (const Thin& thin : thin_)
  {
    if (thin.triangles)
    {
      add(model.contact_triangles.data() + thin.first, thin.end - thin.first, false);
      continue;
    }
    for (std::size_t s = thin.first; s < thin.end; ++s)
      edges_.push_back({ model.contact_segments[s].first, model.contact_segments[s].second, -1, -1 });
    edges_first_.push_back(edges_.size());
  }
}

void SurfaceContacts::find(const Model& model, const NodeArray& x, const NodeArray& predicted, double margin,
                           std::vector<SurfaceTouch>& touches)
{
  touches.clear();
  // The box around each solid now and where it is predicted, widened by the widest radius and the margin.
  low_.resize(solids_.size());
  high_.resize(solids_.size());
  for (std::size_t i = 0; i < solids_.size(); ++i)
    std::tie(low_[i], high_[i]) = bodyBox(model.bodies[solids_[i]], x, predicted, widest_ + margin);
  const auto finite = [&](std::size_t i) { return low_[i].allFinite() && high_[i].allFinite(); };
  for (std::size_t i = 0; i < solids_.size(); ++i)
  {
    if (!finite(i))
      continue;  // the divergence guard's case
    const std::size_t s = solids_[i];
    const BodyRange& solid = model.bodies[s];
    const Vec3& low = low_[i];
    const Vec3& high = high_[i];
    for (std::size_t other = 0; other < model.bodies.size(); ++other)
    {
      if (other == s)
        continue;
      const BodyRange& body = model.bodies[other];
      const double friction =
          body.surface.empty() ? solid.surface_friction : 0.5 * (solid.surface_friction + body.surface_friction);
      for (int p = body.first; p < body.first + body.count; ++p)
      {
        const Vec3 at = x.col(p);
        if (!inBox(at, low, high) && !inBox(predicted.col(p), low, high))
          continue;
        double nearest = std::numeric_limits<double>::infinity();
        const std::array<int, 3>* face = nullptr;
        TrianglePoint on{};
        for (const std::array<int, 3>& t : solid.surface)
        {
          const TrianglePoint candidate = nearestOnTriangle(at, x.col(t[0]), x.col(t[1]), x.col(t[2]));
          const double distance = (at - candidate.point).squaredNorm();
          if (distance < nearest)
          {
            nearest = distance;
            face = &t;
            on = candidate;
          }
        }
        if (face == nullptr)
          continue;  // a position that is not finite: the divergence guard's case
        const std::array<int, 3>& t = *face;
        const Vec3 across = (x.col(t[1]) - x.col(t[0])).cross(x.col(t[2]) - x.col(t[0]));
        const double twice_area = across.norm();
        if (!(twice_area > 0.0))
          continue;  // a collapsed triangle has no side
        Vec3 normal = across / twice_area;
        const Vec3 gap = at - on.point;
        if (normal.dot(gap) > 0.0)
          normal = (gap + kRounding * std::sqrt(twice_area) * normal).normalized();
        const Vec3 predicted_gap = predicted.col(p) - on.weight[0] * predicted.col(t[0]) -
                                   on.weight[1] * predicted.col(t[1]) - on.weight[2] * predicted.col(t[2]);
        const double depth = model.contact_radius[p] - normal.dot(predicted_gap);
        if (depth > -margin)
          touches.push_back({ { p, t[0], t[1], t[2] },
                              { 1.0, -on.weight[0], -on.weight[1], -on.weight[2] },
                              normal,
                              predicted_gap,
                              depth,
                              friction });
      }
    }
  }
  if (edges_.empty())
    return;
  // Which of the solids' edges are folds: only those touch another body's edges.
  fold_.resize(edges_first_[solids_.size()]);
  for (std::size_t i = 0; i < solids_.size(); ++i)
    for (std::size_t e = edges_first_[i]; e < edges_first_[i + 1]; ++e)
      fold_[e] = finite(i) && isFold(model, x, solids_[i], edges_[e]);
  outward_found_.assign(solids_.size(), 0);
  // Two solids' edges, those of each in the other's box.
  for (std::size_t i = 0; i < solids_.size(); ++i)
    for (std::size_t j = i + 1; j < solids_.size(); ++j)
    {
      if (!finite(i) || !finite(j))
        continue;
      edgesIn(i, x, predicted, low_[j], high_[j], near_first_);
      if (near_first_.empty())
        continue;
      edgesIn(j, x, predicted, low_[i], high_[i], near_second_);
      touchNearEdges(model, x, predicted, margin, solids_[i], solids_[j], false, touches);
    }
  // A solid against a thin body in its box.
  for (std::size_t k = 0; k < thin_.size(); ++k)
  {
    const auto [low, high] = bodyBox(model.bodies[thin_[k].body], x, predicted, widest_ + margin);
    if (!low.allFinite() || !high.allFinite())
      continue;
    for (std::size_t i = 0; i < solids_.size(); ++i)
      if (finite(i) && (high.array() >= low_[i].array()).all() && (low.array() <= high_[i].array()).all())
        touchThin(model, x, predicted, margin, i, k, low, high, touches);
  }
}

void SurfaceContacts::touchThin(const Model& model, const NodeArray& x, const NodeArray& predicted, double margin,
                                std::size_t i, std::size_t k, const Vec3& low, const Vec3& high,
                                std::vector<SurfaceTouch>& touches)
{
  const Thin& thin = thin_[k];
  const BodyRange& solid = model.bodies[solids_[i]];
  // Its triangles, or its segments, in the solid's box.
  near_triangles_.clear();
  for (std::size_t t = thin.first; thin.triangles && t < thin.end; ++t)
  {
    const std::array<int, 3>& triangle = model.contact_triangles[t];
    const auto [least, most] = sweptBox(triangle[0], triangle[1], x, predicted);
    const auto [least_c, most_c] = sweptBox(triangle[2], triangle[2], x, predicted);
    if ((most.cwiseMax(most_c).array() >= low_[i].array()).all() &&
        (least.cwiseMin(least_c).array() <= high_[i].array()).all())
      near_triangles_.push_back(t);
  }
  edgesIn(solids_.size() + k, x, predicted, low_[i], high_[i], near_second_);
  if (near_second_.empty())
    return;
  if (!thin.triangles && !outward_found_[i])
  {
    // Against segments only the solid's nodes on a fold (a rim's, a corner's: where a segment's chord can
    // cut in between the segment's nodes; on a flat face the segment's nodes meet the face), each with its
    // outward direction (its triangles' normals summed): found once per find, for every rope near it.
    outward_found_[i] = 1;
    outward_.resize(3, model.nodeCount());
    on_fold_.resize(static_cast<std::size_t>(model.nodeCount()));
    std::fill_n(on_fold_.begin() + solid.first, solid.count, false);
    outward_.middleCols(solid.first, solid.count).setZero();
    for (const std::array<int, 3>& t : solid.surface)
    {
      const Vec3 normal = (x.col(t[1]) - x.col(t[0])).cross(x.col(t[2]) - x.col(t[0])).normalized();
      for (const int node : t)
        outward_.col(node) += normal;
    }
    for (std::size_t e = edges_first_[i]; e < edges_first_[i + 1]; ++e)
      if (fold_[e])
        on_fold_[static_cast<std::size_t>(edges_[e].a)] = on_fold_[static_cast<std::size_t>(edges_[e].b)] = true;
  }
  // Its nodes, each against the nearest triangle or segment: pushed off a triangle's face on the side it is
  // on at x, or straight off the nearest edge, corner or segment's axis.
  for (int p = solid.first; p < solid.first + solid.count; ++p)
  {
    const Vec3 at = x.col(p);
    if ((!inBox(at, low, high) && !inBox(predicted.col(p), low, high)) ||
        (!thin.triangles && !on_fold_[static_cast<std::size_t>(p)]))
      continue;
    double nearest = std::numeric_limits<double>::infinity();
    std::array<int, 3> corners{};
    Vec3 on = Vec3::Zero(), weight = Vec3::Zero();
    for (const std::size_t t : near_triangles_)
    {
      const std::array<int, 3>& triangle = model.contact_triangles[t];
      const TrianglePoint candidate = nearestOnTriangle(at, x.col(triangle[0]), x.col(triangle[1]), x.col(triangle[2]));
      const double distance = (at - candidate.point).squaredNorm();
      if (distance < nearest)
      {
        nearest = distance;
        corners = triangle;
        on = candidate.point;
        weight = candidate.weight;
      }
    }
    for (std::size_t n = 0; !thin.triangles && n < near_second_.size(); ++n)
    {
      const Edge& segment = edges_[near_second_[n].edge];
      const Vec3 c = x.col(segment.a), along = x.col(segment.b) - c;
      const double t = closestSegmentParameters(at, Vec3::Zero(), c, along).second;
      const double distance = (at - c - t * along).squaredNorm();
      if (distance < nearest)
      {
        nearest = distance;
        corners = { segment.a, segment.b, segment.b };  // the third of weight 0
        on = c + t * along;
        weight = Vec3(1.0 - t, t, 0.0);
      }
    }
    if (!std::isfinite(nearest))
      continue;
    const Vec3 gap = at - on;
    const Vec3 across = thin.triangles
                            ? Vec3((x.col(corners[1]) - x.col(corners[0])).cross(x.col(corners[2]) - x.col(corners[0])))
                            : Vec3::Zero();
    Vec3 normal;
    if (weight.minCoeff() > 0.0 && across.squaredNorm() > 0.0)
      normal = (across.dot(gap) < 0.0 ? -1.0 : 1.0) * across.normalized();
    else if (gap.squaredNorm() > 0.0)
      normal = gap.normalized();
    else
      continue;  // on an edge or axis exactly: no side to hold it on
    // Off a segment's axis into the solid: a node that faces away from the axis is not the segment's to
    // hold (the segment lies beyond the solid, or the node is past its axis already).
    if (!thin.triangles && !(normal.dot(outward_.col(p)) < 0.0))
      continue;
    const Vec3 predicted_gap = predicted.col(p) - weight[0] * predicted.col(corners[0]) -
                               weight[1] * predicted.col(corners[1]) - weight[2] * predicted.col(corners[2]);
    // The triangle's thickness, or the segment's radius at its point.
    const double thickness = thin.triangles ? triangleThickness(model, corners)
                                            : weight[0] * model.contact_radius[corners[0]] +
                                                  weight[1] * model.contact_radius[corners[1]];
    const double depth = model.contact_radius[p] + thickness - normal.dot(predicted_gap);
    if (depth > -margin)
      touches.push_back({ { p, corners[0], corners[1], corners[2] },
                          { 1.0, -weight[0], -weight[1], -weight[2] },
                          normal,
                          predicted_gap,
                          depth,
                          solid.surface_friction });
  }
  // Its folds across the triangles' edges or the segments.
  edgesIn(i, x, predicted, low, high, near_first_);
  touchNearEdges(model, x, predicted, margin, solids_[i], thin.body, true, touches);
}

std::pair<Vec3, Vec3> SurfaceContacts::sideNormals(const Model& model, const NodeArray& x, std::size_t body,
                                                   const Edge& edge)
{
  const std::vector<std::array<int, 3>>& surface = model.bodies[body].surface;
  const auto normal = [&](int triangle) {
    const std::array<int, 3>& k = surface[static_cast<std::size_t>(triangle)];
    return Vec3((x.col(k[1]) - x.col(k[0])).cross(x.col(k[2]) - x.col(k[0])).normalized());
  };
  const Vec3 left = normal(edge.left);
  return { left, edge.right < 0 ? left : normal(edge.right) };
}

bool SurfaceContacts::isFold(const Model& model, const NodeArray& x, std::size_t body, const Edge& edge)
{
  if (edge.right < 0)
    return true;  // an open surface's rim
  const auto [left, right] = sideNormals(model, x, body, edge);
  return left.dot(right) < std::cos(kFold);
}

void SurfaceContacts::edgesIn(std::size_t k, const NodeArray& x, const NodeArray& predicted, const Vec3& low,
                              const Vec3& high, std::vector<NearEdge>& found) const
{
  found.clear();
  for (std::size_t e = edges_first_[k]; e < edges_first_[k + 1]; ++e)
  {
    if (k < solids_.size() && !fold_[e])
      continue;
    const auto [least, most] = sweptBox(edges_[e].a, edges_[e].b, x, predicted);
    if ((most.array() >= low.array()).all() && (least.array() <= high.array()).all())
      found.push_back({ e, least, most, (x.col(edges_[e].b) - x.col(edges_[e].a)).norm() });
  }
}

void SurfaceContacts::touchNearEdges(const Model& model, const NodeArray& x, const NodeArray& predicted, double margin,
                                     std::size_t first, std::size_t second, bool thin,
                                     std::vector<SurfaceTouch>& touches) const
{
  for (const NearEdge& e : near_first_)
  {
    const std::size_t before = touches.size();
    for (const NearEdge& f : near_second_)
      touchEdges(model, x, predicted, margin, e, f, first, second, thin, touches);
    keepDeepest(touches, before);
  }
}

void SurfaceContacts::touchEdges(const Model& model, const NodeArray& x, const NodeArray& predicted, double margin,
                                 const NearEdge& e, const NearEdge& f, std::size_t first, std::size_t second,
                                 bool thin, std::vector<SurfaceTouch>& touches) const
{
  const Edge& one = edges_[e.edge];
  const Edge& two = edges_[f.edge];
  const double radius = 0.5 * (model.contact_radius[one.a] + model.contact_radius[one.b]) +
                        0.5 * (model.contact_radius[two.a] + model.contact_radius[two.b]);
  const double deepest = kDeepestCrossing * std::min(e.length, f.length);
  // Their boxes, now and predicted, within the radius, the margin and the deepest crossing of each other:
  // most pairs are left here without their nearest points.
  const double reach = radius + margin + deepest;
  if (!((e.most.array() + reach >= f.least.array()).all() && (f.most.array() + reach >= e.least.array()).all()))
    return;
  const Vec3 a = x.col(one.a), along_one = x.col(one.b) - a;
  const Vec3 c = x.col(two.a), along_two = x.col(two.b) - c;
  const auto [s, t] = closestSegmentParameters(a, along_one, c, along_two, kNearParallelSine2);
  if (!(s > kEdgeEnd && s < 1.0 - kEdgeEnd && t > kEdgeEnd && t < 1.0 - kEdgeEnd))
    return;  // nearest at an end, or near parallel: that node and the other's faces
  const Vec3 across = along_one.cross(along_two);
  if (!(across.squaredNorm() > kNearParallelSine2 * along_one.squaredNorm() * along_two.squaredNorm()))
    return;
  // Each solid edge's outward direction (its triangles' normals summed; a thin body's edge has no side: the
  // solid's says which way n points).
  const auto outward = [&](const Edge& edge, std::size_t body) {
    const auto [left, right] = sideNormals(model, x, body, edge);
    return edge.right < 0 ? left : Vec3(left + right);
  };
  const Vec3 out_one = outward(one, first), out_two = thin ? -out_one : outward(two, second);
  Vec3 normal = across.normalized();
  if (normal.dot(out_two - out_one) < 0.0)
    normal = -normal;
  if (!(normal.dot(out_two) > 0.0 && normal.dot(out_one) < 0.0))
    return;  // not out of the second solid and into the first: no side to hold them on
  const Vec3 gap = a + s * along_one - c - t * along_two;
  if (normal.dot(gap) < -deepest)
    return;  // crossed too far to be these edges' contact
  const std::array<double, 4> weights{ 1.0 - s, s, -(1.0 - t), -t };
  const std::array<int, 4> nodes{ one.a, one.b, two.a, two.b };
  Vec3 predicted_gap = Vec3::Zero();
  for (std::size_t l = 0; l < 4; ++l)
    predicted_gap += weights[l] * predicted.col(nodes[l]);
  const double depth = radius - normal.dot(predicted_gap);
  if (depth > -margin)
    touches.push_back({ nodes, weights, normal, predicted_gap, depth,
                        thin ? model.bodies[first].surface_friction
                              : 0.5 * (model.bodies[first].surface_friction + model.bodies[second].surface_friction),
                        static_cast<std::int64_t>(e.edge * edges_.size() + f.edge) });
}

}  // namespace soft_body_sim
