// Contact with rigid shapes (spheres, capsules, boxes, cylinders, meshes): one template over the shape,
// whose geometry is surfaceDistance (colliders.h). Private to the core.
#pragma once

#include <algorithm>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <vector>

#include "core/contact/closest_points.h"
#include "core/contact/contact_response.h"
#include "soft_body_sim/core/contact/contact_stage.h"
#include "soft_body_sim/core/contact/mesh_field.h"

namespace soft_body_sim
{
/// The t in [lo, hi] where the shape is nearest to la + t d, by a ternary search of `iterations` steps
/// (the bracket shrinks by 2/3 each): exact where the distance along the line is convex in the bracket.
template <typename Shape>
double ternarySearch(const Shape& shape, const Vec3& la, const Vec3& d, double lo, double hi, int iterations)
{
  for (int iteration = 0; iteration < iterations; ++iteration)
  {
    const double m1 = lo + (hi - lo) / 3.0, m2 = hi - (hi - lo) / 3.0;
    if (surfaceDistance(shape, la + m1 * d).distance < surfaceDistance(shape, la + m2 * d).distance)
      hi = m2;
    else
      lo = m1;
  }
  return 0.5 * (lo + hi);
}

/// Where along the segment la + t d (t in [0, 1], in the shape's local frame) the shape is nearest: the
/// distance to a convex shape along a line is convex, so a ternary search finds it, to (2/3)^24 = 6e-5 of
/// the link (3 um of a 5 cm link). Spheres and capsules have closed forms below.
template <typename Shape>
double nearestParameter(const Shape& shape, const Vec3& la, const Vec3& d)
{
  return ternarySearch(shape, la, d, 0.0, 1.0, 24);
}

/// A sphere is nearest where its centre is.
inline double nearestParameter(const Sphere& /*sphere*/, const Vec3& la, const Vec3& d)
{
  const double length2 = d.squaredNorm();
  return length2 > 0.0 ? std::clamp(-la.dot(d) / length2, 0.0, 1.0) : 0.0;
}

/// A capsule is nearest where its axis is: the closest points of two segments (closest_points.h).
inline double nearestParameter(const Capsule& capsule, const Vec3& la, const Vec3& d)
{
  return closestSegmentParameters(la, d, Vec3(0.0, 0.0, -0.5 * capsule.length), Vec3(0.0, 0.0, capsule.length)).first;
}

/// A mesh need not be convex, so the distance along a segment may have several minima: it is sampled at
/// about a voxel apart (a minimum narrower than that is one the field cannot resolve anyway), then the
/// best sample's neighbourhood is searched as above, to (2/3)^16 = 2e-3 of two sample spacings.
inline double nearestParameter(const Mesh& mesh, const Vec3& la, const Vec3& d)
{
  const double voxel = mesh.field->voxelSize();
  const int samples = std::clamp(static_cast<int>(std::ceil(d.norm() / voxel)), 4, 256);
  int best = 0;
  double nearest = surfaceDistance(mesh, la).distance;
  for (int k = 1; k <= samples; ++k)
  {
    const double distance = surfaceDistance(mesh, la + (static_cast<double>(k) / samples) * d).distance;
    if (distance < nearest)
    {
      nearest = distance;
      best = k;
    }
  }
  const double lo = std::max(0, best - 1) / static_cast<double>(samples);
  const double hi = std::min(samples, best + 1) / static_cast<double>(samples);
  // Two minima in the bracket can mislead the search: it never returns worse than the best sample.
  const double t = ternarySearch(mesh, la, d, lo, hi, 16);
  return surfaceDistance(mesh, la + t * d).distance <= nearest ? t : best / static_cast<double>(samples);
}

/// The most a segment contact moves either node per unit of the contact point's correction.
constexpr double kMaxLever = 2.0;

template <typename Shape>
class ShapeContacts final : public ColliderKind
{
public:
  ShapeContacts(std::vector<Shape> shapes, int nodes)
    : shapes_(std::move(shapes))
    , goals_(shapes_.size())
    , touching_(static_cast<std::size_t>(nodes), 0)
    , received_(shapes_.size())
  {
    for (Shape& shape : shapes_)
    {
      checkCollider(shape);
      shape.at.orientation.normalize();
      bounds_.push_back(boundingRadius(shape));
      // A shape on a tf frame has no place in the scene until its frame's first pose lands.
      placed_.push_back(shape.at.frame.empty() ? 1 : 0);
    }
  }

