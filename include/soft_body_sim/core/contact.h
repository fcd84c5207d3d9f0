// The contact stage of a step: after each sub-step's integration, every kind of collider the scene
// declares (colliders.h) pushes the free nodes, with their contact radius, out of its shapes and changes
// their velocities (bounce, friction relative to the shape's own motion). A new kind is its shape struct
// in colliders.h, its ColliderKind in its own file (or a surfaceDistance for ShapeContacts), one line in
// makeColliderKinds (contact.cpp) and its reader: nothing in World. A scene that declares no colliders
// has no kinds here and pays nothing.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
/// Where a drawable collider is now, and its extents.
struct ColliderPose
{
  enum class Shape
  {
    Sphere,
    Capsule,
    Box
  };
  std::string name;
  Shape shape = Shape::Sphere;
  Vec3 position = Vec3::Zero();                                   ///< [m] of its origin
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  /// [m] sphere: its diameter three times; capsule: (2 radius, 2 radius, length); box: its size.
  Vec3 size = Vec3::Zero();

  static ColliderPose of(const Sphere& s) { return { s.at.name, Shape::Sphere, s.at.position, s.at.orientation, Vec3::Constant(2.0 * s.radius) }; }
  static ColliderPose of(const Capsule& c)
  {
    return { c.at.name, Shape::Capsule, c.at.position, c.at.orientation, Vec3(2.0 * c.radius, 2.0 * c.radius, c.length) };
  }
  static ColliderPose of(const Box& b) { return { b.at.name, Shape::Box, b.at.position, b.at.orientation, b.size }; }
};

/// One kind of collider, over all of its shapes in the model.
class ColliderKind
{
public:
  virtual ~ColliderKind() = default;
  /// After a sub-step of h [s] that took the nodes from `start` [m] to state.position: moves its shapes
  /// by h and resolves the contacts of every free node with them. True if it touched any node (the
  /// integrators' caches of the state are then stale).
  virtual bool resolve(const Model& model, const NodeArray& start, State& state, double h) = 0;
  /// Appends the current pose of each of its drawable shapes (planes are infinite: none).
  virtual void appendPoses(std::vector<ColliderPose>& /*poses*/) const {}
  /// Places its shape `name` (a unit quaternion); false if it has none of that name.
  virtual bool setPose(const std::string& /*name*/, const Vec3& /*position*/, const Eigen::Quaterniond& /*orientation*/)
  {
    return false;
  }
};

/// The kinds of collider that `model` declares, in the order they resolve. Throws std::invalid_argument
/// on a collider that its kind rejects.
std::vector<std::unique_ptr<ColliderKind>> makeColliderKinds(const Model& model);

class ContactStage
{
public:
  explicit ContactStage(const Model& model) : kinds_(makeColliderKinds(model)) {}

  /// Before a sub-step's integration: keeps where the nodes start (friction acts on the sub-step's
  /// displacement). Nothing without colliders.
  void remember(const State& state)
  {
    if (!kinds_.empty())
      start_ = state.position;
  }

  /// Every kind in turn; true if any touched a node.
  bool resolve(const Model& model, State& state, double h)
  {
    bool touched = false;
    for (const std::unique_ptr<ColliderKind>& kind : kinds_)
      touched = kind->resolve(model, start_, state, h) || touched;
    return touched;
  }

  /// The current pose of every drawable collider.
  std::vector<ColliderPose> poses() const
  {
    std::vector<ColliderPose> poses;
    for (const std::unique_ptr<ColliderKind>& kind : kinds_)
      kind->appendPoses(poses);
    return poses;
  }

  /// Places collider `name`; false if there is none of that name.
  bool setPose(const std::string& name, const Vec3& position, const Eigen::Quaterniond& orientation)
  {
    for (const std::unique_ptr<ColliderKind>& kind : kinds_)
      if (kind->setPose(name, position, orientation))
        return true;
    return false;
  }

private:
  std::vector<std::unique_ptr<ColliderKind>> kinds_;
  NodeArray start_;  ///< positions before the current sub-step's integration [m]
};

}  // namespace soft_body_sim
