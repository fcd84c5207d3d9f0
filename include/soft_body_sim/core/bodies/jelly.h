// Jelly (springy-viscous-jelly.txt): a square of equal-mass nodes joined by damped springs along the
// edges and both diagonals of every cell, each cell filled with gas whose pressure resists its
// collapse. Gravity, air resistance (physics.drag) and the bounce off walls and floors (planes) come
// from the scene. The seed's three failures and what replaces its mechanisms:
//  1. nodes crossing springs, cells collapsing: the seed's pressure (push out from the centroid,
//     proportional to the change of that distance) has no energy and points anywhere once nodes
//     cross. Here each cell is a gas at Boyle's law, with an energy of its signed area that grows
//     without bound as the cell is squeezed and, past that barrier, still pushes an inverted cell
//     back (CellGas in forces.h); every integrator treats it (forces, implicit_euler's Jacobian, xpbd's
//     area constraint). The gas does not hold a jelly that a collider presses flat; with
//     self_collision its nodes stay out of its springs (self_contacts.h).
//  2. jitter at the walls: the seed reverses a node's velocity at every contact, so the weight of the
//     structure drives the bottom nodes to vibrate. Plane contacts here remove the normal approach
//     and do not bounce below a resting speed (restingSpeed). A jelly's floor should have restitution
//     0: the jelly bounces by its own elasticity, and the resting speed (2 g h) only covers a node's own
//     weight, so with restitution > 0 floor nodes carrying the jelly above them would be bounced
//     (in velocity, not in position) at every step.
//  3. damping past c h / m = 1 explodes: it is reported for the explicit integrators
//     (stabilityWarnings in stability.h); implicit_euler and xpbd are stable there.
#pragma once

#include <string>

#include "soft_body_sim/core/bodies/cloth.h"

namespace soft_body_sim
{
struct JellyDef
{
  int nx = 6;                                                ///< cells per row (along the top edge), >= 1
  int ny = 6;                                                ///< cells per column (along the left edge), >= 1
  /// Where the square starts, at rest [m]; (nx + 1) x (ny + 1) nodes numbered as in GridCorners.
  GridCorners corners{ Vec3(-0.2, 0.0, 2.4), Vec3(0.2, 0.0, 2.4), Vec3(-0.2, 0.0, 2.0) };
  double mass = 1.0;                                         ///< total mass [kg], equal per node
  SpringParameters edges{ 2000.0, 1.0 };                     ///< springs along the cells' edges
  SpringParameters diagonals{ 1000.0, 0.5 };                 ///< springs along both diagonals of each cell
  double pressure = 1000.0;                                  ///< each cell's rest gas pressure p0 [N/m], > 0
  double thickness = 0.0;                                    ///< [m] >= 0: contact radius of its nodes
  /// Its nodes (balls of its thickness) stay out of its springs (capsules of its thickness), so that no
  /// node crosses a spring and no cell turns inside out however hard it is squeezed, and keep apart from
  /// other self-colliding bodies (self_contacts.h). Needs 0 < thickness <= a quarter of the distance from
  /// a cell's corner to the diagonal it is not on: the nodes start two contact distances clear of every
  /// spring.
  bool self_collision = false;
  double self_friction = 0.0;                                ///< Coulomb coefficient [-] where it touches, >= 0
  /// Its cells, two triangles each, meet spheres, capsules, boxes, cylinders and meshes over their faces and
  /// edges, not only at its nodes (face_contacts.h, as a cloth's): a rail or finger thinner than a cell does
  /// not pass between its nodes, across its plane or into its outline. Its self-collision stays by nodes and
  /// springs. Off by default, experimental as a cloth's.
  bool face_contacts = false;
};

/// The jelly as nodes, springs and pressure cells (type "jelly"). Each cell's corners run
/// counter-clockwise about the grid's normal (top_right - top_left) x (bottom_left - top_left), so its
/// signed area is positive; cells and springs start at rest. Throws std::invalid_argument on a bad
/// definition.
BodyDef buildJelly(const std::string& name, const JellyDef& jelly);

}  // namespace soft_body_sim
