#include "soft_body_sim/core/bodies/volume.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>

#include "soft_body_sim/core/meshing/volume_mesh.h"
#include "soft_body_sim/core/elements/tetrahedra.h"

namespace soft_body_sim
{
namespace
{
/// A box face by name: the axis it is normal to and the side (-1 the minimum, +1 the maximum).
struct BoxFace
{
  const char* name;
  int axis;
  double side;
};
constexpr BoxFace kBoxFaces[] = { { "x_min", 0, -1.0 }, { "x_max", 0, 1.0 }, { "y_min", 1, -1.0 },
                                  { "y_max", 1, 1.0 },  { "z_min", 2, -1.0 }, { "z_max", 2, 1.0 } };

std::string boxFaceNames()
{
  std::string names;
  for (const BoxFace& face : kBoxFaces)
    names += (names.empty() ? "" : ", ") + std::string(face.name);
  return names;
}

/// Checks that the keys of the shape are given and those of the others are not.
void requireShapeKeys(const VolumeDef& volume, const std::string& what)
{
  const bool box = volume.shape == VolumeShape::Box, sphere = volume.shape == VolumeShape::Sphere,
             mesh = volume.shape == VolumeShape::Mesh;
  const std::string shape = box ? "box" : sphere ? "sphere" : "mesh";
  requireDefinition(!box || volume.size.has_value(), what, { "size", "shape" },
                    "shape box needs size (full extents [m])");
  requireDefinition(!sphere || volume.radius.has_value(), what, { "radius", "shape" }, "shape sphere needs radius [m]");
  requireDefinition(!mesh || !volume.surface.triangles.empty(), what, { "mesh", "shape" },
                    "shape mesh needs mesh (a closed surface file)");
  const auto only = [&](const std::string& key, const std::string& with) {
    return key + " is only for shape " + with + ", not " + shape;
  };
  requireDefinition(box || !volume.size, what, { "size" }, only("size", "box"));
  requireDefinition(sphere || !volume.radius, what, { "radius" }, only("radius", "sphere"));
  requireDefinition(mesh || (volume.surface.triangles.empty() && volume.mesh.empty()), what, { "mesh" },
                    only("mesh", "mesh"));
  requireDefinition(box || volume.pinned_faces.empty(), what, { "pinned" },
                    "a face name in pinned (" + (volume.pinned_faces.empty() ? "" : volume.pinned_faces[0]) +
                        ") is only for shape box, not " + shape + "; pin nodes by index");
}

/// The mesh of the shape about the origin (the surface in its own frame), the mesher's errors prefixed
/// with the body (and the file a surface came from).
TetMesh meshShape(const VolumeDef& volume, const std::string& what)
{
  try
  {
    switch (volume.shape)
    {
      case VolumeShape::Box:
        return meshBox(*volume.size, volume.resolution, volume.max_tetrahedra);
      case VolumeShape::Sphere:
        return meshSphere(*volume.radius, volume.resolution, volume.max_tetrahedra);
      case VolumeShape::Mesh:
        return meshSurface(volume.surface, volume.resolution, volume.max_tetrahedra);
    }
  }
  catch (const DefinitionError& e)
  {
    throw DefinitionError(what + (volume.mesh.empty() ? "" : " (mesh " + volume.mesh + ")") + ": " + e.what(),
                          e.keys());
  }
  throw DefinitionError(what + ": unknown shape", { "shape" });
}

/// The nodes of `mesh` on the face `face` of the box of full extents `size` about the origin.
void pinFace(const TetMesh& mesh, const Vec3& size, const BoxFace& face, BodyDef& body)
{
  // TetGen keeps the box's corners and adds nodes on a face as combinations of nodes on it, so a face's
  // nodes lie in its plane to rounding (and 17 digits through its files); 1e-9 of the box's size keeps
  // every inner node out (a quality mesh has none closer to a face than a fraction of the resolution).
  const double plane = 0.5 * face.side * size[face.axis];
  for (std::size_t k = 0; k < mesh.nodes.size(); ++k)
    if (std::abs(mesh.nodes[k][face.axis] - plane) <= 1e-9 * size[face.axis])
      body.nodes[k].pinned = true;
}

/// The points of `mesh`'s boundary triangles at most `spacing` apart along the longest edge of each at rest:
/// a triangle whose longest edge takes n spacings has the grid of barycentric weights (i, j, n - i - j) / n
/// but its three corners (its nodes meet the colliders themselves). Refuses more than kMaxSurfaceSamples.
std::vector<SurfaceSample> sampleSurface(const TetMesh& mesh, double spacing, const std::string& what)
{
  std::vector<int> divisions;
  double count = 0.0;
  for (const std::array<int, 3>& t : mesh.surface)
  {
    double longest = 0.0;
    for (std::size_t k = 0; k < 3; ++k)
      longest = std::max(longest, (mesh.nodes[static_cast<std::size_t>(t[k])] -
                                   mesh.nodes[static_cast<std::size_t>(t[(k + 1) % 3])]).norm());
    const double n = std::max(1.0, std::ceil(longest / spacing));
    count += 0.5 * (n + 1.0) * (n + 2.0) - 3.0;
    if (!(count <= kMaxSurfaceSamples))
    {
      char message[200];
      std::snprintf(message, sizeof message,
                    "surface_samples %g m lays more than %.0f points on its surface: take a larger spacing (about "
                    "the thinnest collider's radius)",
                    spacing, kMaxSurfaceSamples);
      requireDefinition(false, what, { "surface_samples" }, message);
    }
    divisions.push_back(static_cast<int>(n));
  }
  std::vector<SurfaceSample> samples;
  samples.reserve(static_cast<std::size_t>(count));
  for (std::size_t t = 0; t < mesh.surface.size(); ++t)
  {
    const int n = divisions[t];
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j)
        if (i != n && j != n && i + j != 0)
          samples.push_back({ mesh.surface[t], Vec3(i, j, n - i - j) / static_cast<double>(n) });
  }
  return samples;
}

}  // namespace

