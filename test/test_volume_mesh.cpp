// The tetrahedral mesher (bodies/volume_mesh.h) against truths of geometry that do not come from it: the
// box's volume and area, the divergence theorem's volume of a surface, the sphere's inscribed
// polyhedron between two balls, Euler's rule that a closed surface shares every edge by two triangles,
// and TetGen's quality bound checked from the node positions.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <unistd.h>

#include <gtest/gtest.h>

#include "soft_body_sim/core/bodies/volume_mesh.h"
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
  const Eigen::Vector3d x = (u.squaredNorm() * v.cross(w) + v.squaredNorm() * w.cross(u) + w.squaredNorm() * u.cross(v)) /
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

/// Every tetrahedron positive, none thinner than the floor 1e-3 resolution^3 / 6 [m^3] (a sliver, flat
/// with a fine radius-edge ratio, would be); those with no node on the surface within TetGen's
/// radius-edge bound, up to 2 % for its node smoothing after refinement (volume_mesh.h).
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
  EXPECT_LE(worst_ratio, 1.02 * kRadiusEdgeBound);
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
    mesh.vertices.push_back(centre + half * Eigen::Vector3d(corner & 1 ? 1 : -1, corner & 2 ? 1 : -1, corner & 4 ? 1 : -1));
  for (const std::array<int, 4>& q : std::vector<std::array<int, 4>>{
           { 0, 2, 3, 1 }, { 4, 5, 7, 6 }, { 0, 1, 5, 4 }, { 2, 6, 7, 3 }, { 0, 4, 6, 2 }, { 1, 3, 7, 5 } })
  {
    mesh.triangles.emplace_back(q[0], q[1], q[2]);
    mesh.triangles.emplace_back(q[0], q[2], q[3]);
  }
  return mesh;
}

/// The L-shaped prism: the polygon (0,0) (2,0) (2,1) (1,1) (1,2) (0,2) times `scale` [m], extruded from
/// z = 0 to `scale`; volume 3 scale^3.
TriangleMesh lPrism(double scale)
{
  const std::vector<Eigen::Vector2d> outline{ { 0, 0 }, { 2, 0 }, { 2, 1 }, { 1, 1 }, { 1, 2 }, { 0, 2 } };
  TriangleMesh mesh;
  for (double z : { 0.0, 1.0 })
    for (const Eigen::Vector2d& p : outline)
      mesh.vertices.push_back(scale * Eigen::Vector3d(p.x(), p.y(), z));
  // Caps: a fan from the reflex corner 3, counter-clockwise seen from +z on top, turned on the bottom.
  for (int k : { 4, 5, 0, 1 })
  {
    const int next = (k + 1) % 6;
    mesh.triangles.emplace_back(3 + 6, k + 6, next + 6);
    mesh.triangles.emplace_back(3, next, k);
  }
  for (int k = 0; k < 6; ++k)  // sides: outward, as the outline runs counter-clockwise
  {
    const int next = (k + 1) % 6;
    mesh.triangles.emplace_back(k, next, next + 6);
    mesh.triangles.emplace_back(k, next + 6, k + 6);
  }
  return mesh;
}

/// `mesh` written as an ASCII STL file at `path`.
void writeStl(const TriangleMesh& mesh, const std::string& path)
{
  std::ofstream out(path);
  out.precision(17);
  out << "solid test\n";
  for (const Eigen::Vector3i& t : mesh.triangles)
  {
    out << "facet normal 0 0 0\nouter loop\n";
    for (int k = 0; k < 3; ++k)
      out << "vertex " << mesh.vertices[t[k]].x() << ' ' << mesh.vertices[t[k]].y() << ' ' << mesh.vertices[t[k]].z() << '\n';
    out << "endloop\nendfacet\n";
  }
  out << "endsolid test\n";
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

TEST(VolumeMesh, BoxNodesGrowAsTheCubeOfOneOverResolution)
{
  const Eigen::Vector3d size(0.2, 0.2, 0.2);
  const TetMesh coarse = meshBox(size, 0.02), fine = meshBox(size, 0.01);
  const double ratio = static_cast<double>(fine.nodes.size()) / static_cast<double>(coarse.nodes.size());
  // 8 in the interior's limit; the surface's nodes, a share ~ 1/n of them, grow only 4 times.
  EXPECT_GT(ratio, 5.0);
  EXPECT_LT(ratio, 10.0);
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
  const std::string path =
      (std::filesystem::temp_directory_path() / ("test_volume_mesh_" + std::to_string(getpid()) + ".stl")).string();
  writeStl(lPrism(0.1), path);
  const TriangleMesh surface = readTriangleMesh(path, Eigen::Vector3d::Ones());
  std::filesystem::remove(path);
  const double exact = 3.0 * 0.1 * 0.1 * 0.1;
  // ASCII STL is read in single precision: the corners move by ~1e-8 of their size.
  ASSERT_NEAR(enclosedVolume(surface), exact, 1e-6 * exact);
  const double resolution = 0.02;
  const TetMesh mesh = meshSurface(surface, resolution);
  const double enclosed = enclosedVolume(surface);
  EXPECT_NEAR(meshVolume(mesh), enclosed, 1e-9 * enclosed);
  EXPECT_NEAR(enclosedVolume(surfaceOf(mesh)), enclosed, 1e-9 * enclosed);
  expectClosedAndOriented(mesh);
  expectQuality(mesh, resolution);
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
  // 4.5 V / (h^3 / (6 sqrt 2)) at V = 1 m^3, h = 1 cm: 3.8e7 tetrahedra.
  EXPECT_NE(definitionError([&] { meshBox(Eigen::Vector3d::Ones(), 0.01); }).find("too fine"), std::string::npos);
}

TEST(VolumeMesh, MissingTetgenIsNamed)
{
  const std::string path = std::getenv("PATH");
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
