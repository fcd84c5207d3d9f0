// A cloth's triangles against a collider (`face_contacts: true`): where a thin shape touches a cloth
// between its nodes. Private to the core.
//
// Two convex bodies come closest, or overlap deepest, at a corner of one against a face of the other or at
// an edge against an edge. A triangle's corners are nodes, which meet the shape's exact surface already
// (ShapeContacts' node contacts); what is left is the shape's own edges and corners against the triangle's
// face and edges. So a shape is described here by its features: segments, thickened by a radius, whose
// union with the nodes' contacts is the shape as a triangle meets it: a sphere is its centre thickened by
// its radius, a capsule its axis, a box its twelve edges (radius 0), a cylinder its axis (radius r, its
// ends flat) and the edges of its rims (a polygon of kRimSides; inscribed, it lies inside the rim by at most
// r (1 - cos(pi / kRimSides)) = 0.0086 r).
//
// No tunnelling: a face contact is taken on the side of the triangle where the feature was at the start of
// the sub-step, so a feature that crossed the face in one sub-step (a 1 cm finger moving 3.3 cm per step)
// pushes the face back to its own far side, instead of out through the side it went to (a feature that lay
// across the face's plane at the start, a rail through a jelly's plane, meets the triangle's edges only).
// That is a swept test in its simplest form: it holds as long as the feature's crossing point stays over
// the face it crossed within a sub-step, and ShapeContacts widens its search by the sub-step's motion to
// find it.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <vector>

#include <Eigen/Geometry>

#include "core/contact/closest_points.h"
#include "soft_body_sim/core/contact/colliders.h"
#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
/// A segment a + s (b - a), s in [0, 1], thickened by `radius` [m] (a point when a == b).
/// `flat_ends`: the shape ends flat at a and b (a cylinder's axis), so only what lies beside the segment,
/// between the planes through a and b normal to it, touches it.
struct ShapeFeature
{
  Vec3 a;
  Vec3 b;
  double radius = 0.0;
  bool flat_ends = false;
};

/// The sides of the polygons that stand for a cylinder's rims.
constexpr int kRimSides = 24;

/// Each shape's features in its local frame.
inline std::vector<ShapeFeature> shapeFeatures(const Sphere& sphere)
{
  return { { Vec3::Zero(), Vec3::Zero(), sphere.radius, false } };
}

inline std::vector<ShapeFeature> shapeFeatures(const Capsule& capsule)
{
  const Vec3 half(0.0, 0.0, 0.5 * capsule.length);
  return { { -half, half, capsule.radius, false } };
}

inline std::vector<ShapeFeature> shapeFeatures(const Box& box)
{
  std::vector<ShapeFeature> features;
  const Vec3 half = 0.5 * box.size;
  for (int axis = 0; axis < 3; ++axis)
    for (const double u : { -1.0, 1.0 })
      for (const double w : { -1.0, 1.0 })
      {
        Vec3 a, b;
        a[axis] = -half[axis];
        b[axis] = half[axis];
        a[(axis + 1) % 3] = b[(axis + 1) % 3] = u * half[(axis + 1) % 3];
        a[(axis + 2) % 3] = b[(axis + 2) % 3] = w * half[(axis + 2) % 3];
        features.push_back({ a, b, 0.0, false });
      }
  return features;
}

inline std::vector<ShapeFeature> shapeFeatures(const Cylinder& cylinder)
{
  const double half = 0.5 * cylinder.length;
  std::vector<ShapeFeature> features{ { Vec3(0.0, 0.0, -half), Vec3(0.0, 0.0, half), cylinder.radius, true } };
  const auto rim = [&](int k, double z) {
    const double angle = 2.0 * M_PI * k / kRimSides;
    return Vec3(cylinder.radius * std::cos(angle), cylinder.radius * std::sin(angle), z);
  };
  for (const double z : { -half, half })
    for (int k = 0; k < kRimSides; ++k)
      features.push_back({ rim(k, z), rim(k + 1, z), 0.0, false });
  return features;
}

