// The self-contact stage of a step: the links of bodies that ask for it (`self_collision`; a rope's links,
// a cloth's nodes as balls, a jelly's nodes as balls and its springs as capsules) keep apart by their
// radii, within a body and between such bodies, so that a rope can lie on itself, coil and hold a knot, a
// folded cloth's layers stay apart and no node of a squeezed jelly crosses a spring. A scene in which no
// body asks has no pass here and pays nothing.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
/// A uniform grid hashed into a table (a spatial hash, Teschner et al. 2003, "Optimized Spatial Hashing
/// for Collision Detection of Deformable Objects"), over segments: each segment sits in the cell of its
/// midpoint, and with cells at least as wide as the longest segment plus the two largest radii, two
/// segments that come within their radii of each other sit in the same or neighbouring cells. Built by a
/// counting sort each time: no allocation once its arrays have grown to the segment count.
class SegmentGrid
{
public:
  /// Sorts `segments` (node index pairs into `x`) into cells of width `cell` [m] (> 0).
  void build(const NodeArray& x, const std::vector<std::pair<int, int>>& segments, double cell);

  /// Calls visit(s, t) once for every pair s < t of segments in the same or neighbouring cells (and some
  /// more, whose cells share a slot of the table): a superset of the pairs within `cell` of each other.
  template <typename Visit>
  void forEachNearPair(Visit visit) const;

private:
  std::int64_t slot(std::int64_t i, std::int64_t j, std::int64_t k) const;

  std::vector<std::int32_t> coordinate_;  ///< per segment: its cell's i, j, k
  std::vector<std::uint32_t> start_;      ///< per slot: where its segments begin in sorted_
  std::vector<std::uint32_t> sorted_;     ///< segment indices sorted by slot
  std::vector<std::uint32_t> slot_of_;    ///< per segment: its slot
  std::vector<std::uint32_t> cursor_;     ///< per slot: the next free place while sorting
};

template <typename Visit>
void SegmentGrid::forEachNearPair(Visit visit) const
{
  const std::size_t count = slot_of_.size();
  for (std::size_t s = 0; s < count; ++s)
  {
    const std::int32_t* c = &coordinate_[3 * s];
    // The 27 cells around s's, each non-empty slot looked at once even if two of them share it.
    std::int64_t seen[27];
    int seen_count = 0;
    for (int di = -1; di <= 1; ++di)
      for (int dj = -1; dj <= 1; ++dj)
        for (int dk = -1; dk <= 1; ++dk)
        {
          const std::int64_t slot_index = slot(c[0] + di, c[1] + dj, c[2] + dk);
          const std::size_t slot_u = static_cast<std::size_t>(slot_index);
          if (start_[slot_u] == start_[slot_u + 1])
            continue;  // empty: most of them, and nothing to tell apart
          bool repeated = false;
          for (int q = 0; q < seen_count; ++q)
            repeated = repeated || seen[q] == slot_index;
          if (repeated)
            continue;
          seen[seen_count++] = slot_index;
          for (std::uint32_t e = start_[slot_u]; e < start_[slot_u + 1]; ++e)
            if (sorted_[e] > s)
              visit(s, static_cast<std::size_t>(sorted_[e]));
        }
  }
}

/// Segment-against-segment contact of the bodies with `self_collision` (BodyRange); a body without links
/// (a cloth, a jelly) gives each node as a segment from the node to itself, and one with springs_collide
/// (a jelly) its springs as well, against which only its nodes collide.
class SelfContacts
{
public:
  /// `rest`: the nodes' positions [m] at rest (the scene's start), which tell a cloth's neighbours apart.
  SelfContacts(const Model& model, const NodeArray& rest);

  /// At the start of a sub-step (before anchors move): where the links start, from which friction
  /// measures their slip. Nothing without friction.
  void remember(const State& state);

  /// After a sub-step's integration and colliders: every two links closer than their radii together
  /// (not neighbours along one rope, see kSkippedLinks) are pushed apart along the line between their
  /// nearest points, the correction shared by their four nodes in proportion to their inverse masses and
  /// weights there, their approach speed along that line removed, and Coulomb friction (the mean of the
  /// two bodies' self_friction) acts on their slip past each other; kPasses times. True if any pair
  /// touched.
  bool resolve(const Model& model, State& state);

  /// How many times the candidate pairs have been searched: once per Verlet list (kSkinRadii).
  std::size_t searches() const { return searches_; }

  /// Two links of one body whose first nodes are this many places apart or fewer never collide: a rope
  /// bent back on itself within a few links touches itself at its joints already.
  static constexpr int kSkippedLinks = 2;
  /// Gauss-Seidel passes over the touching pairs per sub-step: a link pressed from several sides at once
  /// (a pile) needs more than one.
  static constexpr int kPasses = 4;

  /// The candidate pairs (those that may touch) are found with a margin, the skin, of this many largest
  /// radii, and kept until some node has moved half the skin relative to their mean motion (a Verlet
  /// list, as in molecular dynamics): a pile at rest, or a cloth falling flat, is searched once, not
  /// every sub-step.
  static constexpr double kSkinRadii = 2.0;

private:
  /// True if no node of a colliding link has moved half the skin, relative to their mean motion, since
  /// the candidates were found.
  bool candidatesHold(const NodeArray& x) const;
  /// The pairs within twice their radii and the skin, through the spatial hash.
  void findCandidates(const NodeArray& x);

  std::vector<std::pair<int, int>> segments_;  ///< global node pairs of the colliding links
  std::vector<int> body_;                      ///< per segment: its body
  std::vector<bool> springs_collide_;          ///< per body: BodyRange::springs_collide
  std::vector<double> radius_;                 ///< per segment: its nodes' mean contact radius [m]
  NodeArray rest_;                             ///< per segment: its first node at rest [m]
  std::vector<double> friction_;               ///< per segment: its body's self_friction [-]
  bool any_friction_ = false;
  NodeArray start_;                            ///< positions at the sub-step's start, if any friction [m]
  double largest_radius_ = 0.0;                ///< [m]
  std::vector<int> nodes_;                     ///< the nodes of the colliding links, each once
  double skin_ = 0.0;                          ///< [m]
  NodeArray middle_;                           ///< per segment: its midpoint when candidates are found [m]
  std::vector<double> half_;                   ///< per segment: half its length then [m]
  SegmentGrid grid_;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> candidates_;  ///< pairs that may touch
  NodeArray found_at_;                         ///< positions when the candidates were found [m]
  std::size_t searches_ = 0;
  /// Two links that may touch this sub-step, and what friction may still spend there.
  struct NearPair
  {
    std::uint32_t s, t;  ///< segment indices
    double push;         ///< [m] the normal passes' push apart, less what friction has cancelled / mu
    double stop;         ///< [m/s] the approach speed they removed, likewise
  };
  std::vector<NearPair> near_;
};

}  // namespace soft_body_sim
