// The tetrahedral mesher (bodies/volume_mesh.h) against truths of geometry that do not come from it: the
// box's volume and area, the divergence theorem's volume of a surface, the sphere's inscribed
// polyhedron held between two balls, a closed oriented surface running each edge once each way, and
// TetGen's radius-edge bound checked from the node positions.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "soft_body_sim/core/meshing/volume_mesh.h"
#include "soft_body_sim/core/definition_error.h"

namespace soft_body_sim::test
{
namespace
{
/// TetGen's radius-edge bound, the -q1.414 that volume_mesh.cpp asks for.
constexpr double kRadiusEdgeBound = 1.414;

/// R / l_min: the circumradius of the tetrahedron (a, b, c, d) over its shortest edge; sqrt(6) / 4 =
/// 0.612 for the regular one. The circumcentre a + x solves 2 (p - a) . x = |p - a|^2 for p = b, c, d:
/// x = (|u|^2 v x w + |v|^2 w x u + |w|^2 u x v) / (2 u . v x w), with u, v, w = b - a, c - a, d - a.
double radiusEdgeRatio(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                       const Eigen::Vector3d& d)
{
  const Eigen::Vector3d u = b - a, v = c - a, w = d - a;
  const Eigen::Vector3d x =
      (u.squaredNorm() * v.cross(w) + v.squaredNorm() * w.cross(u) + w.squaredNorm() * u.cross(v)) /
      (2.0 * u.dot(v.cross(w)));
  const double shortest = std::min({ u.norm(), v.norm(), w.norm(), (c - b).norm(), (d - b).norm(), (d - c).norm() });
  return x.norm() / shortest;
}

/// The mesh's surface as a TriangleMesh over its nodes.
TriangleMesh surfaceOf(const TetMesh& mesh)
{
  TriangleMesh surface;
  surface.vertices = mesh.nodes;
  for (const std::array<int, 3>& f : mesh.surface)
    surface.triangles.emplace_back(f[0], f[1], f[2]);
  return surface;
}

double surfaceArea(const TetMesh& mesh)
{
  double area = 0.0;
  for (const std::array<int, 3>& f : mesh.surface)
    area += 0.5 * (mesh.nodes[f[1]] - mesh.nodes[f[0]]).cross(mesh.nodes[f[2]] - mesh.nodes[f[0]]).norm();
  return area;
}

/// The mean length of the mesh's edges (each counted once) [m].
double meanEdge(const TetMesh& mesh)
{
  std::set<std::pair<int, int>> edges;
  for (const std::array<int, 4>& t : mesh.tets)
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j)
        edges.insert({ std::min(t[i], t[j]), std::max(t[i], t[j]) });
  double sum = 0.0;
  for (const auto& [i, j] : edges)
    sum += (mesh.nodes[i] - mesh.nodes[j]).norm();
  return sum / static_cast<double>(edges.size());
}

/// Every tetrahedron positive and none thinner than the floor 1e-3 resolution^3 / 6 [m^3], which
/// excludes slivers (flat, though of a fine radius-edge ratio) that no bound of TetGen's does (the
/// thinnest measured: 1.5e-3 on part.stl, 5e-3 and more on boxes and spheres); those with no node on
/// the surface within 5 % of TetGen's radius-edge bound, which its optimisation after refinement moves
/// (volume_mesh.h).
void expectQuality(const TetMesh& mesh, double resolution)
{
  ASSERT_FALSE(mesh.tets.empty());
  std::vector<bool> on_surface(mesh.nodes.size(), false);
  for (const std::array<int, 3>& f : mesh.surface)
    for (int v : f)
      on_surface[static_cast<std::size_t>(v)] = true;
  double smallest = INFINITY, worst_ratio = 0.0;
  for (const std::array<int, 4>& t : mesh.tets)
  {
    const Eigen::Vector3d &a = mesh.nodes[t[0]], &b = mesh.nodes[t[1]], &c = mesh.nodes[t[2]], &d = mesh.nodes[t[3]];
    smallest = std::min(smallest, tetVolume(a, b, c, d));
    if (!on_surface[t[0]] && !on_surface[t[1]] && !on_surface[t[2]] && !on_surface[t[3]])
      worst_ratio = std::max(worst_ratio, radiusEdgeRatio(a, b, c, d));
  }
  EXPECT_GT(smallest, 1e-3 * resolution * resolution * resolution / 6.0);
  EXPECT_LE(worst_ratio, 1.05 * kRadiusEdgeBound);
}

/// Every edge of the surface is run once each way by two of its triangles: closed and consistently
/// oriented.
void expectClosedAndOriented(const TetMesh& mesh)
{
  ASSERT_FALSE(mesh.surface.empty());
  std::map<std::pair<int, int>, int> runs;  // directed edge -> triangles running it
  for (const std::array<int, 3>& f : mesh.surface)
    for (int k = 0; k < 3; ++k)
      ++runs[{ f[k], f[(k + 1) % 3] }];
  for (const auto& [edge, count] : runs)
  {
    EXPECT_EQ(count, 1) << "edge " << edge.first << " -> " << edge.second;
    EXPECT_EQ(runs.count({ edge.second, edge.first }), 1u) << "edge " << edge.first << " -> " << edge.second;
  }
}

/// The cube of half-edge `half` [m] about `centre` as 12 outward triangles.
TriangleMesh cube(const Eigen::Vector3d& centre, double half)
{
  TriangleMesh mesh;
  for (int corner = 0; corner < 8; ++corner)  // bit 0: +x, bit 1: +y, bit 2: +z
    mesh.vertices.push_back(centre +
                            half * Eigen::Vector3d(corner & 1 ? 1 : -1, corner & 2 ? 1 : -1, corner & 4 ? 1 : -1));
  for (const std::array<int, 4>& q : std::vector<std::array<int, 4>>{
           { 0, 2, 3, 1 }, { 4, 5, 7, 6 }, { 0, 1, 5, 4 }, { 2, 6, 7, 3 }, { 0, 4, 6, 2 }, { 1, 3, 7, 5 } })
  {
    mesh.triangles.emplace_back(q[0], q[1], q[2]);
    mesh.triangles.emplace_back(q[0], q[2], q[3]);
  }
  return mesh;
}

/// The message of the DefinitionError that `make` throws, or "" if it throws none.
template <typename Make>
std::string definitionError(Make make)
{
  try
  {
    make();
  }
  catch (const DefinitionError& error)
  {
    return error.what();
  }
  return "";
}

TEST(VolumeMesh, BoxFillsItsVolumeAndItsSurfaceIsItsFaces)
{
  const Eigen::Vector3d size(0.4, 0.3, 0.2);
  const double resolution = 0.05;
  const TetMesh mesh = meshBox(size, resolution);
  const double volume = size.prod(), area = 2.0 * (size.x() * size.y() + size.y() * size.z() + size.z() * size.x());
  EXPECT_NEAR(meshVolume(mesh), volume, 1e-12 * volume);
  EXPECT_NEAR(enclosedVolume(surfaceOf(mesh)), volume, 1e-12 * volume);  // outward: + the tets' volume
  EXPECT_NEAR(surfaceArea(mesh), area, 1e-12 * area);
  expectClosedAndOriented(mesh);
  expectQuality(mesh, resolution);
  for (const Eigen::Vector3d& node : mesh.nodes)
    EXPECT_LE((node.cwiseAbs() - 0.5 * size).maxCoeff(), 1e-15) << node.transpose();
  EXPECT_GT(meanEdge(mesh), 0.5 * resolution);
  EXPECT_LT(meanEdge(mesh), 1.5 * resolution);
}

/// The number of nodes on the mesh's surface.
std::size_t surfaceNodes(const TetMesh& mesh)
{
  std::set<int> nodes;
  for (const std::array<int, 3>& f : mesh.surface)
    nodes.insert(f.begin(), f.end());
  return nodes.size();
}

TEST(VolumeMesh, BoxRefinesAsTheCubeOfOneOverResolution)
{
  const Eigen::Vector3d size(0.2, 0.2, 0.2);
  const TetMesh coarse = meshBox(size, 0.02), fine = meshBox(size, 0.01);
  const auto ratio = [](std::size_t fine_count, std::size_t coarse_count) {
    return static_cast<double>(fine_count) / static_cast<double>(coarse_count);
  };
  // Halving the resolution: the tetrahedra, filling the volume, grow 2^3 = 8 times, the surface's nodes
  // 2^2 = 4 times, and all nodes in between (10 to 20 tetrahedra across, half of them on the surface).
  EXPECT_GT(ratio(fine.tets.size(), coarse.tets.size()), 6.0);
  EXPECT_LT(ratio(fine.tets.size(), coarse.tets.size()), 10.0);
  EXPECT_GT(ratio(surfaceNodes(fine), surfaceNodes(coarse)), 3.0);
  EXPECT_LT(ratio(surfaceNodes(fine), surfaceNodes(coarse)), 5.0);
  EXPECT_GT(ratio(fine.nodes.size(), coarse.nodes.size()), 4.0);
  EXPECT_LT(ratio(fine.nodes.size(), coarse.nodes.size()), 8.0);
  EXPECT_GT(meanEdge(fine), 0.5 * 0.01);
  EXPECT_LT(meanEdge(fine), 1.5 * 0.01);
}

TEST(VolumeMesh, SphereIsItsInscribedPolyhedron)
{
  const double radius = 0.1, ball = 4.0 / 3.0 * M_PI * radius * radius * radius;
  std::vector<double> deficits;
  for (double resolution : { 0.02, 0.01 })
  {
    const TetMesh mesh = meshSphere(radius, resolution);
    const TriangleMesh surface = surfaceOf(mesh);
    const double volume = meshVolume(mesh), polyhedron = enclosedVolume(surface);
    EXPECT_NEAR(volume, polyhedron, 1e-9 * polyhedron);
    expectClosedAndOriented(mesh);
    expectQuality(mesh, resolution);
    // Inscribed: no node outside the sphere, so the polyhedron lies in the ball. Convex about the
    // centre: it holds the ball of radius its nearest facet plane's distance.
    double inner = radius;
    for (const Eigen::Vector3d& node : mesh.nodes)
      EXPECT_LE(node.norm(), radius * (1.0 + 1e-12));
    for (const Eigen::Vector3i& t : surface.triangles)
    {
      const Eigen::Vector3d& a = surface.vertices[t[0]];
      const Eigen::Vector3d normal = (surface.vertices[t[1]] - a).cross(surface.vertices[t[2]] - a).normalized();
      inner = std::min(inner, normal.dot(a));
    }
    EXPECT_LT(volume, ball);
    EXPECT_GT(volume, 4.0 / 3.0 * M_PI * inner * inner * inner);
    const double deficit = (ball - volume) / ball;
    EXPECT_LT(deficit, 0.51 * (resolution / radius) * (resolution / radius));  // volume_mesh.h's bound
    deficits.push_back(deficit);
    EXPECT_GT(meanEdge(mesh), 0.5 * resolution);
    EXPECT_LT(meanEdge(mesh), 1.5 * resolution);
  }
  // The chord error is second order: halving the resolution divides it by about 4.
  EXPECT_GT(deficits[0] / deficits[1], 3.0);
  EXPECT_LT(deficits[0] / deficits[1], 5.0);
}

TEST(VolumeMesh, ClosedStlFillsItsDivergenceVolume)
{
  // The example bracket (scripts/make_part_stl.py): an L-shaped profile of area 0.1 x 0.02 + 0.02 x 0.06
  // [m^2] extruded 0.06 m, not convex.
  const TriangleMesh surface = readTriangleMesh(SOURCE_DIR "/config/meshes/part.stl", Eigen::Vector3d::Ones());
  const double exact = (0.1 * 0.02 + 0.02 * 0.06) * 0.06, enclosed = enclosedVolume(surface);
  ASSERT_NEAR(enclosed, exact, 1e-6 * exact);  // a binary STL holds single-precision corners
  const double resolution = 0.01;
  const TetMesh mesh = meshSurface(surface, resolution);
  EXPECT_NEAR(meshVolume(mesh), enclosed, 1e-9 * enclosed);
  EXPECT_NEAR(enclosedVolume(surfaceOf(mesh)), enclosed, 1e-9 * enclosed);
  expectClosedAndOriented(mesh);
  expectQuality(mesh, resolution);
  EXPECT_GT(meanEdge(mesh), 0.5 * resolution);
  EXPECT_LT(meanEdge(mesh), 1.5 * resolution);
}

TEST(VolumeMesh, InwardSurfaceMeshesTheSameSolid)
{
  TriangleMesh inward = cube(Eigen::Vector3d(0.1, 0.0, 0.0), 0.05);
  for (Eigen::Vector3i& t : inward.triangles)
    std::swap(t[1], t[2]);
  const TetMesh mesh = meshSurface(inward, 0.02);
  EXPECT_NEAR(meshVolume(mesh), 1e-3, 1e-15);
  EXPECT_NEAR(enclosedVolume(surfaceOf(mesh)), 1e-3, 1e-15);
}

TEST(VolumeMesh, OpenSurfaceIsRefused)
{
  TriangleMesh open = cube(Eigen::Vector3d::Zero(), 0.05);
  open.triangles.pop_back();
  const std::string message = definitionError([&] { meshSurface(open, 0.02); });
  EXPECT_NE(message.find("not closed: 3 edge(s) are not shared by exactly two triangles"), std::string::npos)
      << message;
  EXPECT_NE(message.find("is in 1 triangle(s)"), std::string::npos) << message;
}

TEST(VolumeMesh, InconsistentOrientationIsRefused)
{
  TriangleMesh flipped = cube(Eigen::Vector3d::Zero(), 0.05);
  std::swap(flipped.triangles[4][1], flipped.triangles[4][2]);
  const std::string message = definitionError([&] { meshSurface(flipped, 0.02); });
  EXPECT_NE(message.find("inconsistently oriented: triangles"), std::string::npos) << message;
}

TEST(VolumeMesh, SelfIntersectingSurfaceIsRefused)
{
  TriangleMesh both = cube(Eigen::Vector3d::Zero(), 0.05);
  const TriangleMesh other = cube(Eigen::Vector3d(0.03, 0.03, 0.03), 0.05);
  const int offset = static_cast<int>(both.vertices.size());
  both.vertices.insert(both.vertices.end(), other.vertices.begin(), other.vertices.end());
  for (const Eigen::Vector3i& t : other.triangles)
    both.triangles.push_back(t + Eigen::Vector3i::Constant(offset));
  const std::string message = definitionError([&] { meshSurface(both, 0.02); });
  EXPECT_NE(message.find("the surface intersects itself"), std::string::npos) << message;
  EXPECT_NE(message.find("of its triangles cross another (tetgen -d), the first triangle"), std::string::npos)
      << message;
}

TEST(VolumeMesh, CavityIsRefused)
{
  TriangleMesh hollow = cube(Eigen::Vector3d::Zero(), 0.05);
  TriangleMesh cavity = cube(Eigen::Vector3d::Zero(), 0.02);
  const int offset = static_cast<int>(hollow.vertices.size());
  hollow.vertices.insert(hollow.vertices.end(), cavity.vertices.begin(), cavity.vertices.end());
  for (const Eigen::Vector3i& t : cavity.triangles)
    hollow.triangles.emplace_back(t[0] + offset, t[2] + offset, t[1] + offset);  // facing into the cavity
  const std::string message = definitionError([&] { meshSurface(hollow, 0.02); });
  EXPECT_NE(message.find("a shell lies inside another (a cavity is not supported)"), std::string::npos) << message;
}

TEST(VolumeMesh, BadSizesAndResolutionsAreRefused)
{
  const Eigen::Vector3d size(0.1, 0.1, 0.1);
  for (double resolution : { 0.0, -0.01, std::nan("") })
  {
    EXPECT_NE(definitionError([&] { meshBox(size, resolution); }).find("resolution must be > 0"), std::string::npos);
    EXPECT_NE(definitionError([&] { meshSphere(0.1, resolution); }).find("resolution must be > 0"), std::string::npos);
    EXPECT_NE(definitionError([&] { meshSurface(cube(Eigen::Vector3d::Zero(), 0.05), resolution); })
                  .find("resolution must be > 0"),
              std::string::npos);
  }
  for (int axis = 0; axis < 3; ++axis)
  {
    Eigen::Vector3d flat = size;
    flat[axis] = axis == 1 ? -0.1 : 0.0;
    EXPECT_NE(definitionError([&] { meshBox(flat, 0.01); }).find("size must be > 0 in x, y and z"), std::string::npos);
  }
  EXPECT_NE(definitionError([&] { meshSphere(0.0, 0.01); }).find("radius must be > 0"), std::string::npos);
  // kTetsPerMaxVolume V / v_max = 3.5 x 1 m^3 / (1e-6 m^3 / (2 sqrt 2)): 9.9e6 tetrahedra.
  const std::string message = definitionError([&] { meshBox(Eigen::Vector3d::Ones(), 0.01); });
  EXPECT_NE(message.find("resolution 0.01 m is too fine: it would make about 9899495 tetrahedra"), std::string::npos)
      << message;
  EXPECT_NE(message.find("over the limit of 2000000"), std::string::npos) << message;
}

TEST(VolumeMesh, MissingTetgenIsNamed)
{
  const char* const path_set = std::getenv("PATH");
  ASSERT_NE(path_set, nullptr);
  const std::string path = path_set;
  setenv("PATH", "/nonexistent", 1);
  std::string message;
  try
  {
    meshBox(Eigen::Vector3d(0.1, 0.1, 0.1), 0.05);
  }
  catch (const std::runtime_error& error)
  {
    message = error.what();
  }
  setenv("PATH", path.c_str(), 1);
  EXPECT_NE(message.find("install the Debian package tetgen"), std::string::npos) << message;
}

}  // namespace
}  // namespace soft_body_sim::test
