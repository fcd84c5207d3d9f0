// The self-contact stage of a step: the links of bodies that ask for it (`self_collision`; a rope's links,
// a cloth's nodes as balls, a jelly's nodes as balls and its springs as capsules) keep apart by their
// radii, within a body and between such bodies, so that a rope can lie on itself, coil and hold a knot, a
// folded cloth's layers stay apart and no node of a squeezed jelly crosses a spring. A scene in which no
// body asks has no pass here and pays nothing.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "soft_body_sim/core/model.h"
#include "soft_body_sim/core/state_archive.h"

namespace soft_body_sim
{
/// A uniform grid hashed into a table (a spatial hash, Teschner et al. 2003, "Optimized Spatial Hashing
/// for Collision Detection of Deformable Objects"), over balls: a segment's midpoint and half length, a
/// face's centroid and its farthest corner from it. With cells at least as wide as the two largest radii
/// and the widest gap asked about, two balls within that gap of each other sit in the same or neighbouring
/// cells. The cells that hold balls are numbered and found by their coordinates in a hash table, so that
/// a query reads its 27 cells' balls and no others, and a search for all near pairs each two neighbouring
/// cells once. Built by a counting sort each time, the balls copied
/// in the cells' order so that a cell's are read one after the other: no allocation once its arrays have
/// grown to the ball count.
class BallGrid
{
public:
  /// Sorts the balls (`centre` [m], one per column, and `radius` [m]) into cells of width `cell` [m] (> 0).
  void build(const NodeArray& centre, const std::vector<double>& radius, double cell);

  /// Calls visit(s, t) once for every pair s < t of balls closer than `gap` [m] to each other (their
  /// centres closer than their radii and the gap, which must not exceed the cell's width less the two
  /// largest radii), cell by cell: in no order of s or t.
  template <typename Visit>
  void forEachNearPair(double gap, Visit visit) const;

  /// Calls visit(t) for every ball closer than `gap` [m] to a ball at `centre` [m] of `radius` [m] (radius,
  /// gap and the largest radius together within the cell's width).
  template <typename Visit>
  void forEachNear(const Vec3& centre, double radius, double gap, Visit visit) const;

private:
  /// Cell coordinate i's term of the hash along `axis` (Teschner et al.'s primes): a cell's slot is made
  /// from the three's exclusive or (slotOf).
  static std::uint64_t hashTerm(std::int64_t i, int axis);
  /// The table's slot where a cell of these terms is looked for first.
  std::size_t slotOf(std::uint64_t terms) const;
  /// True if the cell numbered `cell` is the one at coordinates c.
  bool sameCell(std::uint32_t cell, const std::int32_t* c) const;
  std::int32_t coordinate(double position) const;
  /// The cells around c (i, j, k) numbered 0 to 26 by their offsets (di, dj, dk), each -1, 0 or 1, in the
  /// order of di, then dj, then dk; c's own is kOwnCell. The numbers of the balls' cells among those from
  /// `first` on, each once; their count.
  int cellsAround(const std::int32_t* c, int first, std::uint32_t* cells) const;
  static constexpr int kOwnCell = 13;
  /// Calls visit(t) for every ball t at the places [from[q], to[q]) of the sorted arrays, q < count,
  /// closer than `gap` to the ball (p, r).
  template <typename Visit>
  void visitRanges(const std::uint32_t* from, const std::uint32_t* to, int count, const Vec3& p, double r,
                   double gap, Visit visit) const;