/// A mesh's edges where its surface turns outward (convex), and the rims of an open one, at their exact
/// place (radius 0; the nodes meet the mesh through its distance field). A flat edge (its two triangles in
/// one plane) or an inward one (the floor of a groove) is left out: the faces beside it, which the nodes
/// meet, come nearer to any triangle outside the mesh than it does.
std::vector<ShapeFeature> shapeFeatures(const Mesh& mesh);

/// Consecutive features of a shape [first, last) within `radius` [m] (their own radii included) of
/// `centre` (in the shape's frame): a triangle beyond that skips them all (a cylinder's rims of 24 edges
/// in arcs of 8, a box's twelve edges in two sets).
struct FeatureGroup
{
  std::size_t first = 0;
  std::size_t last = 0;
  Vec3 centre;
  double radius = 0.0;
};

/// The features in groups of up to kFeatureGroup, each about the middle of its endpoints' bounding box.
constexpr std::size_t kFeatureGroup = 8;
inline std::vector<FeatureGroup> featureGroups(const std::vector<ShapeFeature>& features)
{
  std::vector<FeatureGroup> groups;
  for (std::size_t first = 0; first < features.size(); first += kFeatureGroup)
  {
    FeatureGroup group;
    group.first = first;
    group.last = std::min(features.size(), first + kFeatureGroup);
    Eigen::AlignedBox3d box;
    for (std::size_t f = group.first; f < group.last; ++f)
    {
      box.extend(features[f].a);
      box.extend(features[f].b);
    }
    group.centre = box.center();
    for (std::size_t f = group.first; f < group.last; ++f)
      group.radius = std::max({ group.radius, (features[f].a - group.centre).norm() + features[f].radius,
                                (features[f].b - group.centre).norm() + features[f].radius });
    groups.push_back(group);
  }
  return groups;
}

/// A triangle's bounding ball at the sub-step's start and end: its centroids and the largest distance
/// of a corner from its centroid at either.
struct TriangleBall
{
  TriangleBall(const std::array<Vec3, 3>& now, const std::array<Vec3, 3>& then)
    : centre((now[0] + now[1] + now[2]) / 3.0), centre_then((then[0] + then[1] + then[2]) / 3.0)
  {
    double size2 = 0.0;
    for (int c = 0; c < 3; ++c)
      size2 = std::max({ size2, (now[c] - centre).squaredNorm(), (then[c] - centre_then).squaredNorm() });
    size = std::sqrt(size2);
  }

  /// Whether a point moving straight from p_then to p comes within `reach` [m] of the ball moving
  /// straight from its start to its end (relative to each other).
  bool meets(const Vec3& p, const Vec3& p_then, double reach) const
  {
    const Vec3 offset = centre - p, offset_then = centre_then - p_then;
    const Vec3 path = offset - offset_then;
    const double length2 = path.squaredNorm();
    const double s = length2 > 0.0 ? std::clamp(-offset_then.dot(path) / length2, 0.0, 1.0) : 0.0;
    const double within = reach + size;
    return (offset_then + s * path).squaredNorm() <= within * within;
  }

  /// Whether feature f (f_then at the start), thickened by `thickness` [m] more, comes within the ball, its
  /// point nearest to the ball's centre followed through the sub-step.
  bool meetsSegment(const ShapeFeature& f, const ShapeFeature& f_then, double thickness) const
  {
    const Vec3 d = f.b - f.a;
    const double length2 = d.squaredNorm();
    const double s = length2 > 0.0 ? std::clamp((centre - f.a).dot(d) / length2, 0.0, 1.0) : 0.0;
    return meets(f.a + s * d, f_then.a + s * (f_then.b - f_then.a), f.radius + thickness);
  }

  Vec3 centre;
  Vec3 centre_then;
  double size = 0.0;
};

/// Where a triangle must move to clear a feature: its point sum_k weight_k x_k moves by `depth` [m] along
/// the unit `normal`; `contact` is the point of the shape's surface that it touches [m].
struct FaceTouch
{
  Vec3 weight;
  Vec3 normal;
  double depth = 0.0;
  Vec3 contact;
};