  bool resolve(const Model& model, const NodeArray& start, State& state, double h) override
  {
    move(h);
    const double resting_speed = restingSpeed(model.gravity, h);
    bool touched_any = false;
    for (int i = 0; i < model.nodeCount(); ++i)
    {
      if (!model.isFree(i))
        continue;
      const bool was_touching = touching_[static_cast<std::size_t>(i)] != 0;
      bool touched = false;
      const double radius = model.contact_radius[i];
      for (std::size_t k = 0; k < shapes_.size(); ++k)
      {
        if (!placed_[k])
          continue;
        const Shape& shape = shapes_[k];
        const ColliderPlacement& at = shape.at;
        const Vec3 offset = Vec3(state.position.col(i)) - at.position;
        const double reach = bounds_[k] + radius;
        if (offset.squaredNorm() > reach * reach)
          continue;  // outside the shape's bounding ball: no need to look closer
        const Vec3 local = at.orientation.conjugate() * offset;
        const SurfaceDistance surface = surfaceDistance(shape, local);
        const double depth = radius - surface.distance;
        if (!(depth > 0.0))
          continue;
        touched = true;
        const Vec3 normal = at.orientation * surface.normal;
        const Vec3 contact = at.position + at.orientation * surface.closest;
        const Vec3 velocity = at.velocity + at.angular_velocity.cross(contact - at.position);
        const Vec3 v0 = state.velocity.col(i);
        const double approach = -(v0 - velocity).dot(normal);
        leaveSurface({ normal, velocity, at.friction, at.restitution }, depth, !was_touching && approach > resting_speed,
                     h, state.position.col(i) - start.col(i), state.position.col(i), state.velocity.col(i));
        push(k, contact, model.mass[i] * (v0 - state.velocity.col(i)));
      }
      touching_[static_cast<std::size_t>(i)] = touched ? 1 : 0;
      touched_any = touched_any || touched;
    }
    for (const auto& [a, b] : model.contact_segments)
      touched_any = resolveSegment(model, start, state, h, a, b) || touched_any;
    return touched_any;
  }

  bool touching(const Model& model, int node, const Vec3& x, double margin, NodeContact& contact) const override
  {
    bool found = false;
    const double radius = model.contact_radius[node];
    for (std::size_t k = 0; k < shapes_.size(); ++k)
    {
      if (!placed_[k])
        continue;
      const ColliderPlacement& at = shapes_[k].at;
      const Vec3 offset = x - at.position;
      const double reach = bounds_[k] + radius + margin;
      if (offset.squaredNorm() > reach * reach)
        continue;
      const SurfaceDistance surface = surfaceDistance(shapes_[k], Vec3(at.orientation.conjugate() * offset));
      const double depth = radius - surface.distance;
      if (!(depth > -margin) || (found && depth <= contact.depth))
        continue;
      const Vec3 point = at.orientation * surface.closest;
      contact = NodeContact{ at.orientation * surface.normal, at.velocity + at.angular_velocity.cross(point),
                             at.friction, depth, static_cast<int>(k) };
      found = true;
    }
    return found;
  }

  std::size_t count() const override { return shapes_.size(); }

  void receive(std::size_t shape, const Vec3& point, const Vec3& impulse) override { push(shape, point, impulse); }

  void clearImpulses() override { std::fill(received_.begin(), received_.end(), ReceivedImpulse{}); }