  static constexpr std::uint32_t kEmpty = 0xffffffffu;
  double cell_ = 1.0;  ///< [m]
  int shift_ = 63;     ///< 64 less the bits of the table's size
  /// A hash table with linear probing, at most half full: per slot, the number of a cell that has balls,
  /// or kEmpty. Only a cell's own balls are read, not those of cells that share its hash.
  std::vector<std::uint32_t> table_;
  std::vector<std::int32_t> cell_key_;  ///< per cell: its i, j, k
  std::vector<std::uint32_t> start_;    ///< per cell: where its balls begin in the sorted arrays
  std::vector<std::uint32_t> cell_of_;  ///< per ball: its cell's number
  std::vector<std::uint32_t> cursor_;   ///< per cell: the next free place while sorting
  /// the balls in cell order: index, centre [m] and radius [m]
  std::vector<std::uint32_t> sorted_;
  std::vector<double> x_, y_, z_, r_;
};

template <typename Visit>
void BallGrid::visitRanges(const std::uint32_t* from, const std::uint32_t* to, int count, const Vec3& p, double r,
                           double gap, Visit visit) const
{
  // The arrays' starts held here: visit may write memory, which would have them read again for each ball.
  const std::uint32_t* sorted = sorted_.data();
  const double *x = x_.data(), *y = y_.data(), *z = z_.data(), *radius = r_.data();
  // The balls tested without a branch, those that pass written to `found` and visited a batch at a time:
  // whether a ball is near is a coin toss the processor cannot learn (mispredicted tests were most of a
  // draping cloth's search). The same balls, in the same order, as visiting each as it is tested.
  constexpr int kBatch = 64;
  std::uint32_t found[kBatch];
  int taken = 0;
  const auto visit_taken = [&] {
    for (int k = 0; k < taken; ++k)
      visit(static_cast<std::size_t>(found[k]));
    taken = 0;
  };
  for (int q = 0; q < count; ++q)
    for (std::size_t e = from[q]; e < to[q]; ++e)
    {
      const double reach = r + radius[e] + gap;
      const double dx = x[e] - p.x(), dy = y[e] - p.y(), dz = z[e] - p.z();
      found[taken] = sorted[e];
      taken += static_cast<int>(dx * dx + dy * dy + dz * dz < reach * reach);
      if (taken == kBatch)
        visit_taken();
    }
  visit_taken();
}

template <typename Visit>
void BallGrid::forEachNearPair(double gap, Visit visit) const
{
  if (start_.empty())
    return;
  // Cell by cell, each ball against the later balls of its own cell and all those of the 13 cells after it
  // (a half shell): each two neighbouring cells are looked at once, and the cells around are looked up once
  // a cell, not once a ball (a ball's 27 probes of the hash table were about 30 % of a draping cloth's
  // search in perf's profile).
  const std::size_t cells = start_.size() - 1;
  std::uint32_t later[kOwnCell];
  std::uint32_t from[kOwnCell + 1], to[kOwnCell + 1];
  for (std::size_t q = 0; q < cells; ++q)
  {
    const int around = cellsAround(&cell_key_[3 * q], kOwnCell + 1, later);
    for (int k = 0; k < around; ++k)
    {
      from[k + 1] = start_[later[k]];
      to[k + 1] = start_[later[k] + 1];
    }
    to[0] = start_[q + 1];
    for (std::uint32_t e = start_[q]; e < start_[q + 1]; ++e)
    {
      from[0] = e + 1;
      const std::size_t s = sorted_[e];
      visitRanges(from, to, around + 1, Vec3(x_[e], y_[e], z_[e]), r_[e], gap, [&](std::size_t t) {
        if (s < t)
          visit(s, t);
        else
          visit(t, s);
      });
    }
  }
}

template <typename Visit>
void BallGrid::forEachNear(const Vec3& centre, double radius, double gap, Visit visit) const
{
  const std::int32_t c[3] = { coordinate(centre.x()), coordinate(centre.y()), coordinate(centre.z()) };
  std::uint32_t cells[27], from[27], to[27];
  const int count = cellsAround(c, 0, cells);
  for (int q = 0; q < count; ++q)
  {
    from[q] = start_[cells[q]];
    to[q] = start_[cells[q] + 1];
  }
  visitRanges(from, to, count, centre, radius, gap, visit);
}

/// Segment-against-segment contact of the bodies with `self_collision` (BodyRange); a body without links
/// (a cloth, a jelly) gives each node as a segment from the node to itself, and one with springs_collide
/// (a jelly) its springs as well, against which only its nodes collide. A cloth with `face_contacts` gives
/// its triangles instead (Model::contact_triangles): their edges as segments of its thickness, and their
/// faces, which every colliding node keeps out of (a node against a face, an edge against an edge: every
/// way two such bodies come closest). A 5 mm rope then lies on a cloth of 5 cm spacing, which its nodes
/// as balls would let it fall through.
class SelfContacts
{
public:
  /// `rest`: the nodes' positions [m] at rest (the scene's start), which tell a cloth's neighbours apart.
  SelfContacts(const Model& model, const NodeArray& rest);

