// A scene as plain structs with defaults: what the YAML loader fills and what tests build directly.
// ROS-free and YAML-free; buildWorld() turns it into a running World.
#pragma once

#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "soft_body_sim/core/bodies/controller.h"
#include "soft_body_sim/core/definition_error.h"
#include "soft_body_sim/core/guard.h"
#include "soft_body_sim/core/integrators/integrator.h"
#include "soft_body_sim/core/model.h"
#include "soft_body_sim/core/sensing/camera_def.h"
#include "soft_body_sim/core/world.h"

namespace soft_body_sim
{
struct NodeDef
{
  Vec3 position = Vec3::Zero();  ///< [m]
  double mass = 1.0;             ///< [kg], > 0
  Vec3 velocity = Vec3::Zero();  ///< [m/s]
  bool pinned = false;           ///< pinned nodes have inverse mass 0
};

struct SpringDef
{
  int a = 0;  ///< node index within the body
  int b = 0;
  double stiffness = 0.0;                ///< [N/m], > 0
  double damping = 0.0;                  ///< [N s/m], >= 0
  std::optional<double> rest_length;     ///< [m]; default: the initial distance
};

struct ConstraintDef
{
  int a = 0;  ///< node index within the body
  int b = 0;
  double compliance = 0.0;               ///< [m/N], >= 0 (0 = inextensible)
  std::optional<double> rest_length;     ///< [m]; default: the initial distance
};

/// A gas-filled quadrilateral cell (see PressureCell): four node indices within the body,
/// counter-clockwise about `normal`.
struct CellDef
{
  int nodes[4] = { 0, 0, 0, 0 };
  Vec3 normal = Vec3::UnitZ();         ///< normal of the cell's plane (need not be unit)
  double pressure = 0.0;               ///< rest pressure p0 [N/m], > 0
  std::optional<double> rest_area;     ///< [m^2], > 0; default: the initial signed area
};

/// A named node that the caller moves (World::moveAnchor); the node is pinned.
struct AnchorDef
{
  AnchorDef() = default;
  AnchorDef(std::string name_, int node_, std::string frame_ = {})
    : name(std::move(name_)), node(node_), frame(std::move(frame_))
  {
  }

