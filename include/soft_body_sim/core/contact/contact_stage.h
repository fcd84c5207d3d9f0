// The contact stage of a step: after each sub-step's integration, every kind of collider the scene
// declares (colliders.h) pushes the free nodes, with their contact radius, out of its shapes and changes
// their velocities (bounce, friction relative to the shape's own motion). Solves that take contact into
// themselves (xpbd's chains) ask it where a node touches through ContactQuery. A new kind is its shape struct
// in colliders.h, its ColliderKind in its own file (or a surfaceDistance for ShapeContacts), one line in
// makeColliderKinds (contact_stage.cpp) and its reader: nothing in World. A scene that declares no colliders
// has no kinds here and pays nothing.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "soft_body_sim/core/holding/reactions.h"
#include "soft_body_sim/core/integrators/integrator.h"
#include "soft_body_sim/core/model.h"
#include "soft_body_sim/core/state_archive.h"

namespace soft_body_sim
{
/// Where a drawable collider is now, and its extents.
struct ColliderPose
{
  enum class Shape
  {
    Sphere,
    Capsule,
    Box,
    Cylinder,
    Mesh
  };
  std::string name;
  Shape shape = Shape::Sphere;
  Vec3 position = Vec3::Zero();                                   ///< [m] of its origin
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  /// [m] sphere: its diameter three times; capsule and cylinder: (2 radius, 2 radius, length); box: its size;
  /// mesh: its scale [-] (the file's coordinates are metres).
  Vec3 size = Vec3::Zero();
  std::string mesh;  ///< a mesh's file as rviz loads it (Mesh::uri: package:// or file://); else empty
  Vec3 color = Vec3::Constant(0.6);  ///< rgb in [0, 1] (ColliderPlacement::color)

  static ColliderPose of(const Sphere& s)
  {
    return { s.at.name, Shape::Sphere, s.at.position, s.at.orientation, Vec3::Constant(2.0 * s.radius), {}, s.at.color };
  }
  static ColliderPose of(const Capsule& c)
  {
    return { c.at.name, Shape::Capsule, c.at.position, c.at.orientation,
             Vec3(2.0 * c.radius, 2.0 * c.radius, c.length), {}, c.at.color };
  }
  static ColliderPose of(const Box& b)
  {
    return { b.at.name, Shape::Box, b.at.position, b.at.orientation, b.size, {}, b.at.color };
  }
  static ColliderPose of(const Cylinder& c)
  {
    return { c.at.name, Shape::Cylinder, c.at.position, c.at.orientation,
             Vec3(2.0 * c.radius, 2.0 * c.radius, c.length), {}, c.at.color };
  }
  static ColliderPose of(const Mesh& m)
  {
    return { m.at.name, Shape::Mesh, m.at.position, m.at.orientation, m.scale, m.uri, m.at.color };
  }
};

/// A rigid pose: position [m] and orientation (unit quaternion) of a collider's origin and axes.
struct RigidPose
{
  Vec3 position = Vec3::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();

  void carry(StateArchive& archive) { archive(position, orientation); }
};

/// `local`, a pose in the frame that `frame` places, in the frame's parent (a tf child's pose composed with
/// its parent's).
inline RigidPose compose(const RigidPose& frame, const RigidPose& local)
{
  return { frame.position + frame.orientation * local.position, frame.orientation * local.orientation };
}

/// Where a collider should be at simulated time t [s]; nullopt = not known (it then holds still).
using ColliderPath = std::function<std::optional<RigidPose>(double t)>;

/// The force [N] and torque [N m] that the bodies exerted on a named collider, averaged over the last step
/// (the contact impulses it received in the step's sub-steps over dt), torque about its origin, both in
/// the scene frame (World::colliderWrenches).
struct ColliderWrench
{
  std::string name;
  Wrench wrench;
};

/// What one collider received from the bodies since the step began: the sum of the contact impulses
/// [N s] and of their moments about its origin [N m s].
struct ReceivedImpulse
{
  Vec3 linear = Vec3::Zero();
  Vec3 angular = Vec3::Zero();

