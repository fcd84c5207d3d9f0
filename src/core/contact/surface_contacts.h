// Where other bodies touch a soft solid's surface (`type: volume`): every node of another body (a rope's,
// a cloth's, another solid's) that is within its contact radius of a solid's boundary triangles, or behind
// them; where two solids meet, every fold of one's boundary near or across a fold of the other's; where a
// solid meets a cloth's (or a jelly's) contact triangles, the solid's nodes against them and its folds
// across their edges; and its rims' nodes and its folds against a rope's (or a rod's) segments.
// implicit_euler holds each such pair apart inside its Newton solve (see its surface holds). A scene with
// no solid, or with a solid and no other body, has no finder and pays nothing.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <utility>
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

/// Two bodies touching at a solid's surface (see SurfaceContacts::find), as the gap g = sum_l weights_l
/// x_(nodes_l) between the two points that touch:
/// - a node p of one body near or behind a boundary triangle of a solid: nodes (p, the triangle's three),
///   weights (1, -w_0, -w_1, -w_2), so g = x_p - q with q the triangle's point nearest to p at weights w;
/// - a node p of a solid near a cloth's contact triangle: the same, the triangle the cloth's;
/// - an edge (a, b) of one solid's boundary near or across an edge (c, d) of another's, of a cloth's
///   contact triangles or a rope's segment: nodes (a, b, c, d), weights (1 - s, s, -(1 - t), -t), so g is
///   the first edge's point minus the second's, s and t where the edges come closest.
/// n is the direction along which the first point is held out (from the triangle, or from the second
/// edge), d = r - n . g its depth (> 0: closer than r, or behind). r is the node's contact radius (and the
/// cloth triangle's thickness, its nodes' mean radius), or the sum of the two edges' nodes' mean radii.
struct SurfaceTouch
{
  std::array<int, 4> nodes;
  std::array<double, 4> weights;
  Vec3 normal;
  Vec3 gap;  ///< g [m] at the predicted positions
  double depth;
  double friction;  ///< Coulomb coefficient: the solid's `friction`, the mean of two solids'
  /// -1 for a node on a triangle (nodes[0] is the node); for two edges, a number no other pair of edges has
  std::int64_t edges = -1;

  void carry(StateArchive& archive) { archive(nodes, weights, normal, depth, edges); }
};

class SurfaceContacts
{
public:
  explicit SurfaceContacts(const Model& model);

  /// True if no body can touch a solid's surface: find() finds nothing.
  bool empty() const { return solids_.empty(); }

  /// The largest contact radius of any node [m] (radii are fixed when the world is built).
  double widestRadius() const { return widest_; }

  /// Every node p of a body other than the solid's that is near or behind a solid's boundary triangle, and
  /// every pair of edges of two solids' boundaries that are near or across each other, into `touches`
  /// (cleared first).
  ///
  /// A node's triangle is the nearest to p at the positions x (the start of the step), and so are the
  /// weights and n: the triangle's outward normal where p is behind its plane, else the direction from q to
  /// p rounded towards that normal by kRounding of the triangle's size (the normal of the face where q lies
  /// inside it; off an edge or a corner it turns with p, and where p sits on a corner of a flat face it is
  /// the face's normal, not a direction that flips with p's smallest offsets). Taking the triangle where p
  /// is, not where it is predicted, holds a node that approaches a face fast on that face (predicted past
  /// it, it may lie nearer another).
  ///
  /// Two edges touch where they come closest at x inside both (at an end, that end's node meets the other
  /// solid's faces), both are folds of their surfaces (their two triangles turn by more than kFold: two
  /// rims crossing, where neither has a node on the other's face), and they are not within ~10 degrees of
  /// parallel (then the nodes meet the faces). An edge inside a flat face is left to the other solid's
  /// nodes on that face: a rim's contact with it, tried, set the rim's nodes chattering at 0.1 m/s where
  /// two turned cubes rest on each other (friction's share of it: 1 mm/s without). n is across both edges,
  /// pointing out of the second solid at its edge and into the first at its own (the sum of each edge's two
  /// triangle normals says which way is out): so two edges that have crossed are pushed back the way they
  /// came. Pairs crossed by more than kDeepestCrossing of the shorter edge are left (no longer a contact of
  /// those edges).
  ///
  /// A solid meets a cloth's (or a jelly's) contact triangles, two-sided sheets as thick as their nodes'
  /// contact radii, with its nodes and its folds: a node against the nearest triangle, off its face on the
  /// side it is on at x, or straight off its nearest edge or corner; a fold across an edge of the triangles,
  /// along the common normal pointing into the solid. So a cloth draped over a soft box does not let the
  /// box's rims and corners through between its nodes. Its folds meet a rope's (or a rod's) segments the
  /// same way, at the rope's radius, and so do its nodes on a fold (the nearest segment's axis, a node
  /// facing away from it skipped): a rope over a box's rim does not cut into it between its nodes.
  ///
  /// The depth is at the `predicted` positions (x + h v), d = r - n . g, and a pair is kept when
  /// d > -margin. Nodes and edges outside the other solid's bounding box now and predicted, widened by the
  /// largest contact radius and the margin, are skipped without looking at a triangle or an edge.
  void find(const Model& model, const NodeArray& x, const NodeArray& predicted, double margin,
            std::vector<SurfaceTouch>& touches);

