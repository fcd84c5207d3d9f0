// The physical model of a scene: what it *is* (topology, parameters), apart from where it is now.
// Header of the ROS-free core: Eigen and the standard library only.
#pragma once

#include <array>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "soft_body_sim/core/contact/colliders.h"
#include "soft_body_sim/core/state_archive.h"

namespace soft_body_sim
{
/// A point or direction in the scene's fixed frame [m].
using Vec3 = Eigen::Vector3d;
/// One column per node: positions [m], velocities [m/s], accelerations [m/s^2] or forces [N].
using NodeArray = Eigen::Matrix3Xd;

/// Hooke spring with a dashpot on the relative velocity along the spring:
/// F_a = (-k (|d| - rest_length) - c ((v_a - v_b) . u)) u,  F_b = -F_a,  d = x_a - x_b,  u = d / |d|.
struct Spring
{
  int a = 0;
  int b = 0;
  double rest_length = 0.0;  ///< [m]
  double stiffness = 0.0;    ///< k [N/m], > 0
  double damping = 0.0;      ///< c [N s/m], >= 0

  void carry(StateArchive& archive) { archive(a, b, rest_length, stiffness, damping); }
};

/// Distance constraint C = |x_a - x_b| - rest_length, solved by projection (XPBD, Macklin et al. 2016).
/// compliance 0 is inextensible; compliance alpha behaves like a spring of stiffness 1/alpha.
struct DistanceConstraint
{
  int a = 0;
  int b = 0;
  double rest_length = 0.0;  ///< [m]
  double compliance = 0.0;   ///< alpha [m/N], >= 0

  void carry(StateArchive& archive) { archive(a, b, rest_length, compliance); }
};

/// A gas-filled quadrilateral cell of a 2D body (jelly): four nodes, counter-clockwise about `normal`.
/// Its signed area A is that of the outline projected on the plane normal to `normal`, so it is
/// positive at rest and changes sign when the cell turns inside out. The gas follows Boyle's law in an
/// atmosphere of the same rest pressure: net pressure p(A) = pressure (rest_area / A - 1), force
/// F_k = p dA/dx_k, energy pressure rest_area (a - 1 - ln a) with a = A / rest_area (see forces.h).
struct PressureCell
{
  int nodes[4] = { 0, 0, 0, 0 };
  Vec3 normal = Vec3::UnitZ();  ///< unit normal of the cell's plane
  double rest_area = 0.0;       ///< A0 [m^2], > 0
  double pressure = 0.0;        ///< p0 [N/m] (2D pressure: force per length of outline), > 0

  void carry(StateArchive& archive) { archive(nodes, normal, rest_area, pressure); }
};

/// Where a rod is held in position and orientation (rods.h): its nodes first .. last, pinned, and the
/// material frame they hold. A clamped or anchored end is a station of one node; a grasp makes one of
/// the nodes it holds. A station of one node holds the rod's direction there (its frame's x axis) on both
/// sides; a longer one holds it through its nodes' positions. The rod twists between consecutive stations.
struct RodStation
{
  int first = 0;  ///< global index of its first node
  int last = 0;   ///< global index of its last node (first for a station of one node)
  /// The rod's material frame now where it enters the station ([0], toward the rod's first node) and where
  /// it leaves it ([1]): the frames of its first and last segments (equal for a station of one node).
  Eigen::Quaterniond frame[2] = { Eigen::Quaterniond::Identity(), Eigen::Quaterniond::Identity() };
  /// The same frames in the frame of whatever holds the station (a grasp's frame, an anchor's turn): when
  /// it turns by q, frame[c] = q * held[c].
  Eigen::Quaterniond held[2] = { Eigen::Quaterniond::Identity(), Eigen::Quaterniond::Identity() };

  void carry(StateArchive& archive) { archive(first, last, frame, held); }

  /// The holder is at orientation q now (unit).
  void turn(const Eigen::Quaterniond& q)
  {
    frame[0] = q * held[0];
    frame[1] = q * held[1];
  }
};

/// A rod's bending and twisting (a `type: rod` body; rods.h): a discrete elastic rod (Bergou et al. 2008),
/// isotropic (circular cross-section), straight and untwisted at rest, its nodes first .. first + count - 1
/// in order. Its stretching is springs of Model::springs. Its stations (clamped or anchored ends, grasps)
/// hold positions and orientations; they belong to the caller.
/// Material frames: x along the rod (from its first node to its last), y and z across it.
struct Rod
{
  int first = 0;                     ///< global index of its first node
  int count = 0;                     ///< nodes, >= 2
  double segment_length = 0.0;       ///< l: every segment's rest length [m], > 0
  double bending_stiffness = 0.0;    ///< E I [N m^2], > 0
  double twisting_stiffness = 0.0;   ///< G J [N m^2], > 0
  double damping = 0.0;              ///< beta [s]: stiffness-proportional damping of its bending (Rayleigh)
  Eigen::Quaterniond rest_frame = Eigen::Quaterniond::Identity();  ///< every segment's frame at rest
  /// Its stations in order along it, apart from each other (a grasp never holds a pinned node).
  std::vector<RodStation> stations;
  /// [N m] a constant moment on its last node about fixed world axes (its last end free), applied as the
  /// couple across its last segment: its part along that segment is not (a free end holds no twist).
  Vec3 end_moment = Vec3::Zero();