  /// An impulse [N s] at `arm` [m] from the collider's origin.
  void add(const Vec3& arm, const Vec3& impulse)
  {
    linear += impulse;
    angular += arm.cross(impulse);
  }
  /// Their mean force and torque over a step of dt [s].
  Wrench over(double dt) const { return Wrench{ linear / dt, angular / dt }; }

  void carry(StateArchive& archive) { archive(linear, angular); }
};

/// One kind of collider, over all of its shapes in the model.
class ColliderKind
{
public:
  virtual ~ColliderKind() = default;
  /// A copy with its shapes where they are, their goals and what they touch (a mesh's distance field is
  /// shared: it never changes).
  virtual std::unique_ptr<ColliderKind> clone() const = 0;
  /// Writes or reads what a clone copies (state_archive.h), into a kind built from the same scene.
  virtual void carry(StateArchive& archive) = 0;
  /// After a sub-step of h [s] that took the nodes from `start` [m] to state.position: moves its shapes
  /// by h and resolves the contacts of every free node with them. True if it touched any node (the
  /// integrators' caches of the state are then stale).
  virtual bool resolve(const Model& model, const NodeArray& start, State& state, double h) = 0;
  /// ContactQuery::touching over its shapes (as they are before this sub-step's resolve moves them);
  /// the contact's `collider` is its shape's index among its own.
  virtual bool touching(const Model& /*model*/, int /*node*/, const Vec3& /*x*/, double /*margin*/,
                        NodeContact& /*contact*/) const
  {
    return false;
  }
  /// ContactQuery::touchingFaces over its shapes (as they are before this sub-step's resolve moves them),
  /// appended to `found`; each contact's `collider` is its shape's index among its own plus `first`.
  virtual void appendFaceContacts(const Model& /*model*/, const NodeArray& /*start*/, const NodeArray& /*end*/,
                                  double /*h*/, double /*margin*/, int /*first*/,
                                  std::vector<FaceContact>& /*found*/) const
  {
  }
  /// How many shapes it has (ContactStage numbers every kind's shapes in turn).
  virtual std::size_t count() const = 0;
  /// Its shape `shape` received `impulse` [N s] at `point` [m] from a solve (ContactQuery::receive).
  virtual void receive(std::size_t shape, const Vec3& point, const Vec3& impulse) = 0;
  /// At a step's start: the impulses its shapes received are forgotten.
  virtual void clearImpulses() = 0;
  /// Appends, per named shape in its order, the impulses received since clearImpulses as a mean wrench
  /// over dt [s] (ColliderWrench).
  virtual void appendWrenches(double dt, std::vector<ColliderWrench>& wrenches) const = 0;
  /// Appends the current pose of each of its drawable shapes (planes are infinite: none).
  virtual void appendPoses(std::vector<ColliderPose>& /*poses*/) const {}
  /// Moves its shape `name` to `goal` over the next dt [s] at constant linear and angular velocity (its
  /// velocities for friction); nullopt: it holds still. False if it has no shape of that name.
  virtual bool setGoal(const std::string& /*name*/, const std::optional<RigidPose>& /*goal*/, double /*dt*/)
  {
    return false;
  }
  /// At a step's end: the shapes that had a goal sit exactly on it.
  virtual void land() {}
};

/// The kinds of collider that `model` declares, in the order they resolve. Throws std::invalid_argument
/// on a collider that its kind rejects.
std::vector<std::unique_ptr<ColliderKind>> makeColliderKinds(const Model& model);

class ContactStage final : public ContactQuery
{
public:
  explicit ContactStage(const Model& model) : kinds_(makeColliderKinds(model))
  {
    std::size_t first = 0;
    for (const std::unique_ptr<ColliderKind>& kind : kinds_)
    {
      first_.push_back(first);
      first += kind->count();
    }
  }
  /// Each kind cloned: its shapes where they are now, with their goals; the paths are shared (a caller's
  /// function of time; World's copy).
  ContactStage(const ContactStage& other)
    : first_(other.first_), dt_(other.dt_), start_(other.start_), paths_(other.paths_)
  {
    for (const std::unique_ptr<ColliderKind>& kind : other.kinds_)
      kinds_.push_back(kind->clone());
  }
  ContactStage(ContactStage&&) = default;
  ContactStage& operator=(ContactStage&&) = default;
  ContactStage& operator=(const ContactStage& other) { return *this = ContactStage(other); }

