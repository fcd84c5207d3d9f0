#include "soft_body_sim/core/self_contacts.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace soft_body_sim
{
namespace
{
/// The parameters s, t in [0, 1] of the nearest points of segments p0 + s d1 and q0 + t d2 (Ericson,
/// Real-Time Collision Detection, 5.1.9).
std::pair<double, double> nearestParameters(const Vec3& p0, const Vec3& d1, const Vec3& q0, const Vec3& d2)
{
  const Vec3 r = p0 - q0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  if (!(a > 0.0) && !(e > 0.0))
    return { 0.0, 0.0 };
  if (!(a > 0.0))
    return { 0.0, std::clamp(f / e, 0.0, 1.0) };
  const double c = d1.dot(r);
  if (!(e > 0.0))
    return { std::clamp(-c / a, 0.0, 1.0), 0.0 };
  const double b = d1.dot(d2), denominator = a * e - b * b;
  double s = denominator > 0.0 ? std::clamp((b * f - c * e) / denominator, 0.0, 1.0) : 0.0;
  double t = (b * s + f) / e;
  if (t < 0.0)
  {
    t = 0.0;
    s = std::clamp(-c / a, 0.0, 1.0);
  }
  else if (t > 1.0)
  {
    t = 1.0;
    s = std::clamp((b - c) / a, 0.0, 1.0);
  }
  return { s, t };
}

/// A cell coordinate, kept far from the integer limits (a node at 1e300 m is a diverged one the guard
/// deals with; here it only has to stay a valid index).
std::int32_t cellCoordinate(double position, double cell)
{
  return static_cast<std::int32_t>(std::clamp(std::floor(position / cell), -1e9, 1e9));
}
}  // namespace

std::int64_t SegmentGrid::slot(std::int64_t i, std::int64_t j, std::int64_t k) const
{
  const std::uint64_t hash = (static_cast<std::uint64_t>(i) * 73856093u) ^ (static_cast<std::uint64_t>(j) * 19349663u) ^
                             (static_cast<std::uint64_t>(k) * 83492791u);
  return static_cast<std::int64_t>(hash & (start_.size() - 2));  // the slot count is a power of two
}

void SegmentGrid::build(const NodeArray& x, const std::vector<std::pair<int, int>>& segments, double cell)
{
  const std::size_t count = segments.size();
  std::size_t slots = 1;  // a power of two, at least twice the segments: a mask, not a division, per lookup
  while (slots < 2 * count)
    slots *= 2;
  coordinate_.resize(3 * count);
  slot_of_.resize(count);
  sorted_.resize(count);
  start_.assign(slots + 1, 0);
  for (std::size_t s = 0; s < count; ++s)
  {
    const Vec3 middle = 0.5 * (x.col(segments[s].first) + x.col(segments[s].second));
    for (int axis = 0; axis < 3; ++axis)
      coordinate_[3 * s + static_cast<std::size_t>(axis)] = cellCoordinate(middle[axis], cell);
    const std::int32_t* c = &coordinate_[3 * s];
    slot_of_[s] = static_cast<std::uint32_t>(slot(c[0], c[1], c[2]));
    ++start_[slot_of_[s] + 1];
  }
  for (std::size_t q = 0; q < slots; ++q)
    start_[q + 1] += start_[q];
  cursor_.assign(start_.begin(), start_.end() - 1);
  for (std::size_t s = 0; s < count; ++s)
    sorted_[cursor_[slot_of_[s]]++] = static_cast<std::uint32_t>(s);
}

SelfContacts::SelfContacts(const Model& model)
{
  if (model.contact_radius.size() != model.nodeCount())
    return;  // a model made without radii (World gives it zeros): points, which do not collide
  for (const auto& [a, b] : model.contact_segments)
  {
    const std::size_t body = model.bodyOf(a);
    const double radius = 0.5 * (model.contact_radius[a] + model.contact_radius[b]);
    if (!model.bodies[body].self_collision || !(radius > 0.0))
      continue;
    segments_.emplace_back(a, b);
    body_.push_back(static_cast<int>(body));
    radius_.push_back(radius);
    largest_radius_ = std::max(largest_radius_, radius);
  }
  middle_.setZero(3, static_cast<Eigen::Index>(segments_.size()));
  half_.assign(segments_.size(), 0.0);
}

bool SelfContacts::resolve(const Model& model, State& state)
{
  if (segments_.empty())
    return false;
  NodeArray& x = state.position;
  NodeArray& v = state.velocity;
  double longest = 0.0;
  for (std::size_t s = 0; s < segments_.size(); ++s)
  {
    const auto [a, b] = segments_[s];
    middle_.col(static_cast<Eigen::Index>(s)) = 0.5 * (x.col(a) + x.col(b));
    half_[s] = 0.5 * (x.col(a) - x.col(b)).norm();
    longest = std::max(longest, 2.0 * half_[s]);
  }
  // The pairs that touch, or nearly (within their radii again, as the passes move them): cells wide
  // enough for the longest link and twice the largest radii.
  const double reach = 2.0 * largest_radius_;
  grid_.build(x, segments_, longest + 2.0 * reach + 1e-9);
  near_.clear();
  grid_.forEachNearPair([&](std::size_t s, std::size_t t) {
    const auto [a, b] = segments_[s];
    const auto [c, d] = segments_[t];
    if (a == c || a == d || b == c || b == d || (body_[s] == body_[t] && std::abs(a - c) <= kSkippedLinks))
      return;
    // Bounding balls first: most pairs in neighbouring cells are farther apart than that.
    const double bound = half_[s] + half_[t] + 2.0 * (radius_[s] + radius_[t]);
    if ((middle_.col(static_cast<Eigen::Index>(s)) - middle_.col(static_cast<Eigen::Index>(t))).squaredNorm() >
        bound * bound)
      return;
    const Vec3 xa = x.col(a), xc = x.col(c);
    const auto [p, q] = nearestParameters(xa, x.col(b) - xa, xc, x.col(d) - xc);
    const double gap = ((xa + p * (x.col(b) - xa)) - (xc + q * (x.col(d) - xc))).norm();
    if (gap < 2.0 * (radius_[s] + radius_[t]))
      near_.emplace_back(static_cast<std::uint32_t>(s), static_cast<std::uint32_t>(t));
  });
  bool touched = false;
  const Eigen::VectorXd& w = model.inverse_mass;
  for (int pass = 0; pass < kPasses; ++pass)
    for (const auto& [s, t] : near_)
    {
      const auto [a, b] = segments_[s];
      const auto [c, d] = segments_[t];
      const Vec3 xa = x.col(a), xb = x.col(b), xc = x.col(c), xd = x.col(d);
      const auto [p, q] = nearestParameters(xa, xb - xa, xc, xd - xc);
      const Vec3 between = (xa + p * (xb - xa)) - (xc + q * (xd - xc));
      const double distance = between.norm();
      const double depth = radius_[s] + radius_[t] - distance;
      if (!(depth > 0.0) || !(distance > 1e-12))
        continue;  // apart, or crossing exactly (no direction to part them in: the next sub-step has one)
      const Vec3 n = between / distance;
      const double ka = (1.0 - p) * w[a], kb = p * w[b], kc = (1.0 - q) * w[c], kd = q * w[d];
      const double weight = (1.0 - p) * ka + p * kb + (1.0 - q) * kc + q * kd;
      if (!(weight > 0.0))
        continue;
      const double push = depth / weight;
      x.col(a) += ka * push * n;
      x.col(b) += kb * push * n;
      x.col(c) -= kc * push * n;
      x.col(d) -= kd * push * n;
      const double approach = ((1.0 - p) * v.col(a) + p * v.col(b) - (1.0 - q) * v.col(c) - q * v.col(d)).dot(n);
      if (approach < 0.0)
      {
        const double stop = -approach / weight;
        v.col(a) += ka * stop * n;
        v.col(b) += kb * stop * n;
        v.col(c) -= kc * stop * n;
        v.col(d) -= kd * stop * n;
      }
      touched = true;
    }
  return touched;
}

}  // namespace soft_body_sim