  void carry(StateArchive& archive)
  {
    archive(first, count, segment_length, bending_stiffness, twisting_stiffness, damping, rest_frame, stations,
            end_moment);
  }

  int last() const { return first + count - 1; }
};

/// A tetrahedron of a soft solid (a `type: volume` body; tetrahedra.h): four nodes, positively oriented at
/// rest, of a stable neo-Hookean material (Smith, de Goes and Kim 2018) with Lame parameters mu and lambda:
/// energy rest_volume Psi(F), F = D_s rest_inverse the deformation gradient, D_s = [x1 - x0, x2 - x0, x3 - x0].
struct Tetrahedron
{
  int nodes[4] = { 0, 0, 0, 0 };
  Eigen::Matrix3d rest_inverse = Eigen::Matrix3d::Identity();  ///< D_m^-1: D_s's inverse at rest [1/m]
  double rest_volume = 0.0;  ///< V0 = det(D_m) / 6 [m^3], > 0
  double mu = 0.0;           ///< Lame's second parameter, the shear modulus E / (2 (1 + nu)) [Pa], > 0
  double lambda = 0.0;       ///< Lame's first parameter E nu / ((1 + nu)(1 - 2 nu)) [Pa], >= 0
  double pressure = 0.0;     ///< p0 [Pa] of the gas it holds (tetrahedra.h), >= 0; 0: no gas

  void carry(StateArchive& archive) { archive(nodes, rest_inverse, rest_volume, mu, lambda, pressure); }
};

/// [m] The radius a body without a contact radius is seen with (a camera; rviz draws its nodes as balls of
/// this radius too).
constexpr double kDefaultLookRadius = 0.01;

/// How a body looks to a camera (sensing/depth_camera.h): round tubes between node pairs and triangles
/// between nodes, in its colour; a node in neither is a ball. buildWorld derives it: a body type's faces
/// (a cloth's or jelly's grid, BodyDef::faces; a solid's surface), else its contact segments (a rope's,
/// a rod's links), else its springs and constraints.
struct Look
{
  std::vector<std::pair<int, int>> tubes;  ///< global node index pairs
  std::vector<std::array<int, 3>> faces;   ///< global node indices, seen from both sides
  std::vector<int> balls;                  ///< nodes in no tube or face
  double radius = kDefaultLookRadius;      ///< [m] of its tubes and balls: its contact radius if it has one
  Eigen::Vector3d color = Eigen::Vector3d::Constant(0.6);  ///< rgb in [0, 1]

  void carry(StateArchive& archive) { archive(tubes, faces, balls, radius, color); }
};

/// The colour of body `body` (its index in the scene) when the scene gives none: golden-angle hues, distinct
/// and stable, as rviz has always shown them.
Eigen::Vector3d defaultBodyColor(std::size_t body);

/// A named run of consecutive nodes: the scene's bodies share one node array.
struct BodyRange
{
  std::string name;
  int first = 0;
  int count = 0;
  bool self_collision = false;  ///< its links keep apart by their radii (self_contacts.h)
  /// Coulomb coefficient [-] where its links touch each other or another self-colliding body's
  /// (self_contacts.h)
  double self_friction = 0.0;
  bool springs_collide = false; ///< its springs too keep its own nodes out (a jelly; self_contacts.h)
  /// A solid's boundary (a `type: volume` body): triangles of global node indices, counter-clockwise seen
  /// from outside; empty for every other body.
  std::vector<std::array<int, 3>> surface;
  /// A solid's Coulomb coefficient [-] against the other bodies' nodes on its surface (surface_contacts.h;
  /// two solids use the mean of theirs); 0 for every other body.
  double surface_friction = 0.0;
  Look look;  ///< how a camera and rviz see it

  void carry(StateArchive& archive)
  {
    archive(name, first, count, self_collision, self_friction, springs_collide, surface, surface_friction, look);
  }
};

/// A point of a solid's boundary triangle, at fixed barycentric weights of its three nodes (summing to 1),
/// that meets the colliders besides the nodes themselves (VolumeDef::surface_samples; surface_holds.h).
struct SurfaceSample
{
  std::array<int, 3> triangle;  ///< node indices, counter-clockwise seen from outside
  Vec3 weight;                  ///< of triangle[0], [1], [2]