  /// What the integrators' solves may ask and tell (null without colliders: they pay nothing).
  ContactQuery* query() { return kinds_.empty() ? nullptr : this; }

  /// The deepest contact over every kind; its `collider` numbers the kinds' shapes in turn.
  bool touching(const Model& model, int node, const Vec3& x, double margin, NodeContact& contact) const override
  {
    bool found = false;
    NodeContact candidate;
    for (std::size_t k = 0; k < kinds_.size(); ++k)
      if (kinds_[k]->touching(model, node, x, margin, candidate) && (!found || candidate.depth > contact.depth))
      {
        contact = candidate;
        contact.collider += static_cast<int>(first_[k]);
        found = true;
      }
    return found;
  }

  void touchingFaces(const Model& model, const NodeArray& start, const NodeArray& end, double h, double margin,
                     std::vector<FaceContact>& found) const override
  {
    found.clear();
    for (std::size_t k = 0; k < kinds_.size(); ++k)
      kinds_[k]->appendFaceContacts(model, start, end, h, margin, static_cast<int>(first_[k]), found);
  }

  void receive(const NodeContact& contact, const Vec3& point, const Vec3& impulse) override
  {
    if (contact.collider < 0)
      return;
    const auto collider = static_cast<std::size_t>(contact.collider);
    for (std::size_t k = kinds_.size(); k-- > 0;)
      if (collider >= first_[k])
      {
        kinds_[k]->receive(collider - first_[k], point, impulse);
        return;
      }
  }

  /// At a step's start, for a step of dt [s]: the colliders' impulses start from zero.
  void beginStep(double dt)
  {
    dt_ = dt;
    for (const std::unique_ptr<ColliderKind>& kind : kinds_)
      kind->clearImpulses();
  }

  /// Per named collider (planes, spheres, capsules, boxes, cylinders, meshes, each in declaration order),
  /// the mean wrench the bodies exerted on it over the last step (ColliderWrench); zero before the first.
  std::vector<ColliderWrench> wrenches() const
  {
    std::vector<ColliderWrench> wrenches;
    for (const std::unique_ptr<ColliderKind>& kind : kinds_)
      kind->appendWrenches(dt_, wrenches);
    return wrenches;
  }

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

  /// Moves collider `name` to `goal` over the next dt [s]; false if there is none of that name.
  bool setGoal(const std::string& name, const std::optional<RigidPose>& goal, double dt)
  {
    for (const std::unique_ptr<ColliderKind>& kind : kinds_)
      if (kind->setGoal(name, goal, dt))
        return true;
    return false;
  }

  /// Collider `name` follows `path` from the next step on (setGoal to path(t) at every step's end time
  /// t); false if there is none of that name.
  bool followPath(const std::string& name, ColliderPath path)
  {
    if (!setGoal(name, std::nullopt, 1.0))
      return false;
    paths_.emplace_back(name, std::move(path));
    return true;
  }

  /// At a step's start: every collider with a path heads for where it will be at `end_time` [s].
  void goalsFromPaths(double end_time, double dt)
  {
    for (const auto& [name, path] : paths_)
      setGoal(name, path(end_time), dt);
  }

  /// At a step's end: every collider that had a goal sits on it.
  void land()
  {
    for (const std::unique_ptr<ColliderKind>& kind : kinds_)
      kind->land();
  }

  /// Writes or reads what a copy copies but the paths (functions, not state: read, this stage keeps its
  /// own) and what the scene fixes (the kinds and their shapes' numbering).
  void carry(StateArchive& archive)
  {
    archive(dt_, start_);
    for (const std::unique_ptr<ColliderKind>& kind : kinds_)
      kind->carry(archive);
  }

private:
  std::vector<std::unique_ptr<ColliderKind>> kinds_;
  std::vector<std::size_t> first_;  ///< per kind: the number of its first shape (NodeContact::collider)
  double dt_ = 1.0;                 ///< [s] the step the impulses were received in
  NodeArray start_;  ///< positions before the current sub-step's integration [m]
  std::vector<std::pair<std::string, ColliderPath>> paths_;
};

}  // namespace soft_body_sim
