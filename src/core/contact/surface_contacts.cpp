#include "core/contact/surface_contacts.h"

#include <cmath>
#include <limits>

namespace soft_body_sim
{
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
}

void SurfaceContacts::find(const Model& model, const NodeArray& x, const NodeArray& predicted, double margin,
                           std::vector<SurfaceTouch>& touches) const
{
  touches.clear();
  const auto inside = [](const Vec3& at, const Vec3& low, const Vec3& high) {
    return (at.array() >= low.array()).all() && (at.array() <= high.array()).all();
  };
  for (const std::size_t s : solids_)
  {
    const BodyRange& solid = model.bodies[s];
    // The box around the solid now and where it is predicted, widened by the widest radius and the margin.
    Vec3 low = Vec3::Constant(std::numeric_limits<double>::infinity());
    Vec3 high = -low;
    for (int i = solid.first; i < solid.first + solid.count; ++i)
    {
      low = low.cwiseMin(x.col(i)).cwiseMin(predicted.col(i));
      high = high.cwiseMax(x.col(i)).cwiseMax(predicted.col(i));
    }
    if (!low.allFinite() || !high.allFinite())
      continue;  // the divergence guard's case
    low.array() -= widest_ + margin;
    high.array() += widest_ + margin;
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
        if (!inside(at, low, high) && !inside(predicted.col(p), low, high))
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
          touches.push_back({ p, t, on.weight, normal, predicted_gap, depth, friction });
      }
    }
  }
}

}  // namespace soft_body_sim
