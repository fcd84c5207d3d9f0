// Where other bodies touch a soft solid's surface (`type: volume`): every node of another body (a rope's,
// a cloth's, another solid's) that is within its contact radius of a solid's boundary triangles, or behind
// them. implicit_euler holds each such node on the surface inside its Newton solve, coupled to the
// triangle's three nodes (see its surface holds). A scene with no solid, or with a solid and no other body,
// has no finder and pays nothing.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
/// The point of triangle (a, b, c) nearest to p and its barycentric weights (Ericson 2005, "Real-Time
/// Collision Detection" 5.1.5): point = weight[0] a + weight[1] b + weight[2] c, the weights >= 0 summing
/// to 1.
struct TrianglePoint
{
  Vec3 point;
  Vec3 weight;
};
TrianglePoint nearestOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

/// A node p of one body near or behind a boundary triangle of a solid: the weights of the triangle's point q
/// nearest to p, q = sum_k weight_k x_(triangle_k), the direction n along which p is held out of the solid,
/// and its depth d = r_p - n . (x_p - q) (> 0: closer than its contact radius, or behind); see find.
struct SurfaceTouch
{
  int node;
  std::array<int, 3> triangle;
  Vec3 weight;
  Vec3 normal;
  Vec3 gap;  ///< x_p - q [m] at the predicted positions
  double depth;
  double friction;  ///< Coulomb coefficient: the solid's `friction`, the mean of two solids'
};

class SurfaceContacts
{
public:
  explicit SurfaceContacts(const Model& model);

  /// True if no body can touch a solid's surface: find() finds nothing.
  bool empty() const { return solids_.empty(); }

  /// The largest contact radius of any node [m] (radii are fixed when the world is built).
  double widestRadius() const { return widest_; }

  /// Every node p of a body other than the solid's that is near or behind a solid's boundary triangle, into
  /// `touches` (cleared first). The triangle is the nearest to p at the positions x (the start of the step),
  /// and so are the weights and n: the triangle's outward normal where p is behind its plane, else the
  /// direction from q to p rounded towards that normal by kRounding of the triangle's size (the normal of
  /// the face where q lies inside it; off an edge or a corner it turns with p, and where p sits on a corner
  /// of a flat face it is the face's normal, not a direction that flips with p's smallest offsets). The
  /// depth is at the `predicted` positions (x + h v): d = r_p - n . (p - q), and p is kept when d > -margin.
  /// Taking the triangle where p is, not where it is predicted, holds a node that approaches a face fast on
  /// that face (predicted past it, it may lie nearer another). Nodes outside the solid's bounding box now
  /// and predicted, widened by the largest contact radius and the margin, are skipped without looking at a
  /// triangle.
  void find(const Model& model, const NodeArray& x, const NodeArray& predicted, double margin,
            std::vector<SurfaceTouch>& touches) const;

  /// The rounding of edges and corners, relative to the square root of twice a triangle's area.
  static constexpr double kRounding = 0.1;

private:
  double widest_;                    ///< widestRadius()
  std::vector<std::size_t> solids_;  ///< bodies with a surface (Model::bodies), when another body exists
};

}  // namespace soft_body_sim