  void carry(StateArchive& archive) { archive(triangle, weight); }
};

/// A named node of a body that the caller moves kinematically (its node is pinned).
struct Anchor
{
  std::string body;
  std::string name;
  int node = 0;       ///< global node index
  std::string frame;  ///< a tf frame whose origin the ROS node makes it follow; empty = its pose topic

  void carry(StateArchive& archive) { archive(body, name, node, frame); }
};

/// What the scene is (topology and parameters), apart from where it is now (State). Its topology stays
/// fixed while a scene runs; its parameters are the live ones: live tuning (gravity, drag, a body's
/// material scaling) and live pinning (attach, detach, the guard's freeze) rewrite them, while the
/// values the scene was built with stay in MaterialScaling. Pinned node = inverse mass 0: no force moves
/// it; only the caller (an anchor) does.
struct Model
{
  Eigen::VectorXd mass;          ///< [kg] per node (kept for pinned nodes too, for reporting)
  Eigen::VectorXd inverse_mass;  ///< [1/kg] per node, 0 for pinned nodes
  Eigen::VectorXd contact_radius;  ///< [m] per node: how far it keeps from colliders (0 = a point)
  /// Segments that collide along their length (a rope's links), as global node index pairs; their
  /// radius is their nodes' contact radius.
  std::vector<std::pair<int, int>> contact_segments;
  /// Triangles that meet colliders over their faces and edges (a cloth's; face_contacts.h), as global node
  /// indices; their thickness is their nodes' mean contact radius.
  std::vector<std::array<int, 3>> contact_triangles;
  std::vector<Spring> springs;
  std::vector<DistanceConstraint> constraints;
  std::vector<PressureCell> cells;  ///< empty unless a scene has jelly: no pressure pass then
  std::vector<Rod> rods;            ///< empty unless a scene has rods: no bending or twist pass then
  std::vector<Tetrahedron> tetrahedra;  ///< empty unless a scene has volumes: no elasticity pass then
  /// Points of solids' boundary triangles held on the colliders inside implicit_euler's solve, a
  /// triangle's consecutive; empty unless a solid declares surface_samples: no pass then.
  std::vector<SurfaceSample> surface_samples;
  std::vector<BodyRange> bodies;
  Colliders colliders;  ///< as the scene declares them; the contact stage prepares its own copies
  std::vector<Anchor> anchors;
  Vec3 gravity = Vec3(0.0, 0.0, -9.81);  ///< [m/s^2]
  double drag = 0.0;                      ///< linear air drag [1/s]: a -= drag * v on free nodes

  /// Everything but the colliders (the contact stage carries where they are now; the rest the scene fixes).
  void carry(StateArchive& archive)
  {
    archive(mass, inverse_mass, contact_radius, contact_segments, contact_triangles, springs, constraints, cells,
            rods, tetrahedra, surface_samples, bodies, anchors, gravity, drag);
  }

  int nodeCount() const { return static_cast<int>(mass.size()); }
  bool isFree(int i) const { return inverse_mass[i] > 0.0; }
  /// A holder (an attached anchor, a grasp) lets node `node` go: it is free again, inverse mass 1 / mass,
  /// unless its body is `frozen` (the divergence guard pinned it there, and there it stays).
  void releaseNode(int node, bool frozen) { inverse_mass[node] = frozen ? 0.0 : 1.0 / mass[node]; }
  /// Index into `bodies` of the body holding node `node`; throws std::out_of_range if none does.
  std::size_t bodyOf(int node) const
  {
    for (std::size_t b = 0; b < bodies.size(); ++b)
      if (node >= bodies[b].first && node < bodies[b].first + bodies[b].count)
        return b;
    throw std::out_of_range("Model: node " + std::to_string(node) + " belongs to no body");
  }
};

/// Where the scene is now.
struct State
{
  NodeArray position;  ///< [m]
  NodeArray velocity;  ///< [m/s]
  /// [rad] the rods' twists (rods.h): twist[i] is the twist between the rod station whose last node is i
  /// and the next station along its rod, counted on through whole turns; 0 at every other node. One
  /// entry per node when the model has rods, none otherwise.
  Eigen::VectorXd twist;

  void carry(StateArchive& archive) { archive(position, velocity, twist); }
};

/// How a step is taken: the world advances dt per step in `substeps` equal sub-steps.
struct StepSettings
{
  double dt = 0.001;   ///< [s] fixed physics step, > 0
  int substeps = 1;    ///< sub-steps per step, >= 1
  int iterations = 1;  ///< constraint/relaxation iterations (implicit_euler: Newton iterations), >= 1

  void carry(StateArchive& archive) { archive(dt, substeps, iterations); }
};

}  // namespace soft_body_sim
