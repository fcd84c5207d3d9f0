// The tetrahedral meshes of a soft solid (the coming `type: volume` body): a box, a sphere or a closed
// triangle surface filled with tetrahedra by TetGen's quality mesher, run as a separate program
// (volume_mesh.cpp says why). Every mesh is centred where its shape is (the box and the sphere at the
// origin, a surface in its own frame); the caller moves it into place.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "soft_body_sim/core/contact/mesh_field.h"

namespace soft_body_sim
{
/// A tetrahedral mesh and its boundary.
struct TetMesh
{
  std::vector<Eigen::Vector3d> nodes;  ///< [m]
  /// Node indices (a, b, c, d), positively oriented: (b - a) x (c - a) . (d - a) > 0.
  std::vector<std::array<int, 4>> tets;
  /// The faces that belong to exactly one tetrahedron, counter-clockwise seen from outside (their
  /// normals (b - a) x (c - a) point out of the solid).
  std::vector<std::array<int, 3>> surface;
};

/// V = (b - a) x (c - a) . (d - a) / 6 [m^3]: the signed volume of the tetrahedron (a, b, c, d), > 0
/// when d lies on the side of the triangle (a, b, c) that its normal (b - a) x (c - a) points to.
double tetVolume(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                 const Eigen::Vector3d& d);

/// The sum of the signed volumes of `mesh`'s tetrahedra [m^3].
double meshVolume(const TetMesh& mesh);

/// V = sum over triangles (a, b, c) of a . (b x c) / 6 [m^3]: the volume a closed, consistently
/// oriented surface encloses by the divergence theorem, > 0 when its triangles face outward.
double enclosedVolume(const TriangleMesh& surface);

/// The most tetrahedra a mesh may be asked for (the default of each mesher's max_tetrahedra):
/// kTetsPerMaxVolume V / v_max, estimated before meshing from the shape's volume V [m^3] and the volume
/// bound v_max = resolution^3 / (2 sqrt 2) [m^3] that the mesh is made with, may not exceed it; a finer
/// resolution is refused.
constexpr double kMaxTetrahedra = 2.0e6;
/// Tetrahedra per v_max of volume in TetGen's quality meshes: measured 2.0 to 3.5 on boxes, spheres and
/// config/meshes/part.stl at 10 to 40 tetrahedra across, the regime of any mesh near the limit, so the
/// estimate errs high. (A mesh a few tetrahedra across has more, up to 12: its surface's layer of
/// smaller tetrahedra counts.)
constexpr double kTetsPerMaxVolume = 3.5;

/// Every mesh below is TetGen's quality mesh (-pq1.414a<v_max>): no tetrahedron larger than v_max =
/// resolution^3 / (2 sqrt 2) [m^3], three regular tetrahedra of edge `resolution`, which makes the mean
/// edge about `resolution` [m] (measured 0.8 to 1.25 of it at 10 or more tetrahedra across; 0.62 on a
/// sphere 4 across, where the surface's smaller tetrahedra weigh more). TetGen's Delaunay refinement
/// bounds the radius-edge ratio (circumradius over shortest edge) by sqrt 2; its optimisation after
/// refinement (flips and smoothing, which remove slivers) moves that a little for the tetrahedra with no
/// node on the surface (measured up to 1.45, 2.6 % over), and more for those at a curved surface (1.7 on
/// spheres) or a concave edge (3.8 on part.stl), where TetGen splits the surface's triangles only so far.
/// Each throws std::runtime_error when the tetgen program is not on PATH (install the Debian package
/// tetgen) or fails. Meshing takes seconds when fine (measured: 1 s for a sphere's 36,000 tetrahedra,
/// 3.4 s for a box's 350,000), so a mesh near kMaxTetrahedra takes tens of seconds.

/// The box of full extents `size` [m] (x, y, z) about the origin. Its six faces are flat, so the
/// tetrahedra fill it exactly. Throws DefinitionError (keys "size", "resolution") when a component of
/// `size` or `resolution` is not > 0, or the mesh would exceed max_tetrahedra.
TetMesh meshBox(const Eigen::Vector3d& size, double resolution, double max_tetrahedra = kMaxTetrahedra);

/// The ball of `radius` r [m] about the origin, meshed inside a geodesic polyhedron inscribed in its
/// sphere: an icosahedron (edge a = r / sin(2 pi / 5) = 1.0515 r) whose edges are split into
/// n = ceil(a / resolution) parts and faces into n^2 triangles, every point projected to the sphere, so
/// that its surface edges are a / n <= resolution to 1.26 a / n long. Its volume is the polyhedron's,
/// below 4/3 pi r^3 by the caps its flat triangles cut off: a relative deficit of order (resolution / r)^2,
/// at most 0.51 (resolution / r)^2 for every n (0.357 at n = 1, 0.458 at 2, 0.497 at 6, 0.502 at 20 and
/// 40, computed for the resolution a / n; a coarser resolution with the same n has the same deficit).
/// Throws DefinitionError (keys "radius", "resolution") when either is not > 0 or the mesh would exceed
/// max_tetrahedra.
TetMesh meshSphere(double radius, double resolution, double max_tetrahedra = kMaxTetrahedra);

/// The solid that the closed triangle `surface` [m] bounds, in the surface's frame. The surface's own
/// vertices stay nodes of the mesh; TetGen may add nodes on its triangles. Its triangles may face all
/// outward or all inward. Throws DefinitionError (keys "mesh", "resolution")
/// when `resolution` is not > 0, the surface is open (an edge not shared by exactly two triangles),
/// inconsistently oriented (two triangles run a shared edge the same way), intersects itself (TetGen -d),
/// has a shell inside another (a cavity: TetGen would fill it) or shells facing different ways (then
/// the tetrahedra's volume differs from the surface's enclosedVolume by over 1e-9 of it), or the mesh
/// would exceed max_tetrahedra; the message names the edge or triangle at fault.
TetMesh meshSurface(const TriangleMesh& surface, double resolution, double max_tetrahedra = kMaxTetrahedra);

}  // namespace soft_body_sim