  /// The rounding of edges and corners, relative to the square root of twice a triangle's area.
  static constexpr double kRounding = 0.1;

  /// Two edges whose nearest points lie within this fraction of an end of either do not touch: that end's
  /// node meets the other solid's faces (and where two solids' rims meet at their corners, a touch that
  /// came and went with the smallest motion would set them chattering).
  static constexpr double kEdgeEnd = 0.05;
  /// Two edges crossed by more than this fraction of the shorter one's length do not touch.
  static constexpr double kDeepestCrossing = 0.25;
  /// An edge is a fold where its two triangles' normals differ by more than this angle [rad] (an open
  /// surface's rim is one too).
  static constexpr double kFold = 30.0 * M_PI / 180.0;

private:
  /// A boundary edge of a solid: its nodes, the surface's triangles on either side (Model::bodies' surface
  /// indices; the second -1 on an open surface's rim).
  struct Edge
  {
    int a, b;
    int left, right;
  };
  /// A body without a surface that meets a solid by more than its nodes: a cloth's or a jelly's contact
  /// triangles (Model::contact_triangles [first, end): two-sided sheets as thick as their nodes' contact
  /// radii), or a rope's or a rod's segments (Model::contact_segments [first, end), of their nodes' radii).
  struct Thin
  {
    std::size_t body;
    bool triangles;
    std::size_t first, end;
  };
  /// The unit normals at positions x of the triangles on either side of `edge` of solid `body`'s boundary
  /// (both the one triangle's on an open surface's rim).
  static std::pair<Vec3, Vec3> sideNormals(const Model& model, const NodeArray& x, std::size_t body, const Edge& edge);
  /// Whether `edge` of solid `body`'s boundary is a fold at positions x (kFold).
  static bool isFold(const Model& model, const NodeArray& x, std::size_t body, const Edge& edge);
  /// The edges of a surface (k < solids_.size(): solids_[k]'s boundary folds, else thin_[k - solids_.size()]'s
  /// triangles' or segments) in `edges_` that lie in the box [low, high] now or predicted.
  /// An edge in another body's box: its index in edges_, its box now and predicted, its length now [m].
  struct NearEdge
  {
    std::size_t edge;
    Vec3 least, most;
    double length;
  };
  void edgesIn(std::size_t k, const NodeArray& x, const NodeArray& predicted, const Vec3& low, const Vec3& high,
               std::vector<NearEdge>& found) const;
  /// Every edge of near_first_ (Model::bodies `first`'s, a solid's) against every edge of near_second_
  /// (`second`'s; `thin` as touchEdges) whose boxes come near enough, each keeping its deepest touches.
  void touchNearEdges(const Model& model, const NodeArray& x, const NodeArray& predicted, double margin,
                      std::size_t first, std::size_t second, bool thin, std::vector<SurfaceTouch>& touches) const;
  /// Edges e and f, e a solid's (Model::bodies `first`), f another solid's (`second`) or, if `thin`, a thin
  /// body's, into `touches` if they touch (find).
  void touchEdges(const Model& model, const NodeArray& x, const NodeArray& predicted, double margin,
                  const NearEdge& e, const NearEdge& f, std::size_t first, std::size_t second, bool thin,
                  std::vector<SurfaceTouch>& touches) const;
  /// solids_[i] against thin_[k] (find): its nodes against the thin body's triangles, its folds across
  /// their edges or its segments; [low, high] the thin body's box.
  void touchThin(const Model& model, const NodeArray& x, const NodeArray& predicted, double margin, std::size_t i,
                  std::size_t k, const Vec3& low, const Vec3& high, std::vector<SurfaceTouch>& touches);

  double widest_;                    ///< widestRadius()
  std::vector<std::size_t> solids_;  ///< bodies with a surface (Model::bodies), when another body exists
  std::vector<Thin> thin_;           ///< the thin bodies, when a solid exists
  /// the edges of two or more solids' boundaries, and of the thin bodies' triangles or segments if there is
  /// a solid, each once, a body's in a run (a thin body's edges have no triangles: left and right -1)
  std::vector<Edge> edges_;
  /// per body (solids_, then thin_), its first edge in edges_ (and one past the last)
  std::vector<std::size_t> edges_first_;
  /// per solid edge (edges_ before edges_first_[solids_.size()]), whether it is a fold at find's x (an
  /// edge inside a flat face meets no edge: the other body's nodes meet that face)
  std::vector<bool> fold_;
  std::vector<std::size_t> near_triangles_;  ///< touchThin's triangles in the solid's box
  NodeArray outward_;                        ///< touchThin's outward directions of the solids' nodes
  std::vector<bool> on_fold_;                ///< touchThin's: per node, on a fold of its solid
  std::vector<char> outward_found_;          ///< per solid: outward_ and on_fold_ found in this find
  std::vector<Vec3> low_, high_;     ///< find's boxes around the solids (per entry of solids_)
  std::vector<NearEdge> near_first_, near_second_;  ///< find's edges in the other body's box
};

}  // namespace soft_body_sim