  std::string name;
  int node = 0;       ///< node index within the body
  std::string frame;  ///< a tf frame whose origin the ROS node makes it follow; empty = its pose topic
};

/// Any body, as nodes, springs and constraints. Generated body types (rope, cloth, ...) expand into
/// this form; procedurally animated ones add a controller that drives their pinned nodes.
struct BodyDef
{
  std::string name;
  /// "custom": the body is its own definition, which buildWorld checks; else the body type whose builder
  /// (buildRope, ...) made it from a definition of its own and checked that.
  std::string type = "custom";
  std::vector<NodeDef> nodes;
  std::vector<SpringDef> springs;
  std::vector<ConstraintDef> constraints;
  std::vector<CellDef> cells;  ///< pressure cells (jelly); usually empty
  std::vector<AnchorDef> anchors;
  ControllerFactory controller;  ///< empty for passive bodies
  double contact_radius = 0.0;   ///< [m] >= 0: how far its nodes keep from colliders (0 = points)
  /// Pairs of node indices within the body whose segment collides as a whole (a rope's links), not
  /// only at its ends.
  std::vector<std::pair<int, int>> contact_segments;
  /// Triangles of node indices within the body that collide with colliders over their faces and edges
  /// (a cloth's two per grid square), not only at their corners.
  std::vector<std::array<int, 3>> contact_triangles;
  /// Its contact segments (or, without any, its nodes as balls) keep apart from each other and from
  /// those of other such bodies (self_contacts.h); needs contact_radius > 0.
  bool self_collision = false;
  /// Coulomb coefficient [-] >= 0 between its contact segments and those they touch (self_collision;
  /// two bodies touching each other use the mean of theirs).
  double self_friction = 0.0;
  /// With self_collision: its springs too are capsules of its contact radius, which its own nodes stay
  /// out of (a jelly: no node crosses a spring).
  bool springs_collide = false;
  /// A rod's bending and twisting over all its nodes in order (a `type: rod` body, bodies/rod.h), its
  /// first node 0 of the body; empty for every other body.
  std::optional<Rod> rod;
  /// A solid's tetrahedra (a `type: volume` body, bodies/volume.h), their nodes indices within the body;
  /// empty for every other body.
  std::vector<Tetrahedron> tetrahedra;
  /// A solid's boundary triangles, node indices within the body, counter-clockwise seen from outside
  /// (BodyRange::surface).
  std::vector<std::array<int, 3>> surface;
  /// A solid's Coulomb coefficient [-] >= 0 against the other bodies' nodes on its surface
  /// (BodyRange::surface_friction; a volume's `friction`).
  double surface_friction = 0.0;
  /// Model::surface_samples, in the body's node indices (a volume's surface_samples); empty: none.
  std::vector<SurfaceSample> surface_samples;
  /// Triangles of node indices within the body that a camera sees (a cloth's or a jelly's grid, two per
  /// square); empty: it is seen by its surface, its contact segments or its links (Look).
  std::vector<std::array<int, 3>> faces;
  /// rgb in [0, 1] (`color`); none: defaultBodyColor.
  std::optional<Vec3> color;
};

/// The checks of a body's self-contact keys, for the builder of its type (rope, rod, cloth, jelly) or, for a
/// custom body, buildWorld: self_friction >= 0 and only with self_collision, and self_collision only with a
/// contact radius > 0 (the key `radius_key`). Throws DefinitionError naming the keys.
void requireSelfContact(const std::string& what, bool self_collision, double self_friction, double contact_radius,
                        const std::string& radius_key);

struct PhysicsDef
{
  IntegratorType integrator = IntegratorType::SemiImplicitEuler;
  StepSettings step;                        ///< dt [s], substeps, iterations
  /// `dt: auto`: buildWorld replaces step.dt and step.substeps by chooseStableStep's (stability.h), with
  /// more sub-steps where the rule against passing through needs them (tunnellingRisk).
  bool auto_dt = false;
  Vec3 gravity = Vec3(0.0, 0.0, -9.81);     ///< [m/s^2]
  double drag = 0.0;                        ///< [1/s]
  GuardSettings guard;                      ///< what the divergence guard does (guard.h)
};

/// `robot_colliders:`: every <collision> of the URDF on a ROS parameter becomes a collider following its
/// link's tf frame (read by the ROS node: robot_colliders.h).
struct RobotCollidersDef
{
  std::string param = "robot_description";  ///< the parameter holding the URDF (resolved as a global name)
  double friction = 0.0;                     ///< Coulomb coefficient [-] of every such collider, >= 0
  double restitution = 0.0;                  ///< [0, 1]
};

struct SceneDef
{
  std::string frame_id = "world";  ///< fixed frame of the simulation
  double rate = 60.0;              ///< [Hz] at which the ROS node advances and publishes, > 0
  PhysicsDef physics;
  Colliders colliders;  ///< what every body collides with (colliders.h)
  std::optional<RobotCollidersDef> robot_colliders;  ///< more colliders from a URDF (ROS node only)
  std::vector<CameraDef> cameras;  ///< simulated RGB-D cameras (sensing/depth_camera.h); usually none
  std::vector<BodyDef> bodies;
};

/// The most nodes a scene may have, in all its bodies: a typo such as `nx: 100000` or
/// `segments: 1e9` fails with a message rather than exhausting memory.
constexpr long long kMaxSceneNodes = 1000000;

/// A node index of a body of `node_count` nodes made non-negative: a negative one counts from the end
/// (-1 is the last node). Throws std::out_of_range if it is outside the body.
int resolveNodeIndex(long long index, int node_count);

/// The largest contact radius [m] of the scene's bodies (0 without any): how far outside a mesh collider's
/// distance field must reach (buildMeshFields).
double maxContactRadius(const SceneDef& scene);

/// The rule against passing through (self_contacts.h), for the step `step`: each self-colliding body's
/// parts move at most its contact radius r per sub-step h at the speed they can meet at,
///   v = sqrt(2 |g| H) + the fastest of its nodes' initial speeds,
/// H the fall from its highest free (not pinned or anchored) node down to the first plane below it that faces up
/// (kUnsupportedFall if there is none). At that speed two parts come at most r closer in a sub-step, so
/// neither gets past the middle of their contact distance 2 r unseen, and the contact pushes it back the
/// way it came. A body that its anchors or a collider move faster is beyond the rule.
struct TunnellingRisk
{
  std::size_t body = 0;  ///< index in SceneDef::bodies
  int substeps = 1;      ///< the sub-steps at step.dt that keep the rule
  std::string why;       ///< the message: the body, the fall, the speed, the sub-steps it needs
};
/// The fall [m] the rule assumes for a body with no plane below it.
constexpr double kUnsupportedFall = 2.0;
/// The first body that breaks the rule at `step`, if any.
std::optional<TunnellingRisk> tunnellingRisk(const SceneDef& scene, const StepSettings& step);

/// Flattens the bodies into one node array (body k's nodes follow body k-1's), pins anchored nodes,
/// makes the controllers and returns the world. Expects a valid scene (the loader checks, and each
/// generated body's builder); throws std::invalid_argument on an index out of range, a bad collider (a zero
/// plane normal), a zero cell normal, a cell whose rest area is not positive and, in a custom body, a cell
/// whose pressure is not positive or self-contact keys that requireSelfContact refuses. With `dt: auto` it
/// also takes the sub-steps that the rule against passing through needs (tunnellingRisk); a fixed step is
/// the loader's to check.
World buildWorld(const SceneDef& scene);

}  // namespace soft_body_sim