  void appendWrenches(double dt, std::vector<ColliderWrench>& wrenches) const override
  {
    for (std::size_t k = 0; k < shapes_.size(); ++k)
      if (!shapes_[k].at.name.empty())
        wrenches.push_back({ shapes_[k].at.name, received_[k].over(dt) });
  }

  void appendPoses(std::vector<ColliderPose>& poses) const override
  {
    for (std::size_t k = 0; k < shapes_.size(); ++k)
      if (placed_[k])
        poses.push_back(ColliderPose::of(shapes_[k]));
  }

  bool setGoal(const std::string& name, const std::optional<RigidPose>& goal, double dt) override
  {
    for (std::size_t k = 0; k < shapes_.size(); ++k)
    {
      ColliderPlacement& at = shapes_[k].at;
      if (at.name != name)
        continue;
      goals_[k] = goal;
      if (!goal)
      {
        at.velocity.setZero();
        at.angular_velocity.setZero();
        return true;
      }
      goals_[k]->orientation.normalize();
      if (!placed_[k])
      {
        // Its first pose: it appears there, at rest.
        at.position = goals_[k]->position;
        at.orientation = goals_[k]->orientation;
        at.velocity.setZero();
        at.angular_velocity.setZero();
        return true;
      }
      at.velocity = (goal->position - at.position) / dt;
      // The turn from the current orientation to the goal's, as a rotation vector over dt (the shorter way).
      Eigen::Quaterniond turn = goals_[k]->orientation * at.orientation.conjugate();
      if (turn.w() < 0.0)
        turn.coeffs() = -turn.coeffs();
      const Eigen::AngleAxisd axis_angle(turn);
      at.angular_velocity = axis_angle.angle() / dt * axis_angle.axis();
      return true;
    }
    return false;
  }

  void land() override
  {
    for (std::size_t k = 0; k < shapes_.size(); ++k)
      if (goals_[k])
      {
        shapes_[k].at.position = goals_[k]->position;
        shapes_[k].at.orientation = goals_[k]->orientation;
        goals_[k].reset();
        placed_[k] = 1;
      }
  }

private:
  /// A segment between nodes a and b, of their mean contact radius, against every shape: where the shape
  /// comes nearest to the segment's interior (the ends are nodes, resolved above), that point leaves the
  /// shape as a node would, and the correction is shared by the two nodes in proportion to their
  /// inverse masses and their weights at the point (the point moves by exactly the correction).
  bool resolveSegment(const Model& model, const NodeArray& start, State& state, double h, int a, int b)
  {
    const double wa = model.inverse_mass[a], wb = model.inverse_mass[b];
    if (wa == 0.0 && wb == 0.0)
      return false;
    const double radius = 0.5 * (model.contact_radius[a] + model.contact_radius[b]);
    bool touched = false;
    for (std::size_t k = 0; k < shapes_.size(); ++k)
    {
      if (!placed_[k])
        continue;
      const Shape& shape = shapes_[k];
      const ColliderPlacement& at = shape.at;
      const Vec3 xa = state.position.col(a), xb = state.position.col(b);
      // Cheap rejection: the segment's nearest point to the shape's origin is beyond its bounding ball.
      const Vec3 oa = xa - at.position, link = xb - xa;
      const double length2 = link.squaredNorm();
      const double s0 = length2 > 0.0 ? std::clamp(-oa.dot(link) / length2, 0.0, 1.0) : 0.0;
      const double reach = bounds_[k] + radius;
      if ((oa + s0 * link).squaredNorm() > reach * reach)
        continue;
      const Vec3 la = at.orientation.conjugate() * oa;
      const Vec3 d = at.orientation.conjugate() * link;
      const double t = nearestParameter(shape, la, d);
      if (t < 1e-6 || t > 1.0 - 1e-6)
        continue;  // an end: its node's contact
      const SurfaceDistance surface = surfaceDistance(shape, la + t * d);
      const double depth = radius - surface.distance;
      if (!(depth > 0.0) || (onTheSurface(shape, model, a, la, depth) && onTheSurface(shape, model, b, la + d, depth)))
        continue;
      touched = true;
      const double s = (1.0 - t) * (1.0 - t) * wa + t * t * wb;
      const Vec3 normal = at.orientation * surface.normal;
      const Vec3 contact = at.position + at.orientation * surface.closest;
      const Vec3 velocity = at.velocity + at.angular_velocity.cross(contact - at.position);
      Vec3 x = (1.0 - t) * xa + t * xb;
      Vec3 v = (1.0 - t) * state.velocity.col(a) + t * state.velocity.col(b);
      const Vec3 moved = x - ((1.0 - t) * start.col(a) + t * start.col(b));
      const Vec3 x0 = x, v0 = v;
      leaveSurface({ normal, velocity, at.friction, at.restitution }, depth, false, h, moved, x, v);
      // Next to a pinned (or much heavier) end the free node is a lever's long arm: moving the point by D
      // takes D / (1 - t) of it. Beyond kMaxLever the contact is left partly unresolved, since such a
      // point is all but on the pinned node, which contact cannot move.
      const double ka = std::min((1.0 - t) * wa / s, kMaxLever), kb = std::min(t * wb / s, kMaxLever);
      state.position.col(a) += ka * (x - x0);
      state.position.col(b) += kb * (x - x0);
      state.velocity.col(a) += ka * (v - v0);
      state.velocity.col(b) += kb * (v - v0);
      push(k, contact, -(ka * model.mass[a] + kb * model.mass[b]) * (v - v0));
    }
    return touched;
  }