  /// At the start of a sub-step (before anchors move): where the links start, from which friction
  /// measures their slip and a node tells the side of a face it came from. Nothing without friction or
  /// faces.
  void remember(const State& state);

  /// After a sub-step's integration and colliders: every two links closer than their radii together
  /// (not neighbours along one rope, see kSkippedLinks) are pushed apart along the line between their
  /// nearest points, the correction shared by their four nodes in proportion to their inverse masses and
  /// weights there, their approach speed along that line removed, and Coulomb friction (the mean of the
  /// two bodies' self_friction) acts on their slip past each other; kPasses times. A node over a face
  /// closer than its radius and the face's thickness together is pushed out along the face's normal the
  /// same way, to the side it was on at the sub-step's start (one that crossed the face within the
  /// sub-step comes back), the correction shared by the node and the face's three by their weights. True
  /// if any pair touched.
  bool resolve(const Model& model, State& state);

  /// How many times the candidate pairs have been searched: once per Verlet list (kSkinRadii).
  std::size_t searches() const { return searches_; }

  /// Writes or reads the Verlet lists and what the passes keep from sub-step to sub-step
  /// (state_archive.h); the links, faces and their radii are the scene's, travel_, entry_, near_index_,
  /// candidate_bound_ and live_ are each resolve's own, and found_, run_start_, the balls (middle_, half_,
  /// face_centre_, face_extent_) and the grids each search's, written before they are read.
  void carry(StateArchive& archive)
  {
    archive(start_, skin_, candidates_, found_at_, moved_, searches_, near_, moved_at_, tick_, face_candidates_,
            near_faces_);
  }

  /// Two links of one body whose first nodes are this many places apart or fewer never collide: a rope
  /// bent back on itself within a few links touches itself at its joints already.
  static constexpr int kSkippedLinks = 2;
  /// Gauss-Seidel passes over the touching pairs per sub-step: a link pressed from several sides at once
  /// (a pile) needs more than one.
  static constexpr int kPasses = 4;

  /// A pair is taken into a sub-step's passes while its links are within their near radii together: each link's radius
  /// times this. A rope's links twice over: in a pile, a pass pushes a pair that was clear into touch, and the passes
  /// see it at once (once over let a coiled rope's links come to 0.89 diameters apart and a plectoneme's to 0.78, below
  /// the tests' 0.9). A face-contact cloth's edges once over, as its nodes over its faces: three edges a square, each as
  /// long as the spacing, have many more pairs within twice their thickness, nearly all of them neighbours in the
  /// cloth's own plane, and the search for them was most of the step (ClothOnSphere/triangles 2.3 times dearer); a pair
  /// pushed into touch is taken in by the next sub-step (the folding cloth's layers at 0.93 of their contact distance
  /// or more, against 0.95). A cloth's or jelly's nodes as balls once over too: twice over, with the skin, reached its
  /// nodes two spacings apart in its own plane (4 cm at 2 cm spacing and 8 mm thickness, within 2 x 1.6 cm + 1.6 cm),
  /// six candidates a node in a flat cloth that never touch, searched for and bounded every sub-step
  /// (ClothOnSphere/self_collision 10.2 to 7.5 ms a step; the folded cloth's layers 1.309 and 1.311 thicknesses apart).
  static constexpr double kNearRadiiOfLinks = 2.0;
  static constexpr double kNearRadiiOfEdges = 1.0;
  static constexpr double kNearRadiiOfBalls = 1.0;