/// A contact triangle's thickness [m]: its nodes' mean contact radius.
inline double triangleThickness(const Model& model, const std::array<int, 3>& triangle)
{
  return (model.contact_radius[triangle[0]] + model.contact_radius[triangle[1]] + model.contact_radius[triangle[2]]) /
         3.0;
}

/// The corners of a triangle [m].
using TriangleCorners = std::array<Vec3, 3>;

/// The part [lo, hi] of the segment a + s (b - a), s in [0, 1], that lies over triangle t (inside the prism
/// the triangle sweeps along its normal n, not necessarily unit); false if none does.
inline bool overTriangle(const Vec3& a, const Vec3& b, const TriangleCorners& t, const Vec3& n, double& lo, double& hi)
{
  lo = 0.0;
  hi = 1.0;
  for (int k = 0; k < 3; ++k)
  {
    // Inside the edge t_k -> t_(k+1): (n x edge) . (x - t_k) >= 0, linear in s: f0 + s (f1 - f0).
    const Vec3 inward = n.cross(t[(k + 1) % 3] - t[k]);
    const double f0 = inward.dot(a - t[k]), f1 = inward.dot(b - t[k]);
    if (f0 < 0.0 && f1 < 0.0)
      return false;
    if (f0 < 0.0)
      lo = std::max(lo, f0 / (f0 - f1));
    else if (f1 < 0.0)
      hi = std::min(hi, f0 / (f0 - f1));
  }
  return lo <= hi;
}

/// The barycentric weights of the point p in the plane of triangle t with normal n (not necessarily unit).
inline Vec3 barycentric(const Vec3& p, const TriangleCorners& t, const Vec3& n)
{
  const double area2 = n.squaredNorm();
  const double wb = n.dot((t[2] - p).cross(t[0] - p)) / area2;
  const double wc = n.dot((t[0] - p).cross(t[1] - p)) / area2;
  return Vec3(1.0 - wb - wc, wb, wc);
}

/// How far [m] the feature's point at parameter s moved in the sub-step relative to the triangle's point of
/// barycentric weights `weight`: the most a contact can have crossed in it. A contact pushes no deeper than
/// that beyond the contact distance, so a triangle that a long feature pierces at a slant (its corner
/// swung round the feature, not the feature through its face) is not thrown the length of the feature's
/// part over it.
inline double relativeMotion(const ShapeFeature& f, const ShapeFeature& f_start, double s, const TriangleCorners& t,
                             const TriangleCorners& t_start, const Vec3& weight)
{
  Vec3 moved = (f.a + s * (f.b - f.a)) - (f_start.a + s * (f_start.b - f_start.a));
  for (int k = 0; k < 3; ++k)
    moved -= weight[k] * (t[k] - t_start[k]);
  return moved.norm();
}

