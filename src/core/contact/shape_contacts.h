// Contact with rigid shapes (spheres, capsules, boxes, cylinders, meshes): one template over the shape,
// whose geometry is surfaceDistance (colliders.h). Private to the core.
#pragma once

#include <algorithm>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <tuple>
#include <utility>
#include <vector>

#include "core/contact/closest_points.h"
#include "core/contact/contact_response.h"
#include "core/contact/face_contacts.h"
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

/// Sweeps of a sub-step's face contacts: the first over every contact triangle, the others over the
/// features that touched one in the first. A cloth pressed by a
/// finger between its nodes folds round it, and each triangle's push moves its neighbours: measured on a
/// 5 cm cloth carried by a 1 cm finger at 2 m/s, one sweep left the finger through the cloth by the end
/// under implicit_euler; four carried it.
constexpr int kTrianglePasses = 4;

/// The part of its thickness [-] that a triangle's face and edges keep from a shape (its nodes keep all of
/// it). A cloth wrapped over a curved shape has its nodes on it and its faces, chords, inside by d^2 / 8R
/// for a spacing d over a radius R: pushing them out to the full thickness lifts the nodes off at every
/// sub-step and the draped cloth never comes to rest (measured: a 5 cm cloth on a 0.3 m ball still moving
/// at 0.15 m/s after 6 s). So a face may sag into the contact distance by up to half its thickness: never
/// into the shape.
constexpr double kFaceSag = 0.5;

/// A feature of a shape that touched a contact triangle (ShapeContacts' repeated sweeps).
struct TouchedFeature
{
  std::size_t triangle;  ///< in Model::contact_triangles
  std::size_t shape;
  std::size_t feature;
};