  /// Whether a segment of contact depth `depth` [m] whose node `node` (at `local`, in the shape's frame) is
  /// on the shape lies on it as the rope does: a rope wrapped over a curved surface has its nodes on it and
  /// its chords a little inside, by (R + r)(1 - cos(delta / 2)) for a bend delta per link over radius R;
  /// the real rope is curved, not the chord. Pushing the chords out would lengthen the wrapped rope at
  /// every sub-step, which its tension undoes by dragging it along (measured: a rope over a frictionless
  /// capsule with equal loads drifted 0.1 m in 2 s). So a chord no deeper than the rope's radius (its
  /// axis outside the shape) between two nodes on the shape (within their radius plus a quarter) is left.
  static bool onTheSurface(const Shape& shape, const Model& model, int node, const Vec3& local, double depth)
  {
    const double radius = model.contact_radius[node];
    return depth < radius && surfaceDistance(shape, local).distance < 1.25 * radius + 1e-6;
  }

  /// Shape `shape` received `impulse` [N s] at `point` [m]: the opposite of the momentum a contact gave
  /// the nodes (their mass times their velocity change; a position correction alone carries none, and a
  /// node resting on the shape loses the g h it gained in the sub-step, so that the impulses of a step sum
  /// to its weight times dt).
  void push(std::size_t shape, const Vec3& point, const Vec3& impulse)
  {
    received_[shape].add(point - shapes_[shape].at.position, impulse);
  }

  /// Every shape moves by its constant velocity and turns by its angular velocity over h.
  void move(double h)
  {
    for (Shape& shape : shapes_)
    {
      ColliderPlacement& at = shape.at;
      at.position += h * at.velocity;
      const double angle = at.angular_velocity.norm() * h;
      if (angle > 0.0)
        at.orientation = (Eigen::Quaterniond(Eigen::AngleAxisd(angle, at.angular_velocity.normalized())) *
                          at.orientation).normalized();
    }
  }

  std::vector<Shape> shapes_;
  std::vector<std::optional<RigidPose>> goals_;  ///< per shape: where it arrives at this step's end
  std::vector<char> placed_;                     ///< per shape: has a pose in the scene (collides, is drawn)
  std::vector<double> bounds_;                   ///< per shape: boundingRadius [m]
  std::vector<std::uint8_t> touching_;  ///< per node: on one of these shapes after the last sub-step
  std::vector<ReceivedImpulse> received_;  ///< per shape: from the bodies since the step began
};

}  // namespace soft_body_sim
