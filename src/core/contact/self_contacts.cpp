#include "soft_body_sim/core/contact/self_contacts.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <optional>
#include <tuple>

#include "core/contact/closest_points.h"
#include "core/contact/face_contacts.h"
#include "core/contact/surface_contacts.h"

namespace soft_body_sim
{
namespace
{
/// The vector [m] from the contact point of `to`'s segment to that of `from`'s (closestSegmentParameters,
/// kNearParallelSine2), and their parameters p (along `from`) and q (along `to`); `by_ends` as there.
Vec3 contactGap(const NodeArray& x, const std::pair<int, int>& from, const std::pair<int, int>& to, double& p,
                double& q, bool& by_ends)
{
  by_ends = false;
  if (from.first == from.second && to.first == to.second)
  {
    // Two balls (a cloth's or jelly's nodes): the general case's answer, without its work.
    p = q = 0.0;
    return x.col(from.first) - x.col(to.first);
  }
  const Vec3 xa = x.col(from.first), xc = x.col(to.first);
  const Vec3 along_from = x.col(from.second) - xa, along_to = x.col(to.second) - xc;
  std::tie(p, q) = closestSegmentParameters(xa, along_from, xc, along_to, kNearParallelSine2, &by_ends);
  return (xa + p * along_from) - (xc + q * along_to);
}

/// The two segments' least distance [m]: contactGap's without the near-parallel rule, which may take ends
/// farther apart than the lines' nearest points; so never more than contactGap's.
double leastDistance(const NodeArray& x, const std::pair<int, int>& from, const std::pair<int, int>& to)
{
  const Vec3 xa = x.col(from.first), xc = x.col(to.first);
  const Vec3 along_from = x.col(from.second) - xa, along_to = x.col(to.second) - xc;
  const auto [p, q] = closestSegmentParameters(xa, along_from, xc, along_to);
  return ((xa + p * along_from) - (xc + q * along_to)).norm();
}

/// Whether a lower bound of two links' distance, `bound` [m], puts them beyond `reach` [m]: with a hair's
/// margin, so that the rounding of the bound (sums of distances and motions) stays on the side of looking.
bool beyond(double bound, double reach)
{
  return bound > reach * (1.0 + 1e-9) + 1e-12;
}

/// Coulomb friction at a contact of unit normal n: the change of `relative` (a motion, or a velocity, at
/// the contact) that cancels its tangential part up to friction * budget, what it takes spent from budget;
/// none if it has no tangential part.
std::optional<Vec3> frictionChange(const Vec3& relative, const Vec3& n, double friction, double& budget)
{
  const Vec3 tangential = relative - relative.dot(n) * n;
  const double length = tangential.norm();
  if (!(length > 0.0))
    return std::nullopt;
  const double taken = std::min(length, friction * budget);
  budget -= taken / friction;
  return -(taken / length) * tangential;
}

/// Sorts `items`, found grouped by `group` in ascending order (a search's pairs by their first item), by
/// `within` inside each group: the order of (group, within), at the cost of sorting the small groups.
template <typename Item, typename Group, typename Within>
void sortWithinRuns(std::vector<Item>& items, Group group, Within within)
{
  for (auto run = items.begin(); run != items.end();)
  {
    const auto key = group(*run);
    const auto end = std::find_if(run, items.end(), [&](const Item& item) { return group(item) != key; });
    std::sort(run, end, [&](const Item& a, const Item& b) { return within(a) < within(b); });
    run = end;
  }
}

/// Sorts `items` by (group, within), group(item) < groups: by group with a counting sort (through
/// `scratch`; start[g] is then where group g's run begins, start[groups] the end), then inside each group
/// (sortWithinRuns). A search that finds its pairs in no order of their first item (BallGrid's cell by
/// cell) orders them in a time linear in their count.
template <typename Item, typename Group, typename Within>
void sortByGroups(std::vector<Item>& items, std::size_t groups, Group group, Within within, std::vector<Item>& scratch,
                  std::vector<std::uint32_t>& start)
{
  start.assign(groups + 1, 0);
  for (const Item& item : items)
    ++start[static_cast<std::size_t>(group(item)) + 1];
  for (std::size_t g = 0; g < groups; ++g)
    start[g + 1] += start[g];
  scratch.resize(items.size());
  for (const Item& item : items)
    scratch[start[static_cast<std::size_t>(group(item))]++] = item;
  // start[g] is now where group g + 1 begins: shifted back by one.
  for (std::size_t g = groups; g > 0; --g)
    start[g] = start[g - 1];
  start[0] = 0;
  items.swap(scratch);
  sortWithinRuns(items, group, within);
}

}  // namespace

std::int32_t BallGrid::coordinate(double position) const
{
  // Kept far from the integer limits (a node at 1e300 m is a diverged one the guard deals with; here it
  // only has to stay a valid index).
  return static_cast<std::int32_t>(std::clamp(std::floor(position / cell_), -1e9, 1e9));
}

std::uint64_t BallGrid::hashTerm(std::int64_t i, int axis)
{
  static constexpr std::uint64_t kPrimes[3] = { 73856093u, 19349663u, 83492791u };
  return static_cast<std::uint64_t>(i) * kPrimes[axis];
}

std::size_t BallGrid::slotOf(std::uint64_t terms) const
{
  // The terms' exclusive or has weak low bits (a flat cloth's cells fell into two thirds as many slots):
  // its product with 2^64 / golden ratio, whose high bits mix all of them (Knuth's multiplicative hash).
  return static_cast<std::size_t>((terms * 0x9E3779B97F4A7C15ull) >> shift_);
}

bool BallGrid::sameCell(std::uint32_t cell, const std::int32_t* c) const
{
  const std::int32_t* key = &cell_key_[3 * static_cast<std::size_t>(cell)];
  return key[0] == c[0] && key[1] == c[1] && key[2] == c[2];
}

int BallGrid::cellsAround(const std::int32_t* c, int first, std::uint32_t* cells) const
{
  // The hash's three terms for each axis's three cells, each worked out once.
  std::uint64_t term[3][3];
  for (int axis = 0; axis < 3; ++axis)
    for (int d = 0; d < 3; ++d)
      term[axis][d] = hashTerm(static_cast<std::int64_t>(c[axis]) + d - 1, axis);
  const std::size_t mask = table_.size() - 1;
  int count = 0;
  std::int32_t around[3];
  for (int index = first; index < 27; ++index)
  {
    const int di = index / 9, dj = index / 3 % 3, dk = index % 3;
    around[0] = c[0] + di - 1;
    around[1] = c[1] + dj - 1;
    around[2] = c[2] + dk - 1;
    // Linear probing: the cell's entry, or an empty one where it would be (most of them).
    for (std::size_t slot = slotOf(term[0][di] ^ term[1][dj] ^ term[2][dk]);; slot = (slot + 1) & mask)
    {
      const std::uint32_t cell = table_[slot];
      if (cell == kEmpty)
        break;
      if (sameCell(cell, around))
      {
        cells[count++] = cell;
        break;
      }
    }
  }
  return count;
}

void BallGrid::build(const NodeArray& centre, const std::vector<double>& radius, double cell)
{
  cell_ = cell;
  const std::size_t count = radius.size();
  std::size_t slots = 2;  // a power of two, at least twice the balls: a mask, not a division, per probe
  shift_ = 63;
  while (slots < 2 * count)
  {
    slots *= 2;
    --shift_;
  }
  cell_of_.resize(count);
  sorted_.resize(count);
  x_.resize(count);
  y_.resize(count);
  z_.resize(count);
  r_.resize(count);
  table_.assign(slots, kEmpty);
  cell_key_.reserve(3 * count);  // at most a cell a ball: no allocation once grown to the ball count
  cell_key_.clear();
  const std::size_t mask = slots - 1;
  for (std::size_t s = 0; s < count; ++s)
  {
    std::int32_t c[3];
    for (int axis = 0; axis < 3; ++axis)
      c[axis] = coordinate(centre(axis, static_cast<Eigen::Index>(s)));
    std::size_t slot = slotOf(hashTerm(c[0], 0) ^ hashTerm(c[1], 1) ^ hashTerm(c[2], 2));
    while (table_[slot] != kEmpty && !sameCell(table_[slot], c))
      slot = (slot + 1) & mask;
    if (table_[slot] == kEmpty)
    {
      table_[slot] = static_cast<std::uint32_t>(cell_key_.size() / 3);
      cell_key_.insert(cell_key_.end(), c, c + 3);
    }
    cell_of_[s] = table_[slot];
  }
  const std::size_t cells = cell_key_.size() / 3;
  start_.reserve(count + 1);
  start_.assign(cells + 1, 0);
  for (std::size_t s = 0; s < count; ++s)
    ++start_[cell_of_[s] + 1];
  for (std::size_t q = 0; q < cells; ++q)
    start_[q + 1] += start_[q];
  cursor_.reserve(count);
  cursor_.assign(start_.begin(), start_.end() - 1);
  for (std::size_t s = 0; s < count; ++s)
  {
    const std::uint32_t e = cursor_[cell_of_[s]]++;
    sorted_[e] = static_cast<std::uint32_t>(s);
    x_[e] = centre(0, static_cast<Eigen::Index>(s));
    y_[e] = centre(1, static_cast<Eigen::Index>(s));
    z_[e] = centre(2, static_cast<Eigen::Index>(s));
    r_[e] = radius[s];
  }
}

SelfContacts::SelfContacts(const Model& model, const NodeArray& rest)
{
  if (model.contact_radius.size() != model.nodeCount())
    return;  // a model made without radii (World gives it zeros): points, which do not collide
  const auto add = [&](int a, int b, std::size_t body) {
    const double radius = 0.5 * (model.contact_radius[a] + model.contact_radius[b]);
    if (!model.bodies[body].self_collision || !(radius > 0.0))
      return;
    segments_.emplace_back(a, b);
    body_.push_back(static_cast<int>(body));
    radius_.push_back(radius);
    friction_.push_back(model.bodies[body].self_friction);
    any_friction_ = any_friction_ || model.bodies[body].self_friction > 0.0;
    largest_radius_ = std::max(largest_radius_, radius);
  };
  std::vector<bool> has_links(model.bodies.size(), false);
  for (const auto& [a, b] : model.contact_segments)
  {
    const std::size_t body = model.bodyOf(a);
    has_links[body] = true;
    add(a, b, body);
  }
  // A cloth with face contacts: its triangles' edges, each once, and its faces. A jelly's (springs_collide)
  // meet colliders only: it keeps apart by its nodes and springs.
  by_faces_.assign(model.bodies.size(), false);
  std::vector<std::pair<int, int>> edges;
  for (const std::array<int, 3>& triangle : model.contact_triangles)
  {
    const std::size_t body = model.bodyOf(triangle[0]);
    const double radius = triangleThickness(model, triangle);
    if (!model.bodies[body].self_collision || model.bodies[body].springs_collide || !(radius > 0.0))
      continue;
    has_links[body] = true;
    by_faces_[body] = true;
    faces_.push_back(triangle);
    face_body_.push_back(static_cast<int>(body));
    face_radius_.push_back(radius);
    face_friction_.push_back(model.bodies[body].self_friction);
    for (int k = 0; k < 3; ++k)
      edges.emplace_back(std::min(triangle[k], triangle[(k + 1) % 3]), std::max(triangle[k], triangle[(k + 1) % 3]));
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  for (const auto& [a, b] : edges)
    add(a, b, model.bodyOf(a));
  // A body without links (a cloth, a jelly) collides by its nodes, each a ball of its contact radius: a
  // segment from the node to itself.
  for (std::size_t body = 0; body < model.bodies.size(); ++body)
    if (!has_links[body])
      for (int i = model.bodies[body].first; i < model.bodies[body].first + model.bodies[body].count; ++i)
        add(i, i, body);
  // A jelly's springs too, which its nodes stay out of.
  for (const Spring& spring : model.springs)
  {
    const std::size_t body = model.bodyOf(spring.a);
    if (model.bodies[body].springs_collide)
      add(spring.a, spring.b, body);
  }
  for (const BodyRange& body : model.bodies)
    springs_collide_.push_back(body.springs_collide);
  if (!segments_.empty())
    rest_ = rest;  // a scene without self-collision keeps no copy
  middle_.setZero(3, static_cast<Eigen::Index>(segments_.size()));
  half_.assign(segments_.size(), 0.0);
  for (const auto& [a, b] : segments_)
    nodes_.insert(nodes_.end(), { a, b });
  std::sort(nodes_.begin(), nodes_.end());
  nodes_.erase(std::unique(nodes_.begin(), nodes_.end()), nodes_.end());
  std::vector<double> least_skin(static_cast<std::size_t>(model.nodeCount()), std::numeric_limits<double>::infinity());
  for (std::size_t s = 0; s < segments_.size(); ++s)
  {
    const bool ball = segments_[s].first == segments_[s].second;
    const double radii = ball ? kNearRadiiOfBalls
                              : by_faces_[static_cast<std::size_t>(body_[s])] ? kNearRadiiOfEdges : kNearRadiiOfLinks;
    const double skin = (ball ? kSkinRadiiOfBalls : kSkinRadii) * largest_radius_;
    near_radius_.push_back(radii * radius_[s]);
    search_radius_.push_back(near_radius_.back() + 0.5 * skin);
    widest_search_ = std::max(widest_search_, search_radius_.back());
    skin_ = std::max(skin_, skin);
    for (const int node : { segments_[s].first, segments_[s].second })
      least_skin[static_cast<std::size_t>(node)] = std::min(least_skin[static_cast<std::size_t>(node)], skin);
  }
  for (const int node : nodes_)
    hold_limit_.push_back(0.25 * least_skin[static_cast<std::size_t>(node)] * least_skin[static_cast<std::size_t>(node)]);
  findRestNeighbours();
  if (faces_.empty())
    return;
  for (const int node : nodes_)
  {
    node_radius_.push_back(model.contact_radius[node]);
    node_body_.push_back(static_cast<int>(model.bodyOf(node)));
  }
  face_centre_.setZero(3, static_cast<Eigen::Index>(faces_.size()));
  face_extent_.assign(faces_.size(), 0.0);
}

void SelfContacts::remember(const State& state)
{
  if (any_friction_ || !faces_.empty())
    start_ = state.position;
}

bool SelfContacts::candidatesHold(const NodeArray& x)
{
  if (found_at_.cols() != x.cols())
    return false;
  // Two links come closer by at most |d_i - c| + |d_j - c| for their nodes' displacements d_i, d_j since
  // the candidates were found and any common c, since moving everything by c changes no distance. With c
  // the middle of the displacements' bounding box, a body that falls or is carried as a whole keeps its
  // list, and one that lands keeps it longer than with their mean: a cloth whose middle lies on a ball
  // while its sides fall on is nearly all still and the farthest node is as far from the mean as from the
  // still ones, but half as far from the box's middle (ClothOnSphere/self_collision: 155 searches in its
  // first second with the mean, 137 with the box).
  Vec3 low = Vec3::Constant(std::numeric_limits<double>::infinity()), high = -low;
  for (const int node : nodes_)
  {
    const Vec3 displacement = x.col(node) - found_at_.col(node);
    low = low.cwiseMin(displacement);
    high = high.cwiseMax(displacement);
  }
  const Vec3 middle = 0.5 * (low + high);
  for (std::size_t k = 0; k < nodes_.size(); ++k)
  {
    const int node = nodes_[k];
    const double moved2 = (x.col(node) - found_at_.col(node) - middle).squaredNorm();
    if (moved2 > hold_limit_[k])
      return false;
    moved_[static_cast<std::size_t>(node)] = std::sqrt(moved2);
  }
  return true;
}

void SelfContacts::findCandidates(const NodeArray& x)
{
  // A candidate pair's links come within their search radii together (near radii and skins): their balls
  // within the widest such reach.
  const double reach = 2.0 * widest_search_;
  gridSegments(x, reach);
  candidates_.clear();
  grid_.forEachNearPair(reach, [&](std::size_t s, std::size_t t) {
    if (shareANode(s, t))
      return;
    const auto [a, b] = segments_[s];
    const auto [c, d] = segments_[t];
    // Neighbours along one rope touch at their joints; a jelly's springs cross each other at rest (a cell's
    // diagonals) and only its nodes stay out of them; a cloth's (or jelly's) nodes within twice their
    // contact distance at rest (its direct and diagonal neighbours) are held apart by its springs, and come
    // that close only where it is crushed in its plane (Mueller's self-collision, Ten Minute Physics); a
    // face-contact cloth's edges likewise (those two: rest_near_).
    if (nearAtRest(s, t))
      return;
    const double within = search_radius_[s] + search_radius_[t];
    if (a == b && c == d)
    {
      // Two balls: their middles are their centres, so the distance is the bound below and the least
      // distance at once.
      const double distance = (x.col(a) - x.col(c)).norm();
      if (distance < within)
        candidates_.push_back({ static_cast<std::uint32_t>(s), static_cast<std::uint32_t>(t), distance });
      return;
    }
    if (body_[s] == body_[t] && !by_faces_[static_cast<std::size_t>(body_[s])] && a != b && c != d &&
        (springs_collide_[static_cast<std::size_t>(body_[s])] || std::abs(a - c) <= kSkippedLinks))
      return;
    // Their balls within their own reach (the grid's is the widest pair's).
    const double bound = half_[s] + half_[t] + within;
    if ((middle_.col(static_cast<Eigen::Index>(s)) - middle_.col(static_cast<Eigen::Index>(t))).squaredNorm() >
        bound * bound)
      return;
    // By their least distance, which the contact's (contactGap's) never undercuts.
    const double distance = leastDistance(x, segments_[s], segments_[t]);
    if (!(distance < within))
      return;
    candidates_.push_back({ static_cast<std::uint32_t>(s), static_cast<std::uint32_t>(t), distance });
  });
  sortByGroups(candidates_, segments_.size(), [](const Candidate& c) { return c.s; },
               [](const Candidate& c) { return c.t; }, found_, run_start_);
  findFaceCandidates(x);
  found_at_ = x;
  moved_.assign(static_cast<std::size_t>(x.cols()), 0.0);
  ++searches_;
}

void SelfContacts::gridSegments(const NodeArray& y, double reach)
{
  double longest = 0.0;
  for (std::size_t s = 0; s < segments_.size(); ++s)
  {
    const auto [a, b] = segments_[s];
    middle_.col(static_cast<Eigen::Index>(s)) = 0.5 * (y.col(a) + y.col(b));
    half_[s] = 0.5 * (y.col(a) - y.col(b)).norm();
    longest = std::max(longest, 2.0 * half_[s]);
  }
  grid_.build(middle_, half_, longest + reach + 1e-9);
}

bool SelfContacts::nearAtRest(std::size_t s, std::size_t t) const
{
  if (rest_near_start_.empty())
    return false;
  const std::uint32_t* first = rest_near_.data() + rest_near_start_[s];
  const std::uint32_t* last = rest_near_.data() + rest_near_start_[s + 1];
  return std::find(first, last, static_cast<std::uint32_t>(t)) != last;
}

bool SelfContacts::shareANode(std::size_t s, std::size_t t) const
{
  const auto [a, b] = segments_[s];
  const auto [c, d] = segments_[t];
  return a == c || a == d || b == c || b == d;
}

void SelfContacts::findRestNeighbours()
{
  // The pairs this looks at: of one body, two balls or a face-contact cloth's edges.
  const auto kept_apart = [&](std::size_t s, std::size_t t) {
    const bool balls = segments_[s].first == segments_[s].second && segments_[t].first == segments_[t].second;
    return body_[s] == body_[t] && (balls || by_faces_[static_cast<std::size_t>(body_[s])]);
  };
  rest_near_start_.clear();
  rest_near_.clear();
  if (std::none_of(by_faces_.begin(), by_faces_.end(), [](bool b) { return b; }) &&
      std::none_of(segments_.begin(), segments_.end(), [](const auto& segment) { return segment.first == segment.second; }))
    return;
  // At rest, in the arrays each search fills with the current positions.
  const double reach = 4.0 * largest_radius_;
  gridSegments(rest_, reach);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
  grid_.forEachNearPair(reach, [&](std::size_t s, std::size_t t) {
    if (shareANode(s, t) || !kept_apart(s, t))
      return;
    double p, q;
    bool by_ends;
    if (contactGap(rest_, segments_[s], segments_[t], p, q, by_ends).norm() < 2.0 * (radius_[s] + radius_[t]))
      pairs.emplace_back(static_cast<std::uint32_t>(s), static_cast<std::uint32_t>(t));
  });
  std::vector<std::pair<std::uint32_t, std::uint32_t>> scratch;
  sortByGroups(pairs, segments_.size(), [](const auto& pair) { return pair.first; },
               [](const auto& pair) { return pair.second; }, scratch, rest_near_start_);
  for (const auto& pair : pairs)
    rest_near_.push_back(pair.second);
}

void SelfContacts::findFaceCandidates(const NodeArray& x)
{
  face_candidates_.clear();
  if (faces_.empty())
    return;
  // Each face as a ball about its centroid, through its farthest corner; a node within its radius, the
  // face's thickness and the skin of the face lies within that of the ball.
  double widest_face = 0.0, thickest = 0.0;
  for (std::size_t f = 0; f < faces_.size(); ++f)
  {
    const Vec3 centroid = (x.col(faces_[f][0]) + x.col(faces_[f][1]) + x.col(faces_[f][2])) / 3.0;
    face_centre_.col(static_cast<Eigen::Index>(f)) = centroid;
    face_extent_[f] = 0.0;
    for (const int corner : faces_[f])
      face_extent_[f] = std::max(face_extent_[f], (x.col(corner) - centroid).norm());
    widest_face = std::max(widest_face, face_extent_[f]);
    thickest = std::max(thickest, face_radius_[f]);
  }
  const double reach = *std::max_element(node_radius_.begin(), node_radius_.end()) + thickest + skin_;
  face_grid_.build(face_centre_, face_extent_, widest_face + reach + 1e-9);
  for (std::size_t s = 0; s < nodes_.size(); ++s)
    face_grid_.forEachNear(x.col(nodes_[s]), 0.0, reach, [&](std::size_t f) {
      const int node = nodes_[s];
      const std::array<int, 3>& face = faces_[f];
      if (node == face[0] || node == face[1] || node == face[2])
        return;
      const double touch = node_radius_[s] + face_radius_[f];
      const Vec3 p = x.col(node);
      if (!((p - nearestOnTriangle(p, x.col(face[0]), x.col(face[1]), x.col(face[2])).point).norm() < touch + skin_))
        return;
      // A cloth's own node near the face at rest (a corner of the next triangle) is held off by its springs.
      if (node_body_[s] == face_body_[f])
      {
        const Vec3 at_rest = rest_.col(node);
        if ((at_rest - nearestOnTriangle(at_rest, rest_.col(face[0]), rest_.col(face[1]), rest_.col(face[2])).point)
                .norm() < 2.0 * touch)
          return;
      }
      face_candidates_.emplace_back(static_cast<std::uint32_t>(node), static_cast<std::uint32_t>(f));
    });
  sortWithinRuns(face_candidates_, [](const auto& c) { return c.first; }, [](const auto& c) { return c.second; });
}

bool SelfContacts::resolve(const Model& model, State& state)
{
  if (segments_.empty())
    return false;
  NodeArray& x = state.position;
  NodeArray& v = state.velocity;
  if (!candidatesHold(x))
    findCandidates(x);
  const Eigen::VectorXd& w = model.inverse_mass;
  // The contact of segments s and t at positions y: the nearest points' parameters, the unit normal from t's
  // link to s's, the distance and each node's share; false if there is no direction or no free node.
  const auto contact_at = [&](const NodeArray& y, std::size_t s, std::size_t t, Contact& k) {
    const auto [a, b] = segments_[s];
    const auto [c, d] = segments_[t];
    bool by_ends;
    const Vec3 between = contactGap(y, segments_[s], segments_[t], k.p, k.q, by_ends);
    k.distance = between.norm();
    k.least = by_ends ? leastDistance(y, segments_[s], segments_[t]) : k.distance;
    if (!(k.distance > 1e-12))
      return false;  // crossing exactly: no direction to part them in (the next sub-step has one)
    k.n = between / k.distance;
    k.ka = (1.0 - k.p) * w[a];
    k.kb = k.p * w[b];
    k.kc = (1.0 - k.q) * w[c];
    k.kd = k.q * w[d];
    k.weight = (1.0 - k.p) * k.ka + k.p * k.kb + (1.0 - k.q) * k.kc + k.q * k.kd;
    return k.weight > 0.0;
  };
  const auto contact = [&](std::size_t s, std::size_t t, Contact& k) { return contact_at(x, s, t, k); };
  // The pairs that touch, or nearly (within their near radii at this call's start, as the passes move them).
  near_.clear();
  entry_ = x;
  const std::uint64_t entry_tick = tick_;
  moved_at_.resize(static_cast<std::size_t>(x.cols()), 0);
  travel_.resize(static_cast<std::size_t>(x.cols()), 0.0);
  for (const int node : nodes_)
    travel_[static_cast<std::size_t>(node)] = 0.0;
  // The distance the passes have moved the four nodes of segments s and t, summed, since this call began.
  const auto travelled = [&](std::size_t s, std::size_t t) {
    const auto [a, b] = segments_[s];
    const auto [c, d] = segments_[t];
    return travel_[static_cast<std::size_t>(a)] + travel_[static_cast<std::size_t>(b)] +
           travel_[static_cast<std::size_t>(c)] + travel_[static_cast<std::size_t>(d)];
  };
  const auto moved = [&](const std::pair<int, int>& segment) {
    return std::max(moved_[static_cast<std::size_t>(segment.first)], moved_[static_cast<std::size_t>(segment.second)]);
  };
  near_index_.resize(candidates_.size());
  candidate_bound_.resize(candidates_.size());
  live_.clear();
  for (std::size_t i = 0; i < candidates_.size(); ++i)
  {
    const Candidate& candidate = candidates_[i];
    const std::uint32_t s = candidate.s, t = candidate.t;
    const double touching = near_radius_[s] + near_radius_[t];
    near_index_[i] = kFar;
    // Their points have moved, relative to a common motion (which changes no distance), no farther than
    // their farthest node: a pair whose least distance was more than that beyond the contact distance is
    // not near, without its nearest points (most of a flat cloth's candidates, found within the skin, every
    // sub-step until the list is found again).
    const double bound = candidate.distance - moved(segments_[s]) - moved(segments_[t]);
    if (beyond(bound, touching))
      continue;
    // Near if their contact at this call's start is within their near radii; whether it is, is found only
    // once the passes could have brought them into touch (near_pair), from the positions then (entry_).
    near_index_[i] = kUnknown;
    candidate_bound_[i] = bound;
    live_.push_back(static_cast<std::uint32_t>(i));
  }
  // Candidate i's near pair, or none: whether it is near is found the first time it is asked while its links
  // may touch (their least distance at the start, bounded below by candidate_bound_, less what the passes
  // have moved their nodes, within their radii): a pair that cannot touch yet has a pass that changes
  // nothing, near or not. Its contact at the start and the tick then, as if found before the passes: the
  // same contacts, pushes and bits as finding every pair's before them, without the nearest points of the
  // most, which never come near touch in a sub-step (in the demo's coil, 270 of the 313 near pairs each
  // sub-step, and more candidates). The passes take the near pairs in the candidates' order.
  const auto near_pair = [&](std::size_t i) -> NearPair* {
    if (near_index_[i] == kUnknown)
    {
      const std::uint32_t s = candidates_[i].s, t = candidates_[i].t;
      if (beyond(candidate_bound_[i] - travelled(s, t), radius_[s] + radius_[t]))
        return nullptr;
      NearPair pair{ s, t, 0.0, 0.0 };
      pair.valid = contact_at(entry_, s, t, pair.contact);
      pair.seen = entry_tick;
      pair.travel = 0.0;
      if (!(pair.contact.distance < near_radius_[s] + near_radius_[t]))
      {
        near_index_[i] = kFar;
        return nullptr;
      }
      near_index_[i] = static_cast<std::int32_t>(near_.size());
      near_.push_back(pair);
    }
    return near_index_[i] >= 0 ? &near_[static_cast<std::size_t>(near_index_[i])] : nullptr;
  };
  bool touched = false;
  // A pair's contact as the passes left its nodes: the one it last had unless one of its nodes has moved
  // since (most pairs of a cloth lying in folds touch none that moves: their nearest points are not
  // looked for again, pass after pass; the same contacts and bits).
  const auto current = [&](NearPair& pair) -> const Contact* {
    const auto [a, b] = segments_[pair.s];
    const auto [c, d] = segments_[pair.t];
    const std::uint64_t last_move =
        std::max({ moved_at_[static_cast<std::size_t>(a)], moved_at_[static_cast<std::size_t>(b)],
                   moved_at_[static_cast<std::size_t>(c)], moved_at_[static_cast<std::size_t>(d)] });
    if (last_move > pair.seen)
    {
      pair.valid = contact(pair.s, pair.t, pair.contact);
      pair.seen = tick_;
      pair.travel = travelled(pair.s, pair.t);
    }
    return pair.valid ? &pair.contact : nullptr;
  };
  // Changes y (positions or velocities) of the four nodes so that the difference between the two nearest
  // points changes by `change`, each node by its share of the inverse mass there.
  const auto part = [&](std::size_t s, std::size_t t, const Contact& k, NodeArray& y, const Vec3& change) {
    const Vec3 unit = change / k.weight;
    const auto [a, b] = segments_[s];
    const auto [c, d] = segments_[t];
    y.col(a) += k.ka * unit;
    y.col(b) += k.kb * unit;
    y.col(c) -= k.kc * unit;
    y.col(d) -= k.kd * unit;
    if (&y == &x)
    {
      ++tick_;
      for (const int node : { a, b, c, d })
        moved_at_[static_cast<std::size_t>(node)] = tick_;
      const double length = unit.norm();
      travel_[static_cast<std::size_t>(a)] += k.ka * length;
      travel_[static_cast<std::size_t>(b)] += k.kb * length;
      travel_[static_cast<std::size_t>(c)] += k.kc * length;
      travel_[static_cast<std::size_t>(d)] += k.kd * length;
    }
  };
  // The difference of y (positions or velocities) between the two nearest points.
  const auto between = [&](std::size_t s, std::size_t t, const Contact& k, const NodeArray& y) {
    const auto [a, b] = segments_[s];
    const auto [c, d] = segments_[t];
    return Vec3((1.0 - k.p) * y.col(a) + k.p * y.col(b) - (1.0 - k.q) * y.col(c) - k.q * y.col(d));
  };
  // Projected Gauss-Seidel on each pair's accumulated push and speed change (Catto's accumulated
  // impulses): a pass may take back part of what an earlier one gave, never more. A push at a point
  // inside a link moves its nearer node by more than the depth there; without taking back, a neighbouring
  // pair's push on that node would leave it thrown off the surface (and in a groove, off with no friction
  // holding it).
  // A pair that has not pushed (push and stop 0) and whose links were apart by more than their radii
  // together by more than its nodes have since been moved, stays apart: every point of a link moves no
  // farther than its farthest node, so their least distance (which the contact's never undercuts) has shrunk
  // by at most what the four moved. Its pass would push by nothing and stop nothing, so it is passed over,
  // its nearest points not looked for (most near pairs of a pile: 270 of the 313 of the demo's coil, each
  // looked for again in every pass once a neighbour moved); the same bits.
  const auto stays_apart = [&](const NearPair& pair) {
    return pair.push == 0.0 && pair.stop == 0.0 && pair.valid &&
           beyond(pair.contact.least - (travelled(pair.s, pair.t) - pair.travel), radius_[pair.s] + radius_[pair.t]);
  };
  // The passes take the candidates that may be near (live_, in the candidates' order): the others' passes
  // change nothing (most of a folding cloth's: of 33,000 candidates a search, about 3,600 not found far at
  // a sub-step's start and 500 near).
  for (int pass = 0; pass < kPasses; ++pass)
    for (const std::uint32_t i : live_)
    {
      NearPair* near = near_pair(i);
      if (near == nullptr || stays_apart(*near))
        continue;
      NearPair& pair = *near;
      const Contact* found = current(pair);
      if (found == nullptr)
        continue;
      const Contact k = *found;
      const double push = std::max(-pair.push, radius_[pair.s] + radius_[pair.t] - k.distance);
      // Only links that touch stop approaching; others give back what they took.
      const double stop = pair.push + push > 0.0 ? std::max(-pair.stop, -between(pair.s, pair.t, k, v).dot(k.n))
                                                 : -pair.stop;
      if (push != 0.0)
        part(pair.s, pair.t, k, x, push * k.n);
      if (stop != 0.0)
        part(pair.s, pair.t, k, v, stop * k.n);
      pair.push += push;
      pair.stop += stop;
      touched = touched || pair.push > 0.0;
    }
  if (!any_friction_ || !touched)
    return resolveFaces(model, state) || touched;
  // Coulomb friction as on a collider (contact_response.h), relative to the other link, once the links
  // are apart: the sub-step's tangential slip of the nearest points cancelled up to friction * the push
  // apart, their tangential speed reduced by up to friction * the approach speed removed. After the
  // normal passes, not in them: in a groove, a link's motion into the other side is tangential at the
  // first side's contact, and friction there would spend its budget against what the other side stops.
  for (int pass = 0; pass < kPasses; ++pass)
    for (const std::uint32_t i : live_)
    {
      if (near_index_[i] < 0)
        continue;
      NearPair& pair = near_[static_cast<std::size_t>(near_index_[i])];
      const double friction = 0.5 * (friction_[pair.s] + friction_[pair.t]);
      if (!(friction > 0.0) || !(pair.push > 0.0 || pair.stop > 0.0))
        continue;
      const Contact* found = current(pair);
      if (found == nullptr)
        continue;
      const Contact k = *found;
      // Cancels the tangential part of `relative` (a motion of y at the contact) up to friction * budget.
      const auto resist = [&](const Vec3& relative, double& budget, NodeArray& y) {
        if (const std::optional<Vec3> change = frictionChange(relative, k.n, friction, budget))
          part(pair.s, pair.t, k, y, *change);
      };
      resist(between(pair.s, pair.t, k, x) - between(pair.s, pair.t, k, start_), pair.push, x);
      resist(between(pair.s, pair.t, k, v), pair.stop, v);
    }
  return resolveFaces(model, state) || touched;
}

double SelfContacts::startSide(const NodeArray& now, int node, std::size_t face) const
{
  const std::array<int, 3>& f = faces_[face];
  const auto side = [&](const NodeArray& y) {
    return (y.col(f[1]) - y.col(f[0])).cross(y.col(f[2]) - y.col(f[0])).dot(y.col(node) - y.col(f[0]));
  };
  const double then = side(start_);
  return std::copysign(1.0, then != 0.0 ? then : side(now));
}

bool SelfContacts::overFace(const NodeArray& x, int node, std::size_t face, double side, OverFace& over) const
{
  const std::array<int, 3>& f = faces_[face];
  const TriangleCorners t{ x.col(f[0]), x.col(f[1]), x.col(f[2]) };
  const Vec3 n = (t[1] - t[0]).cross(t[2] - t[0]);
  const double twice_area = n.norm();
  if (!(twice_area > 0.0))
    return false;  // a collapsed face: its edges are its neighbours'
  over.weight = barycentric(x.col(node), t, n);
  if (!(over.weight.minCoeff() >= 0.0))
    return false;  // beside it: its edges' and corners' contacts
  over.normal = side / twice_area * n;
  over.height = over.normal.dot(x.col(node) - t[0]);
  return true;
}

bool SelfContacts::resolveFaces(const Model& model, State& state)
{
  if (faces_.empty())
    return false;
  NodeArray& x = state.position;
  NodeArray& v = state.velocity;
  const Eigen::VectorXd& w = model.inverse_mass;
  near_faces_.clear();
  OverFace over;
  for (const auto& [node, face] : face_candidates_)
  {
    const double side = startSide(x, static_cast<int>(node), face);
    if (overFace(x, static_cast<int>(node), face, side, over) &&
        over.height < model.contact_radius[static_cast<Eigen::Index>(node)] + face_radius_[face])
      near_faces_.push_back({ static_cast<int>(node), face, side, 0.0, 0.0 });
  }
  // The node's and the corners' shares (as in resolve: each by its inverse mass and weight at the point),
  // and a change of the gap between the node and the face's point applied to y.
  const auto part = [&](const NearFace& pair, const OverFace& o, NodeArray& y, const Vec3& change) {
    const std::array<int, 3>& f = faces_[pair.face];
    double total = w[pair.node];
    for (int k = 0; k < 3; ++k)
      total += o.weight[k] * o.weight[k] * w[f[k]];
    if (!(total > 0.0))
      return;
    const Vec3 unit = change / total;
    y.col(pair.node) += w[pair.node] * unit;
    for (int k = 0; k < 3; ++k)
      y.col(f[k]) -= o.weight[k] * w[f[k]] * unit;
  };
  const auto gap = [&](const NearFace& pair, const OverFace& o, const NodeArray& y) {
    const std::array<int, 3>& f = faces_[pair.face];
    return Vec3(y.col(pair.node) - o.weight[0] * y.col(f[0]) - o.weight[1] * y.col(f[1]) - o.weight[2] * y.col(f[2]));
  };
  bool touched = false;
  for (int pass = 0; pass < kPasses; ++pass)
    for (NearFace& pair : near_faces_)
    {
      if (!overFace(x, pair.node, pair.face, pair.side, over))
        continue;
      const double reach = model.contact_radius[pair.node] + face_radius_[pair.face];
      // No further back than the node and the face moved apart along the normal in the sub-step: a node
      // behind the face by more than that was behind it at the start too.
      const double moved = std::abs(over.normal.dot(gap(pair, over, x) - gap(pair, over, start_)));
      const double push = std::max(-pair.push, std::min(reach - over.height, reach + moved));
      const double stop =
          pair.push + push > 0.0 ? std::max(-pair.stop, -gap(pair, over, v).dot(over.normal)) : -pair.stop;
      if (push != 0.0)
        part(pair, over, x, push * over.normal);
      if (stop != 0.0)
        part(pair, over, v, stop * over.normal);
      pair.push += push;
      pair.stop += stop;
      touched = touched || pair.push > 0.0;
    }
  if (!any_friction_ || !touched)
    return touched;
  // Coulomb friction as between links (resolve), with the mean of the two bodies' self_friction.
  for (int pass = 0; pass < kPasses; ++pass)
    for (NearFace& pair : near_faces_)
    {
      const double friction =
          0.5 * (model.bodies[model.bodyOf(pair.node)].self_friction + face_friction_[pair.face]);
      if (!(friction > 0.0) || !(pair.push > 0.0 || pair.stop > 0.0) ||
          !overFace(x, pair.node, pair.face, pair.side, over))
        continue;
      const auto resist = [&](const Vec3& relative, double& budget, NodeArray& y) {
        if (const std::optional<Vec3> change = frictionChange(relative, over.normal, friction, budget))
          part(pair, over, y, *change);
      };
      resist(gap(pair, over, x) - gap(pair, over, start_), pair.push, x);
      resist(gap(pair, over, v), pair.stop, v);
    }
  return touched;
}

}  // namespace soft_body_sim