template <typename Shape>
class ShapeContacts final : public ColliderKind
{
public:
  std::unique_ptr<ColliderKind> clone() const override { return std::make_unique<ShapeContacts>(*this); }
  /// The shapes' motion, goals and contacts; the rest of a copy is fixed by the scene or made anew each
  /// sub-step.
  void carry(StateArchive& archive) override
  {
    for (Shape& shape : shapes_)
      archive(shape.at.position, shape.at.orientation, shape.at.velocity, shape.at.angular_velocity);
    archive(goals_, placed_, touching_, received_);
  }
  /// `faces`: the model has contact triangles (the shapes' features are made only then: a mesh's take a
  /// pass over its edges).
  ShapeContacts(std::vector<Shape> shapes, int nodes, bool faces)
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
      features_.push_back(faces ? shapeFeatures(shape) : std::vector<ShapeFeature>{});
      groups_.push_back(featureGroups(features_.back()));
      // A shape on a tf frame has no place in the scene until its frame's first pose lands.
      placed_.push_back(shape.at.frame.empty() ? 1 : 0);
    }
  }

  bool resolve(const Model& model, const NodeArray& start, State& state, double h) override
  {
    if (!model.contact_triangles.empty())
    {
      placeFeatures(start_features_, 0.0);
      start_positions_.clear();
      start_orientations_.clear();
      for (const Shape& shape : shapes_)
      {
        start_positions_.push_back(shape.at.position);
        start_orientations_.push_back(shape.at.orientation);
      }
    }
    move(h);
    if (!model.contact_triangles.empty())
      placeFeatures(features_now_, 0.0);
    const double widest = model.contact_radius.size() > 0 ? model.contact_radius.maxCoeff() : 0.0;
    if (markFarBodies(model, start, state.position, widest))
    {
      for (int i = 0; i < model.nodeCount(); ++i)
        if (model.isFree(i))
          touching_[static_cast<std::size_t>(i)] = 0;
      return false;
    }
    const double resting_speed = restingSpeed(model.gravity, h);
    bool touched_any = false;
    for (int i = 0; i < model.nodeCount(); ++i)
    {
      if (!model.isFree(i))
        continue;
      if (far_body_[static_cast<std::size_t>(i)] != 0)
      {
        touching_[static_cast<std::size_t>(i)] = 0;
        continue;
      }
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
      if (!farTogether(a, b))
        touched_any = resolveSegment(model, start, state, h, a, b) || touched_any;
    if (!model.contact_triangles.empty())
    {
      placeGroups(group_centres_now_, group_centres_then_);
      touched_features_.clear();
      face_impulses_.clear();
      for (std::size_t t = 0; t < model.contact_triangles.size(); ++t)
      {
        const std::array<int, 3>& triangle = model.contact_triangles[t];
        if (!farTogether(triangle[0], triangle[1]) || !farTogether(triangle[0], triangle[2]))
          resolveTriangle(model, start, state, h, t);
      }
      // Pushing one triangle moves its neighbours' corners: the features that touched a triangle, again,
      // as Gauss-Seidel sweeps.
      for (int pass = 1; pass < kTrianglePasses; ++pass)
        for (const TouchedFeature& touched : touched_features_)
          touchFeature(model, start, state, h, touched);
      balanceFaceImpulses(model, state);
      touched_any = touched_any || !touched_features_.empty();
    }
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

  void appendFaceContacts(const Model& model, const NodeArray& start, const NodeArray& end, double h, double margin,
                          int first, std::vector<FaceContact>& found) const override
  {
    if (model.contact_triangles.empty())
      return;
    // The features and their groups' centres where the shapes are (the sub-step's start) and where their
    // velocities take them by its end, and each shape's box over both, as the contact stage has them.
    placeFeatures(query_start_, 0.0);
    placeFeatures(query_end_, h);
    placeGroupCentres(query_centres_start_, 0.0);
    placeGroupCentres(query_centres_end_, h);
    boxShapes(query_end_, query_start_, model.contact_radius.maxCoeff() + margin, query_boxes_);
    for (std::size_t t = 0; t < model.contact_triangles.size(); ++t)
    {
      const std::array<int, 3>& triangle = model.contact_triangles[t];
      const TriangleCorners then{ start.col(triangle[0]), start.col(triangle[1]), start.col(triangle[2]) };
      const TriangleCorners now{ end.col(triangle[0]), end.col(triangle[1]), end.col(triangle[2]) };
      const double thickness = triangleThickness(model, triangle);
      Eigen::AlignedBox3d box;
      for (int c = 0; c < 3; ++c)
      {
        box.extend(then[c]);
        box.extend(now[c]);
      }
      box.min().array() -= thickness;
      box.max().array() += thickness;
      std::optional<TriangleBall> ball;
      for (std::size_t k = 0; k < shapes_.size(); ++k)
      {
        if (!placed_[k] || features_[k].empty() || !box.intersects(query_boxes_[k]))
          continue;
        if (!ball)
          ball.emplace(now, then);
        const ColliderPlacement& at = shapes_[k].at;
        const Vec3 centre_end = at.position + h * at.velocity;
        forEachFeatureNear(k, *ball, thickness + margin, query_centres_end_[k], query_centres_start_[k], query_end_[k],
                           query_start_[k], [&](std::size_t f) {
                             // Within the margin: the thicknesses widened by it, the depth taken back.
                             const std::optional<FaceTouch> touch =
                                 faceTouch(query_end_[k][f], query_start_[k][f], now, then, thickness + margin,
                                           kFaceSag * thickness + margin);
                             // A corner is its node's contact (`touching`).
                             if (!touch || touch->weight.maxCoeff() >= 1.0)
                               return;
                             const Vec3 velocity = at.velocity + at.angular_velocity.cross(touch->contact - centre_end);
                             found.push_back({ t, touch->weight,
                                               NodeContact{ touch->normal, velocity, at.friction, touch->depth - margin,
                                                            first + static_cast<int>(k) },
                                               f });
                           });
      }
    }
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
        // Arrived: it holds still unless a new goal (a path's, World::moveCollider's) moves it on.
        shapes_[k].at.velocity.setZero();
        shapes_[k].at.angular_velocity.setZero();
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

  /// A triangle of a surface against every shape's features (face_contacts.h), each contact shared by the
  /// triangle's nodes by their weights at the point as resolveSegment shares it: the point moves by the
  /// correction, and each node gets the impulse it would get if the contact were at that node, in
  /// proportion to its weight.
  bool resolveTriangle(const Model& model, const NodeArray& start, State& state, double h, std::size_t index)
  {
    const std::array<int, 3>& triangle = model.contact_triangles[index];
    const double thickness = triangleThickness(model, triangle);
    const TriangleCorners then{ start.col(triangle[0]), start.col(triangle[1]), start.col(triangle[2]) };
    const auto corners = [&] {
      return TriangleCorners{ state.position.col(triangle[0]), state.position.col(triangle[1]),
                              state.position.col(triangle[2]) };
    };
    const Eigen::AlignedBox3d box = triangleBox(model, start, state.position, triangle);
    bool touched = false;
    std::optional<TriangleBall> ball;
    for (std::size_t k = 0; k < shapes_.size(); ++k)
    {
      if (!placed_[k] || features_[k].empty())
        continue;
      if (!box.intersects(shape_boxes_[k]))
        continue;
      if (!ball)
        ball.emplace(corners(), then);
      bool touched_shape = false;
      forEachFeatureNear(k, *ball, thickness, group_centres_now_[k], group_centres_then_[k], features_now_[k],
                         start_features_[k], [&](std::size_t f) {
                           const TouchedFeature feature{ index, k, f };
                           if (touchFeature(model, start, state, h, feature))
                           {
                             touched_features_.push_back(feature);
                             touched_shape = true;
                           }
                         });
      if (touched_shape)
      {
        touched = true;
        ball.reset();  // the triangle moved
      }
    }
    return touched;
  }

  /// Feature f of shape k against contact triangle `triangle` (faceTouch): true if it touched, and the
  /// triangle was pushed.
  bool touchFeature(const Model& model, const NodeArray& start, State& state, double h, const TouchedFeature& touched)
  {
    const std::array<int, 3>& triangle = model.contact_triangles[touched.triangle];
    const double thickness = triangleThickness(model, triangle);
    const std::optional<FaceTouch> touch = faceTouch(
        features_now_[touched.shape][touched.feature], start_features_[touched.shape][touched.feature],
        TriangleCorners{ state.position.col(triangle[0]), state.position.col(triangle[1]), state.position.col(triangle[2]) },
        TriangleCorners{ start.col(triangle[0]), start.col(triangle[1]), start.col(triangle[2]) }, thickness,
        kFaceSag * thickness);
    return touch && pushTriangle(model, start, state, h, triangle, *touch, touched.shape);
  }

  /// The triangle's point of `touch` leaves the shape as a node would, the correction shared by its nodes.
  bool pushTriangle(const Model& model, const NodeArray& start, State& state, double h,
                    const std::array<int, 3>& triangle, const FaceTouch& touch, std::size_t k)
  {
    const ColliderPlacement& at = shapes_[k].at;
    double s = 0.0;
    Vec3 x = Vec3::Zero(), v = Vec3::Zero(), x_start = Vec3::Zero();
    for (int c = 0; c < 3; ++c)
    {
      const int node = triangle[c];
      s += touch.weight[c] * touch.weight[c] * model.inverse_mass[node];
      x += touch.weight[c] * state.position.col(node);
      v += touch.weight[c] * state.velocity.col(node);
      x_start += touch.weight[c] * start.col(node);
    }
    if (!(s > 0.0))
      return false;
    const Vec3 velocity = at.velocity + at.angular_velocity.cross(touch.contact - at.position);
    const double approach = -(v - velocity).dot(touch.normal);
    const Vec3 x0 = x, v0 = v;
    leaveSurface({ touch.normal, velocity, at.friction, at.restitution }, touch.depth,
                 approach > restingSpeed(model.gravity, h), h, x - x_start, x, v);
    double moved_mass = 0.0;  // the momentum the nodes gain is moved_mass (v - v0)
    for (int c = 0; c < 3; ++c)
    {
      const int node = triangle[c];
      const double share = std::min(touch.weight[c] * model.inverse_mass[node] / s, kMaxLever);
      state.position.col(node) += share * (x - x0);
      state.velocity.col(node) += share * (v - v0);
      moved_mass += share * model.mass[node];
    }
    push(k, touch.contact, -moved_mass * (v - v0));
    face_impulses_.push_back(FaceImpulse{ triangle, k, touch.weight, touch.normal, touch.contact,
                                          (v - velocity).dot(touch.normal), (v - v0).dot(touch.normal) / s, s });
    return true;
  }

  /// A push given to a triangle's point in this sub-step's sweeps (pushTriangle), for balanceFaceImpulses.
  struct FaceImpulse
  {
    std::array<int, 3> triangle;
    std::size_t shape;
    Vec3 weight;
    Vec3 normal;
    Vec3 contact;
    double target;   ///< [m/s] the normal speed it left the point with relative to the shape (0, or a bounce)
    double impulse;  ///< [N s] along the normal, >= 0
    double inverse_mass;  ///< s = sum_c weight_c^2 / m_c [1/kg]
  };

  /// Each push changed its nodes' velocities by the whole change of its point's (a mid-edge point moves
  /// both ends, as one impulse there must): where pushes share a node, a later one gives it more than the
  /// earlier one's point needed, and that point leaves the shape faster than the push meant. So the normal
  /// impulses are balanced by projected Gauss-Seidel (kTrianglePasses sweeps), each kept >= 0: a point
  /// leaving faster than its push's target speed (0, or a bounce) gives back what it got too much, down to
  /// none. Measured: without it, a taut cloth wrapped round a still finger under implicit_euler (12 sub-steps
  /// of 1/60 s) kept a node beside the finger at 5 m/s, pushed out each sub-step and carried back in by its
  /// tension; with it, 0.7 m/s, the cloth's swing.
  void balanceFaceImpulses(const Model& model, State& state)
  {
    for (int pass = 0; pass < kTrianglePasses; ++pass)
      for (FaceImpulse& f : face_impulses_)
      {
        const ColliderPlacement& at = shapes_[f.shape].at;
        Vec3 v = Vec3::Zero();
        for (int c = 0; c < 3; ++c)
          v += f.weight[c] * state.velocity.col(f.triangle[c]);
        const Vec3 velocity = at.velocity + at.angular_velocity.cross(f.contact - at.position);
        const double speed = (v - velocity).dot(f.normal);
        const double impulse = std::max(0.0, f.impulse + (f.target - speed) / f.inverse_mass);
        const double change = impulse - f.impulse;
        if (change == 0.0)
          continue;
        f.impulse = impulse;
        double moved_mass = 0.0;
        for (int c = 0; c < 3; ++c)
        {
          const int node = f.triangle[c];
          const double share = std::min(f.weight[c] * model.inverse_mass[node] / f.inverse_mass, kMaxLever);
          state.velocity.col(node) += share * (change * f.inverse_mass) * f.normal;
          moved_mass += share * model.mass[node];
        }
        push(f.shape, f.contact, -moved_mass * change * f.inverse_mass * f.normal);
      }
  }

  /// A contact triangle's axis-aligned bounding box over the sub-step (its corners at its start and now,
  /// widened by its thickness: pushes within the sweep move it by about that). Where it is apart from a
  /// shape's box (boxShapes), the triangle is not looked at more closely (a rail along a cloth's width has
  /// a bounding ball as big as the cloth, but a box as thin as the rail).
  static Eigen::AlignedBox3d triangleBox(const Model& model, const NodeArray& start, const NodeArray& x,
                                         const std::array<int, 3>& triangle)
  {
    // The corners' least and greatest coordinates, component by component (what AlignedBox::extend does,
    // here inlined: this runs for every triangle near a shape, every sub-step, for each kind of shape).
    Vec3 low = x.col(triangle[0]).cwiseMin(start.col(triangle[0]));
    Vec3 high = x.col(triangle[0]).cwiseMax(start.col(triangle[0]));
    double thickness = model.contact_radius[triangle[0]];
    for (int c = 1; c < 3; ++c)
    {
      const int node = triangle[static_cast<std::size_t>(c)];
      low = low.cwiseMin(x.col(node)).cwiseMin(start.col(node));
      high = high.cwiseMax(x.col(node)).cwiseMax(start.col(node));
      thickness = std::max(thickness, model.contact_radius[node]);
    }
    return Eigen::AlignedBox3d(low.array() - thickness, high.array() + thickness);
  }

  /// far_body_ for this sub-step: per node, 1 + the index of its body where that body is out of reach of
  /// every placed shape, else 0; true if every node is out of reach (a scene's links and triangles are each
  /// of one body: SceneDef). A body is out of reach where the box of its nodes at the sub-step's start and
  /// now, widened by the widest contact radius, is apart from each shape's bounding ball (what a node and a
  /// link test first; widened by a billionth, which rounding cannot cross) and, for the faces, from each
  /// shape's box (boxShapes, which contains the box of each of its triangles). None of its nodes, links or
  /// triangles can then touch, so none is moved, and the box holds for the whole resolve: the same bits,
  /// without a look at each node, link and triangle of a cloth that a gripper's fingers are far from (in
  /// the demo, the fingers' contacts took 9 % of the cloth's cost without ever reaching it).
  bool markFarBodies(const Model& model, const NodeArray& start, const NodeArray& x, double widest)
  {
    far_body_.assign(static_cast<std::size_t>(model.nodeCount()), 0);
    if (!model.contact_triangles.empty())
      boxShapes(features_now_, start_features_, widest, shape_boxes_);
    for (std::size_t b = 0; b < model.bodies.size(); ++b)
    {
      const BodyRange& body = model.bodies[b];
      if (body.count <= 0)
        continue;
      // Node by node, as triangleBox (a row's minCoeff over a 3 x n block is strided: twice the time).
      Vec3 low = x.col(body.first).cwiseMin(start.col(body.first));
      Vec3 high = x.col(body.first).cwiseMax(start.col(body.first));
      for (int i = body.first + 1; i < body.first + body.count; ++i)
      {
        low = low.cwiseMin(x.col(i)).cwiseMin(start.col(i));
        high = high.cwiseMax(x.col(i)).cwiseMax(start.col(i));
      }
      const Eigen::AlignedBox3d nodes(low.array() - widest, high.array() + widest);
      // A diverged node (the guard restores its body after the step) leaves the box unknown: looked at.
      bool far = nodes.min().allFinite() && nodes.max().allFinite();
      for (std::size_t k = 0; k < shapes_.size() && far; ++k)
      {
        if (!placed_[k])
          continue;
        const Vec3& centre = shapes_[k].at.position;
        const double reach = bounds_[k] + 1e-9 * (bounds_[k] + centre.cwiseAbs().maxCoeff()) + 1e-12;
        far = !nodes.intersects(Eigen::AlignedBox3d(centre.array() - reach, centre.array() + reach)) &&
              (features_[k].empty() || !nodes.intersects(shape_boxes_[k]));
      }
      if (far)
        std::fill_n(far_body_.begin() + body.first, body.count, static_cast<int>(b) + 1);
    }
    return std::find(far_body_.begin(), far_body_.end(), 0) == far_body_.end();
  }

  /// Nodes a and b are of one body out of every shape's reach (markFarBodies): their link or triangle is too.
  bool farTogether(int a, int b) const
  {
    const int body = far_body_[static_cast<std::size_t>(a)];
    return body != 0 && body == far_body_[static_cast<std::size_t>(b)];
  }

  /// Each shape's box around its features `now` and `then` (in the scene frame), widened by their radii and
  /// `widen` [m].
  void boxShapes(const std::vector<std::vector<ShapeFeature>>& now, const std::vector<std::vector<ShapeFeature>>& then,
                 double widen, std::vector<Eigen::AlignedBox3d>& boxes) const
  {
    boxes.resize(shapes_.size());
    for (std::size_t k = 0; k < shapes_.size(); ++k)
    {
      Eigen::AlignedBox3d& box = boxes[k];
      box.setEmpty();
      for (std::size_t f = 0; f < features_[k].size(); ++f)
      {
        const double reach = features_[k][f].radius + widen;
        for (const ShapeFeature* feature : { &now[k][f], &then[k][f] })
          for (const Vec3& end : { feature->a, feature->b })
          {
            box.extend(Vec3(end.array() - reach));
            box.extend(Vec3(end.array() + reach));
          }
      }
    }
  }

  /// Calls touch(f) for every feature f of shape k whose group and whose own segment come within `reach` [m]
  /// of the triangle's `ball` over the sub-step: the groups' centres and the features `now` and `then` (in
  /// the scene frame).
  template <typename Touch>
  void forEachFeatureNear(std::size_t k, const TriangleBall& ball, double reach, const std::vector<Vec3>& centres_now,
                          const std::vector<Vec3>& centres_then, const std::vector<ShapeFeature>& now,
                          const std::vector<ShapeFeature>& then, Touch touch) const
  {
    // The box of the ball's centre's path: meetsSegment's point (on the feature, in the box of its ends at the
    // start and now) comes within its reach of a point there, so a feature whose box is farther from it than
    // that along some axis does not meet the ball. A few comparisons spare the division of meetsSegment for
    // most features of a large shape (the twelve edges of a table against each triangle of the cloth on it:
    // most of the cloth's contact cost). The margin keeps rounding on the side of looking; the same bits.
    const Vec3 centre_low = ball.centre.cwiseMin(ball.centre_then), centre_high = ball.centre.cwiseMax(ball.centre_then);
    for (std::size_t g = 0; g < groups_[k].size(); ++g)
    {
      const FeatureGroup& group = groups_[k][g];
      if (!ball.meets(centres_now[g], centres_then[g], group.radius + reach))
        continue;
      for (std::size_t f = group.first; f < group.last; ++f)
      {
        const double within = (now[f].radius + reach + ball.size) * (1.0 + 1e-9) + 1e-12;
        const Vec3 low = now[f].a.cwiseMin(now[f].b).cwiseMin(then[f].a).cwiseMin(then[f].b);
        const Vec3 high = now[f].a.cwiseMax(now[f].b).cwiseMax(then[f].a).cwiseMax(then[f].b);
        if (((low - centre_high).array() > within).any() || ((centre_low - high).array() > within).any())
          continue;
        if (ball.meetsSegment(now[f], then[f], reach))
          touch(f);
      }
    }
  }

  /// Every shape's feature groups' centres in the scene frame where its velocities take it in h [s] (0: now).
  void placeGroupCentres(std::vector<std::vector<Vec3>>& centres, double h) const
  {
    centres.resize(shapes_.size());
    for (std::size_t k = 0; k < shapes_.size(); ++k)
    {
      const auto [position, orientation] = advanced(shapes_[k].at, h);
      centres[k].clear();
      for (const FeatureGroup& group : groups_[k])
        centres[k].push_back(position + orientation * group.centre);
    }
  }

  /// Every shape's feature groups' centres in the scene frame now and at the sub-step's start.
  void placeGroups(std::vector<std::vector<Vec3>>& now, std::vector<std::vector<Vec3>>& then) const
  {
    placeGroupCentres(now, 0.0);
    then.resize(shapes_.size());
    for (std::size_t k = 0; k < shapes_.size(); ++k)
    {
      then[k].clear();
      for (const FeatureGroup& group : groups_[k])
        then[k].push_back(start_positions_[k] + start_orientations_[k] * group.centre);
    }
  }

  /// Every shape's features in the scene frame (face_contacts.h), where its velocities take it in h [s] (0:
  /// where it is now), into `placed`.
  void placeFeatures(std::vector<std::vector<ShapeFeature>>& placed, double h) const
  {
    placed.resize(shapes_.size());
    for (std::size_t k = 0; k < shapes_.size(); ++k)
    {
      const auto [position, orientation] = advanced(shapes_[k].at, h);
      placed[k].clear();
      for (const ShapeFeature& f : features_[k])
        placed[k].push_back({ position + orientation * f.a, position + orientation * f.b, f.radius, f.flat_ends });
    }
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

  /// Where a shape placed `at` is after h [s] at its constant velocity and angular velocity.
  static std::pair<Vec3, Eigen::Quaterniond> advanced(const ColliderPlacement& at, double h)
  {
    const double angle = at.angular_velocity.norm() * h;
    if (!(angle > 0.0))
      return { at.position + h * at.velocity, at.orientation };
    return { at.position + h * at.velocity,
             (Eigen::Quaterniond(Eigen::AngleAxisd(angle, at.angular_velocity.normalized())) * at.orientation).normalized() };
  }

  /// Every shape moves by its constant velocity and turns by its angular velocity over h.
  void move(double h)
  {
    for (Shape& shape : shapes_)
      std::tie(shape.at.position, shape.at.orientation) = advanced(shape.at, h);
  }

  std::vector<Shape> shapes_;
  std::vector<std::optional<RigidPose>> goals_;  ///< per shape: where it arrives at this step's end
  std::vector<char> placed_;                     ///< per shape: has a pose in the scene (collides, is drawn)
  std::vector<double> bounds_;                   ///< per shape: boundingRadius [m]
  std::vector<std::uint8_t> touching_;  ///< per node: on one of these shapes after the last sub-step
  std::vector<std::vector<ShapeFeature>> features_;  ///< per shape: its features in its own frame
  /// per shape: its features in the scene frame at the start of the current sub-step and now
  std::vector<std::vector<ShapeFeature>> start_features_, features_now_;
  std::vector<TouchedFeature> touched_features_;  ///< those of this sub-step's first sweep
  std::vector<FaceImpulse> face_impulses_;        ///< the pushes of this sub-step's sweeps
  std::vector<std::vector<FeatureGroup>> groups_;  ///< per shape: its features in groups, for the search
  std::vector<std::vector<Vec3>> group_centres_now_, group_centres_then_;  ///< placeGroups
  std::vector<Eigen::AlignedBox3d> shape_boxes_;  ///< per shape: boxShapes of its features over the sub-step
  std::vector<int> far_body_;  ///< markFarBodies
  std::vector<Vec3> start_positions_;  ///< per shape: its origin at the start of the current sub-step [m]
  std::vector<Eigen::Quaterniond> start_orientations_;  ///< per shape: its orientation then
  std::vector<ReceivedImpulse> received_;  ///< per shape: from the bodies since the step began
  /// appendFaceContacts' features and their groups' centres at the sub-step's start and end, and its shapes'
  /// boxes over both
  mutable std::vector<std::vector<ShapeFeature>> query_start_, query_end_;
  mutable std::vector<std::vector<Vec3>> query_centres_start_, query_centres_end_;
  mutable std::vector<Eigen::AlignedBox3d> query_boxes_;
};

}  // namespace soft_body_sim
