// A mesh collider's signed distance field, by OpenVDB (mesh_field.h). The only file that includes
// OpenVDB's headers.
#include "soft_body_sim/core/contact/mesh_field.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <stdexcept>

#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>

namespace soft_body_sim
{
struct MeshField::Grid
{
  openvdb::FloatGrid::ConstPtr grid;
};

double defaultVoxelSize(const TriangleMesh& mesh) { return (mesh.upper() - mesh.lower()).maxCoeff() / kDefaultVoxelsPerExtent; }

double fieldVoxelSize(const Mesh& mesh)
{
  return mesh.voxel_size > 0.0 ? mesh.voxel_size : defaultVoxelSize(*mesh.triangles);
}

double fieldVoxels(const TriangleMesh& mesh, double voxel, double band)
{
  const Eigen::Vector3d extent = mesh.upper() - mesh.lower() + Eigen::Vector3d::Constant(2.0 * band);
  return ((extent / voxel).array().floor() + 1.0).prod();
}

MeshField::MeshField(const TriangleMesh& mesh, double voxel, double exterior_band) : voxel_(voxel)
{
  if (!(voxel > 0.0 && std::isfinite(voxel)) || !(exterior_band > 0.0 && std::isfinite(exterior_band)))
    throw std::invalid_argument("MeshField: the voxel size and the exterior band must be > 0");
  if (mesh.triangles.empty())
    throw std::invalid_argument("MeshField: the mesh has no triangle");
  // OpenVDB registers its grid types once per process; only a scene with a mesh pays for it.
  static std::once_flag initialized;
  std::call_once(initialized, [] { openvdb::initialize(); });

  std::vector<openvdb::Vec3s> points;
  points.reserve(mesh.vertices.size());
  for (const Eigen::Vector3d& v : mesh.vertices)
    points.emplace_back(static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z()));
  std::vector<openvdb::Vec3I> triangles;
  triangles.reserve(mesh.triangles.size());
  for (const Eigen::Vector3i& t : mesh.triangles)
    triangles.emplace_back(static_cast<openvdb::Index32>(t.x()), static_cast<openvdb::Index32>(t.y()),
                           static_cast<openvdb::Index32>(t.z()));
  // Voxel centres at integer multiples of `voxel` in the mesh's frame. Outside: the band, plus a voxel
  // so that every corner a query within the band interpolates holds a distance. Inside: all of it.
  const openvdb::math::Transform::Ptr transform = openvdb::math::Transform::createLinearTransform(voxel);
  const float exterior_voxels = static_cast<float>(std::ceil(exterior_band / voxel) + 1.0);
  grid_ = std::make_unique<const Grid>(Grid{ openvdb::tools::meshToSignedDistanceField<openvdb::FloatGrid>(
      *transform, points, triangles, std::vector<openvdb::Vec4I>(), exterior_voxels,
      std::numeric_limits<float>::max()) });
  band_ = exterior_band;
}

MeshField::~MeshField() = default;

std::size_t MeshField::activeVoxels() const { return static_cast<std::size_t>(grid_->grid->activeVoxelCount()); }

SurfaceDistance MeshField::distance(const Eigen::Vector3d& local) const
{
  // Trilinear interpolation of the 8 voxel centres around the point, and the gradient of that
  // interpolant: phi = sum_c w_c phi_c with w_c = prod over the axes of (f or 1 - f).
  const Eigen::Vector3d q = local / voxel_;
  const Eigen::Vector3d base = q.array().floor();
  const Eigen::Vector3d f = q - base;
  const openvdb::Coord origin(static_cast<openvdb::Int32>(base.x()), static_cast<openvdb::Int32>(base.y()),
                              static_cast<openvdb::Int32>(base.z()));
  // Not registered with the tree (the grid never changes after it is built): no locking per query.
  openvdb::tree::ValueAccessor<const openvdb::FloatTree, false> accessor(grid_->grid->tree());
  double v[2][2][2];
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k)
        v[i][j][k] = accessor.getValue(origin.offsetBy(i, j, k));
  const double fx = f.x(), fy = f.y(), fz = f.z(), gx = 1.0 - fx, gy = 1.0 - fy, gz = 1.0 - fz;
  const double value = gx * (gy * (gz * v[0][0][0] + fz * v[0][0][1]) + fy * (gz * v[0][1][0] + fz * v[0][1][1])) +
                       fx * (gy * (gz * v[1][0][0] + fz * v[1][0][1]) + fy * (gz * v[1][1][0] + fz * v[1][1][1]));
  const Eigen::Vector3d gradient(
      gy * gz * (v[1][0][0] - v[0][0][0]) + fy * gz * (v[1][1][0] - v[0][1][0]) + gy * fz * (v[1][0][1] - v[0][0][1]) +
          fy * fz * (v[1][1][1] - v[0][1][1]),
      gx * gz * (v[0][1][0] - v[0][0][0]) + fx * gz * (v[1][1][0] - v[1][0][0]) + gx * fz * (v[0][1][1] - v[0][0][1]) +
          fx * fz * (v[1][1][1] - v[1][0][1]),
      gx * gy * (v[0][0][1] - v[0][0][0]) + fx * gy * (v[1][0][1] - v[1][0][0]) + gx * fy * (v[0][1][1] - v[0][1][0]) +
          fx * fy * (v[1][1][1] - v[1][1][0]));
  SurfaceDistance s;
  const double length = gradient.norm();
  if (value >= band_ || !(length > 1e-12))
  {
    // Beyond the band (or on a ridge of the field, where no direction is preferred): far, pointing away
    // from the mesh's origin.
    const double r = local.norm();
    s.normal = r > 0.0 ? Eigen::Vector3d(local / r) : Eigen::Vector3d::UnitZ();
    s.distance = value >= band_ ? band_ : value;
  }
  else
  {
    s.normal = gradient / length;
    s.distance = value;
  }
  s.closest = local - s.distance * s.normal;
  return s;
}

void buildMeshFields(std::vector<Mesh>& meshes, double contact_radius)
{
  for (Mesh& mesh : meshes)
  {
    checkCollider(mesh);
    const double voxel = fieldVoxelSize(mesh);
    // Three voxels at least (OpenVDB's usual narrow band), and the largest contact radius with two to spare:
    // a node's contact is then always within the band.
    const double band = std::max(3.0 * voxel, contact_radius + 2.0 * voxel);
    if (!mesh.field || mesh.field->voxelSize() != voxel || mesh.field->exteriorBand() < band)
      mesh.field = std::make_shared<const MeshField>(*mesh.triangles, voxel, band);
  }
}

}  // namespace soft_body_sim
