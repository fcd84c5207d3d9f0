#include "soft_body_sim/core/rods.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

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

/// The transport's tangents along the rod at x: its held first axis (if held), each segment's unit
/// tangent, its held last axis (if held); computed where needed, so that a step allocates nothing.
struct Tangents
{
  const Rod& rod;
  const NodeArray& x;

  int size() const { return rod.count - 1 + (rod.held[0] ? 1 : 0) + (rod.held[1] ? 1 : 0); }
  /// Tangent k; a segment of zero length takes the rest axis.
  Vec3 operator[](int k) const
  {
    if (rod.held[0] && k == 0)
      return heldAxis(rod, 0);
    if (rod.held[1] && k == size() - 1)
      return heldAxis(rod, 1);
    const int i = rod.first + k - (rod.held[0] ? 1 : 0);
    const Vec3 e = x.col(i + 1) - x.col(i);
    const double length = e.norm();
    return length > 0.0 ? Vec3(e / length) : Vec3(rod.rest_frame * Vec3::UnitX());
  }
};

/// The unit vector across tangent t nearest to `y` (any one across t if y is along it).
Vec3 across(const Vec3& t, const Vec3& y)
{
  Vec3 d = y - y.dot(t) * t;
  if (d.norm() < 1e-9)
    d = t.unitOrthogonal();
  return d.normalized();
}
}  // namespace

void requireRodIntegrator(const Model& model, IntegratorType integrator)
{
  if (!model.rods.empty() && integrator != IntegratorType::ImplicitEuler)
    throw std::invalid_argument("a rod (type: rod) bends and twists only under implicit_euler, not " +
                                integratorName(integrator));
}

int heldRodEnd(const Model& model, int node, int& end)
{
  for (std::size_t r = 0; r < model.rods.size(); ++r)
    for (end = 0; end < 2; ++end)
      if (model.rods[r].held[end] && node == (end == 0 ? model.rods[r].first : model.rods[r].last()))
        return static_cast<int>(r);
  return -1;
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
    vertices.push_back({ i - 1, i, i + 1, inner });
  for (int end = 0; end < 2; ++end)
    if (rod.held[end])
      vertices.push_back(heldVertex(rod, end));
}

RodVertex heldVertex(const Rod& rod, int end)
{
  const double weight = rod.bending_stiffness / rod.segment_length;  // E I / (2 D), D = l / 2
  return end == 0 ? RodVertex{ -1, rod.first, rod.first + 1, weight } : RodVertex{ rod.last() - 1, rod.last(), -1, weight };
}

void vertexEdges(const Rod& rod, const RodVertex& vertex, const NodeArray& x, Vec3& e0, Vec3& e1)
{
  e0 = vertex.before < 0 ? Vec3(rod.segment_length * heldAxis(rod, 0)) : Vec3(x.col(vertex.at) - x.col(vertex.before));
  e1 = vertex.after < 0 ? Vec3(rod.segment_length * heldAxis(rod, 1)) : Vec3(x.col(vertex.after) - x.col(vertex.at));
}

double rodTwist(const Rod& rod, const NodeArray& x, double near)
{
  if (!rod.twists())
    return 0.0;
  const Tangents t{ rod, x };
  Vec3 d = rod.end_frame[0] * Vec3::UnitY();
  Vec3 before = t[0];
  for (int k = 1; k < t.size(); ++k)
  {
    const Vec3 after = t[k];
    d = transport(d, before, after);
    before = after;
  }
  const Vec3 y = rod.end_frame[1] * Vec3::UnitY();
  const double angle = std::atan2(before.dot(d.cross(y)), d.dot(y));
  return near + std::remainder(angle - near, 2.0 * M_PI);
}

void rodTwistGradient(const Rod& rod, const NodeArray& x, NodeArray& gradient)
{
  gradient.setZero(3, rod.count);
  if (!rod.twists())
    return;
  // Both ends are held: tangent 0 is the first held axis, j + 1 segment j's, the last the last held axis.
  const Tangents t{ rod, x };
  const auto unit_kb = [](const Vec3& a, const Vec3& b) -> Vec3 {
    return 2.0 * a.cross(b) / std::max(1.0 + a.dot(b), kMinFold);
  };
  Vec3 before = t[0];
  Vec3 tangent = t[1];
  for (int j = 0; j + 1 < rod.count; ++j)
  {
    const Vec3 after = t[j + 2];
    const double length = (x.col(rod.first + j + 1) - x.col(rod.first + j)).norm();
    if (length > 0.0)
    {
      const Vec3 g = (unit_kb(before, tangent) + unit_kb(tangent, after)) / (2.0 * length);
      gradient.col(j + 1) += g;
      gradient.col(j) -= g;
    }
    before = tangent;
    tangent = after;
  }
}

double rodEnergy(const Rod& rod, const NodeArray& x, double twist)
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
  if (rod.twists())
    energy += 0.5 * rod.twisting_stiffness * twist * twist / rod.restLength();
  return energy;
}

void accumulateRodForces(const Rod& rod, const NodeArray& x, double twist, NodeArray& force)
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
  if (!rod.twists())
    return;
  NodeArray gradient;
  rodTwistGradient(rod, x, gradient);
  force.middleCols(rod.first, rod.count) -= (rod.twisting_stiffness * twist / rod.restLength()) * gradient;
}

void rodFrames(const Rod& rod, const NodeArray& x, double twist, std::vector<Eigen::Quaterniond>& frames)
{
  frames.clear();
  const Tangents t{ rod, x };
  const int first_segment = rod.held[0] ? 1 : 0;
  Vec3 d = rod.held[0] ? Vec3(rod.end_frame[0] * Vec3::UnitY())
                       : across(t[first_segment], rod.rest_frame * Vec3::UnitY());
  if (rod.held[0])
    d = transport(d, t[0], t[1]);
  const double segments = rod.count - 1;
  for (int j = 0; j + 1 < rod.count; ++j)
  {
    const int k = first_segment + j;
    if (j > 0)
      d = transport(d, t[k - 1], t[k]);
    const Vec3 y = Eigen::AngleAxisd(twist * (j + 0.5) / segments, t[k]) * across(t[k], d);
    Eigen::Matrix3d axes;
    axes << t[k], y, t[k].cross(y);
    frames.emplace_back(axes);
  }
}

Vec3 heldEndTorque(const Rod& rod, const NodeArray& x, double twist, int end)
{
  if (!rod.held[end])
    return Vec3::Zero();
  const Vec3 axis = heldAxis(rod, end);
  const RodVertex vertex = heldVertex(rod, end);
  Vec3 e0, e1;
  vertexEdges(rod, vertex, x, e0, e1);
  const CurvatureBinormal bend = curvatureBinormal(e0, e1, rod.segment_length * rod.segment_length);
  const Vec3 g = 2.0 * vertex.weight * (end == 0 ? bend.d_e0 : bend.d_e1).transpose() * bend.kb;
  Vec3 torque = rod.segment_length * g.cross(axis);
  if (rod.twists())
    torque += (end == 0 ? 1.0 : -1.0) * rod.twisting_stiffness * twist / rod.restLength() * axis;
  return torque;
}

}  // namespace soft_body_sim
