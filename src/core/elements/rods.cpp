#include "soft_body_sim/core/elements/rods.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace soft_body_sim
{
namespace
{
/// The least denominator l0 l1 + e0 . e1 of a curvature binormal, as a fraction of l0 l1 (see curvatureBinormal).
constexpr double kMinFold = 1e-3;

Eigen::Matrix3d cross(const Vec3& a)
{
  Eigen::Matrix3d m;
  m << 0.0, -a.z(), a.y(), a.z(), 0.0, -a.x(), -a.y(), a.x(), 0.0;
  return m;
}

/// The vector d carried from unit tangent a to unit tangent b by the rotation about a x b that takes a
/// to b (parallel transport across one bend); d itself where b reverses a (the rotation is undefined).
Vec3 transport(const Vec3& d, const Vec3& a, const Vec3& b)
{
  const double c = a.dot(b);
  if (1.0 + c < 1e-12)
    return d;
  const Vec3 k = a.cross(b);
  return c * d + k.cross(d) + (k.dot(d) / (1.0 + c)) * k;
}

/// The unit tangent of the segment from global node i to i + 1; one of zero length takes the rest axis.
Vec3 segmentTangent(const Rod& rod, const NodeArray& x, int i)
{
  const Vec3 e = x.col(i + 1) - x.col(i);
  const double length = e.norm();
  return length > 0.0 ? Vec3(e / length) : Vec3(rod.rest_frame * Vec3::UnitX());
}

/// The tangents of a run of the rod at x: a held axis, the unit tangents of the segments from node `from`
/// to node `to` (global), another held axis; computed where needed, so that a step allocates nothing.
struct Run
{
  const Rod& rod;
  const NodeArray& x;
  int from;
  int to;
  Vec3 enter;  ///< the held axis before the first segment
  Vec3 leave;  ///< the held axis after the last one

  int segments() const { return to - from; }
  int size() const { return segments() + 2; }
  /// Tangent k: 0 the entering axis, 1 .. segments() the segments', then the leaving axis.
  Vec3 operator[](int k) const
  {
    if (k == 0)
      return enter;
    if (k == size() - 1)
      return leave;
    return segmentTangent(rod, x, from + k - 1);
  }
};

/// The run of the interval after station s: from its leaving axis to station s + 1's entering axis.
Run intervalRun(const Rod& rod, int s, const NodeArray& x)
{
  const RodStation& a = rod.stations[static_cast<std::size_t>(s)];
  const RodStation& b = rod.stations[static_cast<std::size_t>(s) + 1];
  return Run{ rod, x, a.last, b.first, stationAxis(rod, s, 1), stationAxis(rod, s + 1, 0) };
}

/// The run through station s itself: from its entering to its leaving axis.
Run stationRun(const Rod& rod, int s, const NodeArray& x)
{
  const RodStation& station = rod.stations[static_cast<std::size_t>(s)];
  return Run{ rod, x, station.first, station.last, stationAxis(rod, s, 0), stationAxis(rod, s, 1) };
}

/// The angle [rad] about the run's leaving axis from `y_from` (across its entering axis) carried along the
/// run by parallel transport to `y_to`; of the values 2 pi apart, the one nearest `near`.
double carriedAngle(const Run& run, const Vec3& y_from, const Vec3& y_to, double near)
{
  Vec3 d = y_from;
  for (int k = 1; k < run.size(); ++k)
    d = transport(d, run[k - 1], run[k]);
  const double angle = std::atan2(run.leave.dot(d.cross(y_to)), d.dot(y_to));
  return near + std::remainder(angle - near, 2.0 * M_PI);
}

/// The twist [rad] inside station s, between its entering and its leaving frame (0 for one node).
double innerTwist(const Rod& rod, int s, const NodeArray& x)
{
  const RodStation& station = rod.stations[static_cast<std::size_t>(s)];
  if (station.first == station.last)
    return 0.0;
  return carriedAngle(stationRun(rod, s, x), station.frame[0] * Vec3::UnitY(), station.frame[1] * Vec3::UnitY(), 0.0);
}

/// True if node i is a station of one node.
bool oneNodeStation(const Rod& rod, int i)
{
  for (const RodStation& station : rod.stations)
    if (station.first == i && station.last == i)
      return true;
  return false;
}

/// The frame with x axis t and y axis y (unit, orthogonal).
Eigen::Quaterniond frameOf(const Vec3& t, const Vec3& y)
{
  Eigen::Matrix3d axes;
  axes << t, y, t.cross(y);
  return Eigen::Quaterniond(axes);
}

/// The unit vector across tangent t nearest to `y` (any one across t if y is along it).
Vec3 across(const Vec3& t, const Vec3& y)
{
  Vec3 d = y - y.dot(t) * t;
  if (d.norm() < 1e-9)
    d = t.unitOrthogonal();
  return d.normalized();
}

/// The unit curvature binormal of two unit tangents, 2 a x b / (1 + a . b), its denominator held as in
/// curvatureBinormal.
Vec3 unitBinormal(const Vec3& a, const Vec3& b) { return 2.0 * a.cross(b) / std::max(1.0 + a.dot(b), kMinFold); }

/// Adds scale * d(twist)/dx of the interval after station s to out.col(node - column0) of its nodes
/// (intervalTwistGradient).
void addTwistGradient(const Rod& rod, int s, const NodeArray& x, double scale, NodeArray& out, int column0)
{
  const Run run = intervalRun(rod, s, x);
  for (int k = 1; k <= run.segments(); ++k)
  {
    const int i = run.from + k - 1;  // the segment's first node
    const double length = (x.col(i + 1) - x.col(i)).norm();
    if (length <= 0.0)
      continue;
    const Vec3 g = (scale / (2.0 * length)) * (unitBinormal(run[k - 1], run[k]) + unitBinormal(run[k], run[k + 1]));
    out.col(i + 1 - column0) += g;
    out.col(i - column0) -= g;
  }
}

/// Appends to `frames` the material frames of the run's segments: `from`'s y axis carried along the run,
/// each segment's turned about it by `twist` times its midpoint's share of the run.
void carryFrames(const Run& run, const Eigen::Quaterniond& from, double twist, std::vector<Eigen::Quaterniond>& frames)
{
  Vec3 d = from * Vec3::UnitY();
  for (int k = 1; k <= run.segments(); ++k)
  {
    const Vec3 t = run[k];
    d = transport(d, run[k - 1], t);
    const Vec3 y = Eigen::AngleAxisd(twist * (k - 0.5) / run.segments(), t) * across(t, d);
    frames.push_back(frameOf(t, y));
  }
}

/// Fills frames[j] for the segments from global node `from` back to `to` (to < from) with a frame carried
/// untwisted from `start` (along the segment after them) toward the rod's first end.
void carryBackward(const Rod& rod, const NodeArray& x, int from, int to, const Eigen::Quaterniond& start,
                   std::vector<Eigen::Quaterniond>& frames)
{
  Vec3 before = start * Vec3::UnitX();
  Vec3 d = start * Vec3::UnitY();
  for (int i = from - 1; i >= to; --i)
  {
    const Vec3 t = segmentTangent(rod, x, i);
    d = transport(d, before, t);
    frames[static_cast<std::size_t>(i - rod.first)] = frameOf(t, across(t, d));
    before = t;
  }
}
}  // namespace

StationIndex findRodStation(const Model& model, int node)
{
  for (std::size_t r = 0; r < model.rods.size(); ++r)
  {
    const std::vector<RodStation>& stations = model.rods[r].stations;
    for (std::size_t s = 0; s < stations.size(); ++s)
      if (node >= stations[s].first && node <= stations[s].last)
        return StationIndex{ static_cast<int>(r), static_cast<int>(s) };
  }
  return StationIndex{};
}

CurvatureBinormal curvatureBinormal(const Vec3& e0, const Vec3& e1, double rest_product)
{
  // kb grows like tan(phi / 2) without bound as the bend folds back on itself (phi -> pi, D -> 0) and
  // turns over past it: a step that folds a segment back (an anchor jerked past its neighbour) would
  // divide by zero. D is kept at kMinFold of its straight value (a fold of 177 degrees), so the bend
  // pushes back with a large, finite force.
  const double denominator = std::max(rest_product + e0.dot(e1), kMinFold * rest_product);
  CurvatureBinormal bend;
  bend.kb = (2.0 / denominator) * e0.cross(e1);
  bend.d_e0 = -(2.0 * cross(e1) + bend.kb * e1.transpose()) / denominator;
  bend.d_e1 = (2.0 * cross(e0) - bend.kb * e0.transpose()) / denominator;
  return bend;
}

void appendRodVertices(const Rod& rod, std::vector<RodVertex>& vertices)
{
  const double inner = rod.bending_stiffness / (2.0 * rod.segment_length);
  for (int i = rod.first + 1; i < rod.last(); ++i)
    if (!oneNodeStation(rod, i))
      vertices.push_back({ i - 1, i, i + 1, -1, inner });
  const double half = rod.bending_stiffness / rod.segment_length;  // E I / (2 D), D = l / 2
  for (std::size_t s = 0; s < rod.stations.size(); ++s)
  {
    const int i = rod.stations[s].first;
    if (i != rod.stations[s].last)
      continue;
    if (i > rod.first)
      vertices.push_back({ i - 1, i, -1, static_cast<int>(s), half });
    if (i < rod.last())
      vertices.push_back({ -1, i, i + 1, static_cast<int>(s), half });
  }
}

void vertexEdges(const Rod& rod, const RodVertex& vertex, const NodeArray& x, Vec3& e0, Vec3& e1)
{
  const double l = rod.segment_length;
  e0 = vertex.before < 0 ? Vec3(l * stationAxis(rod, vertex.station, 0)) : Vec3(x.col(vertex.at) - x.col(vertex.before));
  e1 = vertex.after < 0 ? Vec3(l * stationAxis(rod, vertex.station, 1)) : Vec3(x.col(vertex.after) - x.col(vertex.at));
}

double intervalLength(const Rod& rod, int s)
{
  return rod.segment_length * (rod.stations[static_cast<std::size_t>(s) + 1].first - rod.stations[static_cast<std::size_t>(s)].last);
}

double intervalTwist(const Rod& rod, int s, const NodeArray& x, double near)
{
  return carriedAngle(intervalRun(rod, s, x), rod.stations[static_cast<std::size_t>(s)].frame[1] * Vec3::UnitY(),
                      rod.stations[static_cast<std::size_t>(s) + 1].frame[0] * Vec3::UnitY(), near);
}

void updateRodTwists(const Rod& rod, const NodeArray& x, Eigen::VectorXd& twist)
{
  for (int s = 0; s + 1 < static_cast<int>(rod.stations.size()); ++s)
    twist[twistSlot(rod, s)] = intervalTwist(rod, s, x, twist[twistSlot(rod, s)]);
}

void intervalTwistGradient(const Rod& rod, int s, const NodeArray& x, NodeArray& gradient)
{
  gradient.setZero(3, rod.count);
  addTwistGradient(rod, s, x, 1.0, gradient, rod.first);
}

void accumulateTwistForces(const Rod& rod, const NodeArray& x, const Eigen::VectorXd& twist, NodeArray& force)
{
  for (int s = 0; s + 1 < static_cast<int>(rod.stations.size()); ++s)
  {
    const double moment = rod.twisting_stiffness * intervalTwist(rod, s, x, twist[twistSlot(rod, s)]) / intervalLength(rod, s);
    addTwistGradient(rod, s, x, -moment, force, 0);
  }
}

double rodEnergy(const Rod& rod, const NodeArray& x, const Eigen::VectorXd& twist)
{
  std::vector<RodVertex> vertices;
  appendRodVertices(rod, vertices);
  double energy = 0.0;
  for (const RodVertex& vertex : vertices)
  {
    Vec3 e0, e1;
    vertexEdges(rod, vertex, x, e0, e1);
    energy += vertex.weight * curvatureBinormal(e0, e1, rod.segment_length * rod.segment_length).kb.squaredNorm();
  }
  for (int s = 0; s + 1 < static_cast<int>(rod.stations.size()); ++s)
  {
    const double tau = twist[twistSlot(rod, s)];
    energy += 0.5 * rod.twisting_stiffness * tau * tau / intervalLength(rod, s);
  }
  return energy;
}

void accumulateRodForces(const Rod& rod, const NodeArray& x, const Eigen::VectorXd& twist, NodeArray& force)
{
  std::vector<RodVertex> vertices;
  appendRodVertices(rod, vertices);
  for (const RodVertex& vertex : vertices)
  {
    Vec3 e0, e1;
    vertexEdges(rod, vertex, x, e0, e1);
    const CurvatureBinormal bend = curvatureBinormal(e0, e1, rod.segment_length * rod.segment_length);
    const Vec3 g0 = 2.0 * vertex.weight * bend.d_e0.transpose() * bend.kb;  // dE/de0
    const Vec3 g1 = 2.0 * vertex.weight * bend.d_e1.transpose() * bend.kb;  // dE/de1
    if (vertex.before >= 0)
    {
      force.col(vertex.before) += g0;
      force.col(vertex.at) -= g0;
    }
    if (vertex.after >= 0)
    {
      force.col(vertex.at) += g1;
      force.col(vertex.after) -= g1;
    }
  }
  accumulateTwistForces(rod, x, twist, force);
}

void accumulateRodEndMoment(const Rod& rod, const NodeArray& x, NodeArray& force)
{
  if (rod.end_moment.isZero(0.0))
    return;
  const Vec3 e = x.col(rod.last()) - x.col(rod.last() - 1);
  const double length2 = e.squaredNorm();
  if (length2 <= 0.0)
    return;
  const Vec3 couple = rod.end_moment.cross(e) / length2;
  force.col(rod.last()) += couple;
  force.col(rod.last() - 1) -= couple;
}

void rodFrames(const Rod& rod, const NodeArray& x, const Eigen::VectorXd& twist, std::vector<Eigen::Quaterniond>& frames)
{
  frames.clear();
  const int stations = static_cast<int>(rod.stations.size());
  if (stations == 0)
  {
    // No station: the rest frame turned onto the first segment, carried untwisted to the last.
    const Vec3 t = segmentTangent(rod, x, rod.first);
    const Eigen::Quaterniond start = frameOf(t, across(t, rod.rest_frame * Vec3::UnitY()));
    frames.push_back(start);
    carryFrames(Run{ rod, x, rod.first + 1, rod.last(), t, t }, start, 0.0, frames);
    return;
  }
  // Before the first station (a free first end), filled last, backward from it.
  const RodStation& front = rod.stations.front();
  frames.resize(static_cast<std::size_t>(front.first - rod.first));
  for (int s = 0; s < stations; ++s)
  {
    const RodStation& station = rod.stations[static_cast<std::size_t>(s)];
    carryFrames(stationRun(rod, s, x), station.frame[0], innerTwist(rod, s, x), frames);
    if (s + 1 < stations)
      carryFrames(intervalRun(rod, s, x), station.frame[1], twist[twistSlot(rod, s)], frames);
  }
  // After the last station (a free last end): carried untwisted from it.
  const RodStation& back = rod.stations.back();
  carryFrames(Run{ rod, x, back.last, rod.last(), back.frame[1] * Vec3::UnitX(), back.frame[1] * Vec3::UnitX() },
              back.frame[1], 0.0, frames);
  carryBackward(rod, x, front.first, rod.first, front.frame[0], frames);
}

Vec3 stationTorque(const Rod& rod, int s, const NodeArray& x, const Eigen::VectorXd& twist)
{
  const RodStation& station = rod.stations[static_cast<std::size_t>(s)];
  Vec3 torque = Vec3::Zero();
  if (station.first == station.last)
  {
    // Its bending moment: turning the held axis a by a small angle w moves a ghost edge by l (w x a) and
    // the energy by g . l (w x a) = w . l (a x g); the rod pushes back with l (g x a).
    std::vector<RodVertex> vertices;
    appendRodVertices(rod, vertices);
    for (const RodVertex& vertex : vertices)
    {
      if (vertex.station != s)
        continue;
      Vec3 e0, e1;
      vertexEdges(rod, vertex, x, e0, e1);
      const CurvatureBinormal bend = curvatureBinormal(e0, e1, rod.segment_length * rod.segment_length);
      const bool ghost_before = vertex.before < 0;
      const Vec3 g = 2.0 * vertex.weight * (ghost_before ? bend.d_e0 : bend.d_e1).transpose() * bend.kb;
      torque += rod.segment_length * g.cross(stationAxis(rod, s, ghost_before ? 0 : 1));
    }
  }
  if (s > 0)
    torque -= rod.twisting_stiffness * twist[twistSlot(rod, s - 1)] / intervalLength(rod, s - 1) * stationAxis(rod, s, 0);
  if (s + 1 < static_cast<int>(rod.stations.size()))
    torque += rod.twisting_stiffness * twist[twistSlot(rod, s)] / intervalLength(rod, s) * stationAxis(rod, s, 1);
  return torque;
}

void clampRod(Rod& rod, int node)
{
  auto at = rod.stations.begin();
  while (at != rod.stations.end() && at->first < node)
    ++at;
  if (at != rod.stations.end() && at->first == node)
    return;
  RodStation station;
  station.first = station.last = node;
  station.frame[0] = station.frame[1] = station.held[0] = station.held[1] = rod.rest_frame;
  rod.stations.insert(at, station);
}

int holdRod(Rod& rod, const NodeArray& x, Eigen::VectorXd& twist, int first, int last, const Eigen::Quaterniond& holder)
{
  for (const RodStation& station : rod.stations)
    if (first <= station.last && last >= station.first)
      throw std::invalid_argument("nodes " + std::to_string(first) + " .. " + std::to_string(last) +
                                  " of the rod are held already");
  std::vector<Eigen::Quaterniond> frames;
  rodFrames(rod, x, twist, frames);
  RodStation station;
  station.first = first;
  station.last = last;
  const auto segment = [&](int i) { return frames[static_cast<std::size_t>(i - rod.first)]; };
  if (first == last)
  {
    // One node: held in the mean direction of its segments, so that neither side is bent by the hold.
    Vec3 axis = Vec3::Zero();
    if (first > rod.first)
      axis += segmentTangent(rod, x, first - 1);
    if (first < rod.last())
      axis += segmentTangent(rod, x, first);
    axis = axis.norm() > 1e-9 ? Vec3(axis.normalized()) : segmentTangent(rod, x, first > rod.first ? first - 1 : first);
    const Eigen::Quaterniond near = segment(first > rod.first ? first - 1 : first);
    station.frame[0] = station.frame[1] = frameOf(axis, across(axis, near * Vec3::UnitY()));
  }
  else
  {
    station.frame[0] = segment(first);
    station.frame[1] = segment(last - 1);
  }
  for (int c = 0; c < 2; ++c)
    station.held[c] = holder.conjugate() * station.frame[c];
  std::size_t p = 0;
  while (p < rod.stations.size() && rod.stations[p].first < first)
    ++p;
  const int s = static_cast<int>(p);
  const bool before = s > 0, after = p < rod.stations.size();
  // The old interval's twist, shared between the two new ones by length (rodFrames spreads it so).
  double share_before = 0.0, share_after = 0.0;
  if (before && after)
  {
    const double old_twist = twist[twistSlot(rod, s - 1)];
    const double old_length = intervalLength(rod, s - 1);
    share_before = old_twist * rod.segment_length * (first - rod.stations[p - 1].last) / old_length;
    share_after = old_twist * rod.segment_length * (rod.stations[p].first - last) / old_length;
  }
  rod.stations.insert(rod.stations.begin() + s, station);
  if (before)
    twist[twistSlot(rod, s - 1)] = intervalTwist(rod, s - 1, x, share_before);
  if (after)
    twist[twistSlot(rod, s)] = intervalTwist(rod, s, x, share_after);
  return s;
}

void releaseRod(Rod& rod, const NodeArray& x, Eigen::VectorXd& twist, int s)
{
  const int stations = static_cast<int>(rod.stations.size());
  const bool before = s > 0, after = s + 1 < stations;
  const double joined = before && after ? twist[twistSlot(rod, s - 1)] + innerTwist(rod, s, x) + twist[twistSlot(rod, s)] : 0.0;
  twist[twistSlot(rod, s)] = 0.0;
  if (before)
    twist[twistSlot(rod, s - 1)] = 0.0;
  rod.stations.erase(rod.stations.begin() + s);
  if (before && after)
    twist[twistSlot(rod, s - 1)] = intervalTwist(rod, s - 1, x, joined);
}

}  // namespace soft_body_sim
