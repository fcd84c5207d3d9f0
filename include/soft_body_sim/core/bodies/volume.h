// A soft solid (a `type: volume` body): a box, a ball or a closed surface filled with tetrahedra
// (volume_mesh.h) of a neo-Hookean material given by Young's modulus and Poisson's ratio (tetrahedra.h).
// Its nodes are its contact points; its boundary triangles are kept for drawing and contact.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "soft_body_sim/core/meshing/volume_mesh.h"
#include "soft_body_sim/core/contact/mesh_field.h"
#include "soft_body_sim/core/scene_def.h"

namespace soft_body_sim
{
/// What a volume is filled from.
enum class VolumeShape
{
  Box,     ///< `size`: the box about `position`
  Sphere,  ///< `radius`: the ball about `position` (its inscribed geodesic polyhedron)
  Mesh,    ///< `surface`: a closed triangle surface in its own frame, that frame's origin at `position`
};

/// The most surface samples a volume may have: a finer `surface_samples` is refused.
constexpr double kMaxSurfaceSamples = 1.0e6;

struct VolumeDef
{
  VolumeShape shape = VolumeShape::Box;
  std::optional<Vec3> size;        ///< box only, required there: full extents (x, y, z) [m], each > 0
  std::optional<double> radius;    ///< sphere only, required there [m] > 0
  /// mesh only, required there: the closed surface [m] (meshSurface says which surfaces it fills).
  TriangleMesh surface;
  std::string mesh;                ///< the URI `surface` was read from, for messages (mesh only; may be empty)
  double resolution = 0.01;        ///< [m] > 0: the target edge length of the tetrahedra
  Vec3 position = Vec3::Zero();    ///< [m] the box's or ball's centre, or the surface's origin; finite
  double youngs_modulus = 5.0e4;   ///< E [Pa] > 0
  double poisson_ratio = 0.3;      ///< nu [-] in [0, 0.5); 0.5 (incompressible) has no finite lambda
  double density = 100.0;          ///< rho [kg/m^3] > 0
  std::vector<std::string> pinned_faces;  ///< box only: every node on these faces is pinned: x_min,
                                          ///< x_max, y_min, y_max, z_min, z_max
  std::vector<int> pinned_nodes;   ///< node indices (negative from the end) pinned
  /// Coulomb coefficient [-] >= 0 of its surface against other bodies' nodes (surface_contacts.h; two
  /// volumes touching use the mean of theirs).
  double friction = 0.0;
  /// [Pa] the rest pressure p0 of the gas each tetrahedron holds (tetrahedra.h), >= 0; 0: no gas.
  double pressure = 0.0;
  /// [m] >= 0: the spacing of the points of its boundary triangles that meet the colliders besides its
  /// nodes (Model::surface_samples), held inside implicit_euler's solve: a rod or an edge thinner than the
  /// tetrahedra presses the surface in where it touches, instead of slicing in between the nodes; about the
  /// thinnest collider's radius. 0 (the default): its nodes alone meet the colliders.
  double surface_samples = 0.0;
  /// The most tetrahedra its mesh may be asked for (volume_mesh.h): a finer resolution is refused.
  double max_tetrahedra = kMaxTetrahedra;
};

/// The volume as nodes (mesh node + position) and tetrahedra of its material (lameParameters(E, nu)),
/// with its boundary triangles (`surface`), type "volume", contact radius 0. Masses are lumped: each
/// tetrahedron gives rho V / 4 to each of its four nodes, so the body weighs rho times the mesh's volume.
/// Throws DefinitionError naming the keys on a bad definition (the mesher's errors too, prefixed with the
/// body).
BodyDef buildVolume(const std::string& name, const VolumeDef& volume);

}  // namespace soft_body_sim