  /// The candidate pairs (those that may touch) are found with a margin, the skin, of this many largest
  /// radii, and kept until some node has moved half the skin relative to a common motion (a Verlet
  /// list, as in molecular dynamics): a pile at rest, or a cloth falling flat, is searched once, not
  /// every sub-step. A link's or edge's skin is kSkinRadii; a ball's kSkinRadiiOfBalls, since its near
  /// radius is one radius (kNearRadiiOfBalls) and a skin of three still leaves out a flat cloth's nodes
  /// two spacings apart (ClothOnSphere/self_collision 7.5 ms a step with 2, 6.4 with 2.5, 5.9 with 3, 6.7
  /// with 4; a coiled rope's links 338 us with 2, 350 with 2.5, 382 with 3). A pair is found within the
  /// mean of its two skins, and a node keeps the list while it has moved less than half the least skin of
  /// its segments: a pair's links then come nearer by at most the mean of their skins.
  static constexpr double kSkinRadii = 2.0;
  static constexpr double kSkinRadiiOfBalls = 3.0;

private:
  /// True if no node of a colliding link has moved half its least skin, relative to a common motion, since
  /// the candidates were found; each node's distance so moved into moved_.
  bool candidatesHold(const NodeArray& x);
  /// The pairs within their search radii together (near radii and skins), through the spatial hash.
  void findCandidates(const NodeArray& x);
  /// Each segment as a ball at positions y (about its midpoint, of half its length) into middle_ and half_,
  /// and grid_ built over them for pairs within `reach` [m] of each other.
  void gridSegments(const NodeArray& y, double reach);
  /// True if segments s and t end on a common node (neighbours along a rope, a cloth's edges at a corner).
  bool shareANode(std::size_t s, std::size_t t) const;
  /// True if segment t (s < t) is among s's neighbours at rest (rest_near_), which it never touches.
  bool nearAtRest(std::size_t s, std::size_t t) const;

  /// The pairs of one body that its springs hold apart, their contact at rest within twice their radii:
  /// a cloth's or jelly's nodes (balls) and a face-contact cloth's edges, into rest_near_.
  void findRestNeighbours();
  /// The node-face pairs within the radii and the skin (each of nodes_ against faces_ through face_grid_).
  void findFaceCandidates(const NodeArray& x);
  /// A node's place over a face now: its weights there, the face's unit normal towards the side the node
  /// started on, and the node's height over the face that way [m]; false if the node is not over it.
  struct OverFace
  {
    Vec3 weight;
    Vec3 normal;
    double height;
  };
  bool overFace(const NodeArray& x, int node, std::size_t face, double side, OverFace& over) const;
  /// The node's side of the face at the sub-step's start (+1 along its normal, -1 against it; `now`'s if
  /// it lay in the face's plane then).
  double startSide(const NodeArray& now, int node, std::size_t face) const;
  /// The passes over the node-face pairs (see resolve); true if any touched.
  bool resolveFaces(const Model& model, State& state);

  std::vector<std::pair<int, int>> segments_;  ///< global node pairs of the colliding links
  std::vector<int> body_;                      ///< per segment: its body
  std::vector<bool> springs_collide_;          ///< per body: BodyRange::springs_collide
  std::vector<bool> by_faces_;                 ///< per body: collides by its contact triangles
  std::vector<double> radius_;                 ///< per segment: its nodes' mean contact radius [m]
  NodeArray rest_;                             ///< every node at rest [m], if any link collides
  std::vector<double> friction_;               ///< per segment: its body's self_friction [-]
  bool any_friction_ = false;
  NodeArray start_;                            ///< positions at the sub-step's start, if friction or faces [m]
  double largest_radius_ = 0.0;                ///< [m]
  std::vector<double> near_radius_;            ///< per segment: its radius times kNearRadiiOfLinks, Edges or Balls [m]
  /// per segment: its near radius and half its skin, within which its pairs are found (their sum) [m]
  std::vector<double> search_radius_;
  double widest_search_ = 0.0;                 ///< [m]
  std::vector<int> nodes_;                     ///< the nodes of the colliding links, each once
  std::vector<double> hold_limit_;             ///< per node of nodes_: the square of half its segments' least skin [m^2]
  double skin_ = 0.0;                          ///< the widest segment's skin [m]
  NodeArray middle_;                           ///< per segment: its midpoint when candidates are found [m]
  std::vector<double> half_;                   ///< per segment: half its length then [m]
  BallGrid grid_;
  /// Per segment s, the later segments t (s < t) of its body near it at rest, which it never collides with
  /// (findRestNeighbours): rest_near_[rest_near_start_[s] .. rest_near_start_[s + 1]); none without balls
  /// or face-contact cloths.
  std::vector<std::uint32_t> rest_near_start_, rest_near_;
  /// A pair of links that may touch, and their least distance when found [m].
  struct Candidate
  {
    std::uint32_t s, t;  ///< segment indices, s < t
    double distance;