/// The feature f (at the sub-step's end; `f_start` at its start) against triangle t (`t_start` at the
/// start), whose corners keep `thickness` [m] from the shape and whose face and edges `face_thickness`:
/// where the triangle is closer to the feature's axis than that plus f.radius, the deepest of
/// - over the face: the deepest point of the feature's part over the triangle, measured on the side the
///   feature's part was on at the start (see the file's comment); the face moves along its normal. Not for
///   a part that crossed the triangle's plane at the start (a rail through an upright jelly's plane): it
///   came from neither side, and the edges below meet it;
/// - beside it: the nearest points of the feature and each of the triangle's edges or corners, measured
///   along the direction from the one to the other at the start (so an edge or a node that slipped past
///   the feature within the sub-step comes back: a node's own contact with the shape's surface pushes it
///   out where it is nearest, which past a thin shape's middle is its far side); the edge's point moves
///   that way.
inline std::optional<FaceTouch> faceTouch(const ShapeFeature& f, const ShapeFeature& f_start, const TriangleCorners& t,
                                          const TriangleCorners& t_start, double thickness, double face_thickness)
{
  const double corner_reach = f.radius + thickness, reach = f.radius + face_thickness;
  const Vec3 n = (t[1] - t[0]).cross(t[2] - t[0]);
  const double area2 = n.norm();
  if (!(area2 > 0.0))
    return std::nullopt;  // a collapsed triangle: its edges are its neighbours' too
  const Vec3 unit = n / area2;
  std::optional<FaceTouch> deepest;
  double lo, hi;
  if (overTriangle(f.a, f.b, t, n, lo, hi))
  {
    const Vec3 p_lo = f.a + lo * (f.b - f.a), p_hi = f.a + hi * (f.b - f.a);
    const double h_lo = unit.dot(p_lo - t[0]), h_hi = unit.dot(p_hi - t[0]);
    // The side at the start: of the same part of the feature, over the triangle where it was then.
    const double mid = 0.5 * (lo + hi);
    const Vec3 n_start = (t_start[1] - t_start[0]).cross(t_start[2] - t_start[0]);
    const auto height_start = [&](double s) { return n_start.dot(f_start.a + s * (f_start.b - f_start.a) - t_start[0]); };
    const double h_start = height_start(mid);
    const double side = h_start != 0.0 ? std::copysign(1.0, h_start) : std::copysign(1.0, h_lo + h_hi);
    const bool low = side * h_lo <= side * h_hi;
    const double height = side * (low ? h_lo : h_hi);
    const double at = low ? lo : hi;
    const Vec3 p = low ? p_lo : p_hi;
    const Vec3 on_face = p - (unit.dot(p - t[0])) * unit;
    const bool beside =
        f.flat_ends && !((f.b - f.a).dot(on_face - f.a) > 0.0 && (f.a - f.b).dot(on_face - f.b) > 0.0);
    // A feature whose part crossed the triangle's plane at the start (a rail through a jelly's plane, met by
    // the jelly's outline) came from no side of the face: its edges meet it.
    const double start_lo = height_start(lo), start_hi = height_start(hi);
    const bool crossing = (start_lo < 0.0 && start_hi > 0.0) || (start_lo > 0.0 && start_hi < 0.0);
    if (height < reach && !beside && !crossing)
    {
      const Vec3 weight = barycentric(on_face, t, n);
      const double moved = relativeMotion(f, f_start, at, t, t_start, weight);
      deepest = FaceTouch{ weight, -side * unit, std::min(reach - height, reach + moved), p - side * f.radius * unit };
    }
  }
  for (int k = 0; k < 3; ++k)
  {
    const int next = (k + 1) % 3;
    const Vec3 edge = t[next] - t[k];
    const auto [s, u] = closestSegmentParameters(f.a, f.b - f.a, t[k], edge);
    const Vec3 p = f.a + s * (f.b - f.a), q = t[k] + u * edge;
    if (f.flat_ends && ((s <= 0.0 && (f.b - f.a).dot(q - f.a) <= 0.0) || (s >= 1.0 && (f.a - f.b).dot(q - f.b) <= 0.0)))
      continue;  // beyond a flat end: the rim's
    Vec3 away = (t_start[k] + u * (t_start[next] - t_start[k])) - (f_start.a + s * (f_start.b - f_start.a));
    if (!(away.squaredNorm() > 0.0))
      away = q - p;
    const double length = away.norm();
    if (!(length > 0.0))
      continue;
    away /= length;
    Vec3 weight = Vec3::Zero();
    weight[k] = 1.0 - u;
    weight[next] = u;
    const double edge_reach = u > 0.0 && u < 1.0 ? reach : corner_reach;
    const double depth =
        std::min(edge_reach - away.dot(q - p), edge_reach + relativeMotion(f, f_start, s, t, t_start, weight));
    if (!(depth > 0.0) || (deepest && depth <= deepest->depth))
      continue;
    deepest = FaceTouch{ weight, away, depth, p + f.radius * away };
  }
  return deepest;
}

}  // namespace soft_body_sim
