// A mesh collider's geometry: its triangles, read from a file by assimp (mesh_file.cpp), and the signed
// distance field that contact queries, built from them by OpenVDB (mesh_field.cpp). OpenVDB's headers
// stay inside mesh_field.cpp: they are slow to compile, and no other file needs them.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "soft_body_sim/core/contact/colliders.h"

namespace soft_body_sim
{
/// A closed triangle mesh in its own frame [m].
struct TriangleMesh
{
  std::vector<Eigen::Vector3d> vertices;   ///< [m]
  std::vector<Eigen::Vector3i> triangles;  ///< vertex indices, counter-clockwise seen from outside

  /// The corners of its axis-aligned bounding box [m] (zero when it has no vertex).
  Eigen::Vector3d lower() const;
  Eigen::Vector3d upper() const;
  /// The radius [m] of the smallest ball about the origin that holds every vertex.
  double boundingRadius() const;
};

/// The triangles of every mesh in the file at `path` (STL, COLLADA, OBJ and the other formats assimp
/// reads), joined in the file's frame with the file's node transforms applied, polygons triangulated,
/// identical vertices merged, and every vertex multiplied by `scale` per axis. Units are the file's,
/// taken as metres. Throws DefinitionError at the key "mesh" naming the path and the reason if the file
/// is not a regular file (a FIFO, a directory, a device: refused by its status, never opened), is larger
/// than kMaxMeshFileBytes (refused before it is read), cannot be read by assimp or holds no triangle.
TriangleMesh readTriangleMesh(const std::string& path, const Eigen::Vector3d& scale);

/// The largest mesh file read [bytes]: 256 MiB. assimp reads a file whole into memory before it parses it,
/// so a larger one (a 3 GB sparse file reads as 3 GB of zeros) would take its size in memory only to be
/// refused. The number is the finest mesh our limits can use, in the most verbose format: a field of
/// kMaxFieldVoxels = 256^3 voxels resolves a closed surface to about one triangle pair per voxel face on
/// its bounding box, 6 256^2 2 ~ 8 10^5 triangles, and ASCII STL spends ~250 bytes on a triangle (a
/// `facet normal` line, `outer loop`, three `vertex` lines, `endloop`, `endfacet`), ~200 MB; binary STL
/// takes 50 bytes a triangle.
constexpr std::uintmax_t kMaxMeshFileBytes = std::uintmax_t{ 256 } << 20;

/// The largest extent [m] of `mesh`'s bounding box, over `kDefaultVoxelsPerExtent`: the voxel size of a
/// mesh collider that sets none.
constexpr double kDefaultVoxelsPerExtent = 100.0;
double defaultVoxelSize(const TriangleMesh& mesh);
/// The voxel size [m] of `mesh`'s field: its voxel_size, or defaultVoxelSize of its triangles for 0.
double fieldVoxelSize(const Mesh& mesh);

/// The most voxels a mesh's field may span over its bounding box (2^24: 64 MB of float distances if
/// the mesh filled it): a finer voxel_size is refused.
constexpr double kMaxFieldVoxels = 16777216.0;

/// The number of voxels of edge `voxel` [m] that span `mesh`'s bounding box widened by `band` [m] on
/// each side.
double fieldVoxels(const TriangleMesh& mesh, double voxel, double band);

/// The signed distance to a closed triangle mesh, sampled on a grid of voxels of edge `voxel` [m]
/// (OpenVDB's meshToSignedDistanceField: exact point-triangle distances at the voxel centres, the sign
/// from a flood fill of the outside). Every voxel inside the mesh holds its distance, so a point pushed
/// deep inside still finds the way out; outside, only voxels within `exterior_band` [m] of the surface
/// do, and any point beyond that is reported at that distance (no contact).
///
/// A query trilinearly interpolates the eight voxels around the point; its gradient there is the normal.
/// The error follows from the sampling: on flat faces the distance is linear and exact to float
/// precision (~1e-7 of the mesh's extent); near an edge or a corner, where the distance bends, the
/// interpolation rounds the shape by up to about half a voxel diagonal (0.87 voxel).
class MeshField
{
public:
  /// Throws std::invalid_argument if `voxel` or `exterior_band` is not > 0 or the mesh has no triangle.
  MeshField(const TriangleMesh& mesh, double voxel, double exterior_band);
  ~MeshField();
  MeshField(const MeshField&) = delete;
  MeshField& operator=(const MeshField&) = delete;

  /// Distance, outward normal and closest surface point of a point in the mesh's frame [m].
  SurfaceDistance distance(const Eigen::Vector3d& local) const;

  double voxelSize() const { return voxel_; }          ///< [m]
  double exteriorBand() const { return band_; }        ///< [m] the farthest distance outside it resolves
  std::size_t activeVoxels() const;                    ///< voxels that hold a distance

private:
  struct Grid;  // the OpenVDB grid, defined in mesh_field.cpp
  std::unique_ptr<const Grid> grid_;
  double voxel_ = 0.0;
  double band_ = 0.0;
};

/// Builds the distance field of each mesh at its voxel_size (0: defaultVoxelSize), unless it has one
/// already that fits, with an exterior band of the largest node `contact_radius` [m] plus two voxels (at
/// least three voxels), so that every contact lies within it. Checks each mesh first (checkCollider).
void buildMeshFields(std::vector<Mesh>& meshes, double contact_radius);

}  // namespace soft_body_sim