    void carry(StateArchive& archive) { archive(s, t, distance); }
  };
  /// The pairs that may touch, ordered by s and then t: the order the passes take the touching ones in,
  /// whatever the search (its grid, its skin) or how often it runs, so that none of that changes a bit.
  std::vector<Candidate> candidates_;
  /// The search's own: the candidates as the grid finds them (in no order), and where each segment's run
  /// of them begins once ordered (sortByGroups).
  std::vector<Candidate> found_;
  std::vector<std::uint32_t> run_start_;
  NodeArray found_at_;                         ///< positions when the candidates were found [m]
  /// per node (global index): how far it has moved since the candidates were found, relative to the
  /// colliding nodes' common motion (the middle of their displacements' bounding box) [m] (candidatesHold)
  std::vector<double> moved_;
  std::size_t searches_ = 0;
  /// Two links' contact at some positions: their nearest points' parameters p (on s) and q (on t), the
  /// distance [m] and unit normal n from t's point to s's, the links' least distance (the contact's, or less
  /// where kNearParallelSine2 took their ends) [m], each node's share (its weight there times its inverse
  /// mass) and their sum weighted again (resolve).
  struct Contact
  {
    double p, q, distance, least, ka, kb, kc, kd, weight;
    Vec3 n;

    void carry(StateArchive& archive) { archive(p, q, distance, least, ka, kb, kc, kd, weight, n); }
  };
  /// Two links that may touch this sub-step, and what friction may still spend there.
  struct NearPair
  {
    std::uint32_t s, t;  ///< segment indices
    double push;         ///< [m] the normal passes' push apart, less what friction has cancelled / mu
    double stop;         ///< [m/s] the approach speed they removed, likewise
    Contact contact{};   ///< its contact when last looked at (at tick `seen`)
    bool valid = false;  ///< that contact has a direction and a free node
    std::uint64_t seen = 0;
    double travel = 0.0;  ///< [m] its four nodes' travel_, summed, at tick `seen`

    void carry(StateArchive& archive) { archive(s, t, push, stop, contact, valid, seen, travel); }
  };
  /// The near pairs of this sub-step, as the passes found them (resolve).
  std::vector<NearPair> near_;
  /// per candidate: its place in near_, or kFar (not near this sub-step) or kUnknown (not looked at yet)
  std::vector<std::int32_t> near_index_;
  static constexpr std::int32_t kFar = -2, kUnknown = -1;
  /// per candidate: at most its links' least distance at the sub-step's start [m]
  std::vector<double> candidate_bound_;
  /// the candidates not found far at this call's start (kUnknown), in order: those the passes look at
  std::vector<std::uint32_t> live_;
  /// per node (global index): the tick_ of the last push that moved it
  std::vector<std::uint64_t> moved_at_;
  /// per node (global index): how far the passes of this resolve have moved it, summed [m] (from 0 for the
  /// colliding nodes at each call)
  std::vector<double> travel_;
  NodeArray entry_;  ///< the positions at the start of this resolve [m]
  std::uint64_t tick_ = 0;  ///< counts resolve's pushes of positions, over all sub-steps

  std::vector<std::array<int, 3>> faces_;  ///< the contact triangles of the colliding cloths
  std::vector<int> face_body_;             ///< per face: its body
  std::vector<double> face_radius_;        ///< per face: its nodes' mean contact radius (thickness) [m]
  std::vector<double> face_friction_;      ///< per face: its body's self_friction [-]
  std::vector<double> node_radius_;        ///< per node of nodes_: its contact radius [m]
  std::vector<int> node_body_;             ///< per node of nodes_: its body
  NodeArray face_centre_;                  ///< per face: its centroid when candidates are found [m]
  std::vector<double> face_extent_;        ///< per face: its farthest corner from there [m]
  BallGrid face_grid_;
  /// (node, face) pairs that may touch, ordered by node and then face (as candidates_)
  std::vector<std::pair<std::uint32_t, std::uint32_t>> face_candidates_;
  /// A node over a face this sub-step: the side it started on, and what the passes gave (as NearPair).
  struct NearFace
  {
    int node;
    std::uint32_t face;
    double side;
    double push;
    double stop;

    void carry(StateArchive& archive) { archive(node, face, side, push, stop); }
  };
  std::vector<NearFace> near_faces_;
};

}  // namespace soft_body_sim