BodyDef buildVolume(const std::string& name, const VolumeDef& volume)
{
  const std::string what = "volume '" + name + "'";
  requireShapeKeys(volume, what);
  requireDefinition(volume.resolution > 0.0 && std::isfinite(volume.resolution), what, { "resolution" },
                    "resolution must be > 0 (the target edge length [m])");
  requireDefinition(volume.position.allFinite(), what, { "position" }, "position must be finite [m]");
  requireDefinition(volume.youngs_modulus > 0.0 && std::isfinite(volume.youngs_modulus), what, { "youngs_modulus" },
                    "youngs_modulus must be > 0 [Pa]");
  requireDefinition(volume.poisson_ratio >= 0.0 && volume.poisson_ratio < 0.5, what, { "poisson_ratio" },
                    "poisson_ratio must be in [0, 0.5) (0.5 is incompressible: no finite Lame lambda)");
  requireDefinition(volume.density > 0.0 && std::isfinite(volume.density), what, { "density" },
                    "density must be > 0 [kg/m^3]");
  requireDefinition(volume.friction >= 0.0 && std::isfinite(volume.friction), what, { "friction" },
                    "friction must be >= 0 (a Coulomb coefficient)");
  requireDefinition(volume.pressure >= 0.0 && std::isfinite(volume.pressure), what, { "pressure" },
                    "pressure must be >= 0 [Pa] (the rest pressure of the gas each tetrahedron holds; 0: no gas)");
  requireDefinition(volume.surface_samples >= 0.0 && std::isfinite(volume.surface_samples), what,
                    { "surface_samples" }, "surface_samples must be >= 0 [m] (0: its nodes alone meet the colliders)");
  std::vector<const BoxFace*> faces;
  for (const std::string& face_name : volume.pinned_faces)
  {
    const BoxFace* found = nullptr;
    for (const BoxFace& face : kBoxFaces)
      if (face_name == face.name)
        found = &face;
    requireDefinition(found != nullptr, what, { "pinned" },
                      "unknown face '" + face_name + "' in pinned; a box's faces are " + boxFaceNames());
    faces.push_back(found);
  }

  const TetMesh mesh = meshShape(volume, what);
  const int count = static_cast<int>(mesh.nodes.size());
  BodyDef body;
  body.name = name;
  body.type = "volume";
  body.contact_radius = 0.0;  // its nodes are its contact points
  body.surface_friction = volume.friction;
  for (const Eigen::Vector3d& node : mesh.nodes)
    body.nodes.push_back(NodeDef{ node + volume.position, 0.0, Vec3::Zero(), false });

  // The tetrahedra's rest shapes from the mesh about the origin: D_m is the same wherever the body is put,
  // and differences of small coordinates round less than those of large ones.
  NodeArray rest(3, count);
  for (int k = 0; k < count; ++k)
    rest.col(k) = mesh.nodes[static_cast<std::size_t>(k)];
  const Lame lame = lameParameters(volume.youngs_modulus, volume.poisson_ratio);
  body.tetrahedra.reserve(mesh.tets.size());
  for (const std::array<int, 4>& t : mesh.tets)
  {
    Tetrahedron tet = makeTetrahedron(t, rest, lame);
    tet.pressure = volume.pressure;
    // Lumped masses: a linear tetrahedron's consistent mass matrix rho V (1 + delta_ab) / 20 summed over
    // each row gives rho V / 4 to each of its nodes.
    for (int node : t)
      body.nodes[static_cast<std::size_t>(node)].mass += 0.25 * volume.density * tet.rest_volume;
    body.tetrahedra.push_back(tet);
  }
  for (const NodeDef& node : body.nodes)
    requireDefinition(node.mass > 0.0, what, { "mesh", "shape" },
                      "the mesh has a node in no tetrahedron (it would have no mass)");
  body.surface = mesh.surface;
  if (volume.surface_samples > 0.0)
    body.surface_samples = sampleSurface(mesh, volume.surface_samples, what);

  for (const BoxFace* face : faces)
    pinFace(mesh, *volume.size, *face, body);
  for (int index : volume.pinned_nodes)
  {
    requireDefinition(index >= -count && index < count, what, { "pinned" },
                      "node index " + std::to_string(index) + " in pinned out of range; the mesh has " +
                          std::to_string(count) + " nodes (" + std::to_string(-count) + ".." +
                          std::to_string(count - 1) + ")");
    body.nodes[static_cast<std::size_t>(resolveNodeIndex(index, count))].pinned = true;
  }
  return body;
}

}  // namespace soft_body_sim
