// Mesh colliders (mesh_field.h): the OpenVDB distance field against brute force over the triangles
// (Ericson's closest point on a triangle, the winding number for the sign) on a box, a faceted sphere
// and a non-convex L-shaped block; reading STL and OBJ files through assimp; a cloth resting on a mesh box
// as on the analytic box; a rope draped over the L-shaped block never entering it.
#include <chrono>
#include <cstdio>
#include <fstream>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "core/contact/shape_contacts.h"
#include "soft_body_sim/core/bodies/cloth.h"
#include "soft_body_sim/core/bodies/rope.h"
#include "soft_body_sim/core/definition_error.h"
#include "test_meshes.h"
#include "test_util.h"

namespace soft_body_sim::test
{
namespace
{
/// Trilinear interpolation of exact voxel-centre distances is off by at most sum_c w_c |p - c| <=
/// sqrt(sum_i f_i (1 - f_i)) voxel <= sqrt(3) / 2 voxel (the distance is 1-Lipschitz; Jensen), plus
/// float rounding of the stored distances.
constexpr double kInterpolationError = 0.87;

std::string temporaryPath(const std::string& name)
{
  return ::testing::TempDir() + "soft_body_sim_" + std::to_string(::getpid()) + "_" + name;
}

TEST(MeshGeometry, TheTestMeshesAreClosedAndWoundOutward)
{
  // The brute-force sign needs them so: winding number 1 inside, 0 outside.
  EXPECT_NEAR(windingNumber(boxMesh(Vec3(0.4, 0.3, 0.2)), Vec3(0.1, 0.1, 0.05)), 1.0, 1e-9);
  EXPECT_NEAR(windingNumber(boxMesh(Vec3(0.4, 0.3, 0.2)), Vec3(0.3, 0.1, 0.05)), 0.0, 1e-9);
  EXPECT_NEAR(windingNumber(uvSphere(0.2, 24, 12), Vec3(0.05, 0.0, 0.1)), 1.0, 1e-9);
  EXPECT_NEAR(windingNumber(lBlock(), Vec3(0.02, 0.1, 0.15)), 1.0, 1e-9);   // in the upright
  EXPECT_NEAR(windingNumber(lBlock(), Vec3(0.2, 0.1, 0.03)), 1.0, 1e-9);    // in the foot
  EXPECT_NEAR(windingNumber(lBlock(), Vec3(0.2, 0.1, 0.15)), 0.0, 1e-9);    // in the corner's notch
}

/// 500 points spread over the mesh's bounding box widened by 5 cm (inside, near the surface and beyond the
/// band): the field's distance within kInterpolationError voxels of the brute-force one; its sign right
/// wherever the surface is farther than that; its normal the face's where every triangle that can be
/// nearest to one of the 8 voxel corners around the point lies in that face's plane (a flat neighbourhood,
/// where interpolation is exact).
void expectAgreesWithBruteForce(const TriangleMesh& mesh, const char* name, int min_flat)
{
  SCOPED_TRACE(name);
  const double voxel = defaultVoxelSize(mesh), band = 0.03;
  const auto start = std::chrono::steady_clock::now();
  const MeshField field(mesh, voxel, band);
  ::testing::Test::RecordProperty(std::string(name) + "_build_ms",
                 std::to_string(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count()));
  const double tolerance = kInterpolationError * voxel + 1e-6;
  std::mt19937 random(3);
  const Vec3 low = mesh.lower() - Vec3::Constant(0.05), high = mesh.upper() + Vec3::Constant(0.05);
  int flat = 0, inside = 0;
  for (int k = 0; k < 500; ++k)
  {
    Vec3 p;
    for (int i = 0; i < 3; ++i)
      p[i] = std::uniform_real_distribution<double>(low[i], high[i])(random);
    const BruteForce truth = bruteForce(mesh, p);
    const SurfaceDistance s = field.distance(p);
    SCOPED_TRACE("at (" + std::to_string(p.x()) + ", " + std::to_string(p.y()) + ", " + std::to_string(p.z()) + ")");
    EXPECT_NEAR(s.normal.norm(), 1.0, 1e-9);
    if (truth.distance > band - tolerance)
    {
      EXPECT_GE(s.distance, band - tolerance);  // beyond the band: reported at the band, never nearer
      continue;
    }
    EXPECT_NEAR(s.distance, truth.distance, tolerance);
    if (std::abs(truth.distance) > tolerance)
    {
      EXPECT_EQ(s.distance < 0.0, truth.distance < 0.0);
    }
    inside += truth.distance < 0.0;
    // A corner of the point's voxel cell is within sqrt(3) voxel of it, so its nearest triangle is within
    // |d| + 2 sqrt(3) voxel of the point.
    const Vec3 face_normal = (p - truth.closest).normalized();
    bool planar = truth.interior && std::abs(truth.distance) > 1e-9;
    for (std::size_t t = 0; t < mesh.triangles.size() && planar; ++t)
    {
      const Eigen::Vector3i& tri = mesh.triangles[t];
      const Vec3 &a = mesh.vertices[tri.x()], &b = mesh.vertices[tri.y()], &c = mesh.vertices[tri.z()];
      if ((p - closestOnTriangle(p, a, b, c)).norm() > std::abs(truth.distance) + 2.0 * std::sqrt(3.0) * voxel)
        continue;
      const Vec3 n = (b - a).cross(c - a).normalized();
      planar = std::abs(std::abs(n.dot(face_normal)) - 1.0) < 1e-9 && std::abs(n.dot(a - truth.closest)) < 1e-9;
    }
    if (!planar)
      continue;
    ++flat;
    const Vec3 outward = truth.distance < 0.0 ? Vec3(-face_normal) : face_normal;
    EXPECT_LT((s.normal - outward).norm(), 1e-3);
  }
  // The checks above ran on enough points of each kind to mean something.
  ::testing::Test::RecordProperty(std::string(name) + "_flat_points", std::to_string(flat));
  EXPECT_GE(flat, min_flat);
  EXPECT_GT(inside, 20);
  ::testing::Test::RecordProperty(std::string(name) + "_active_voxels", std::to_string(field.activeVoxels()));
}

TEST(MeshGeometry, DistanceSignAndNormalAgreeWithBruteForceOverTheTriangles)
{
  expectAgreesWithBruteForce(boxMesh(Vec3(0.4, 0.3, 0.2)), "box", 100);
  // Its facets are too small for a flat neighbourhood: distance and sign only.
  expectAgreesWithBruteForce(uvSphere(0.2, 24, 12), "faceted sphere", 0);
  expectAgreesWithBruteForce(lBlock(), "L-shaped block", 50);
}

// Where a segment comes nearest the non-convex L-shaped block (sampling and a local search) against
// sampling the segment at 2,001 points: never farther than the best sample but for the field's own
// resolution (a minimum narrower than a voxel may be missed by up to the interpolation error).
TEST(MeshGeometry, TheNearestPointOfASegmentAgreesWithSampling)
{
  Mesh mesh;
  mesh.triangles = std::make_shared<const TriangleMesh>(lBlock());
  std::vector<Mesh> meshes{ mesh };
  buildMeshFields(meshes, 0.05);
  const Mesh& block = meshes[0];
  const double voxel = block.field->voxelSize();
  std::mt19937 random(5);
  std::uniform_real_distribution<double> coordinate(-0.05, 0.35);
  for (int k = 0; k < 200; ++k)
  {
    const Vec3 a(coordinate(random), coordinate(random) * 0.6, coordinate(random) * 0.7);
    const Vec3 d = Vec3(coordinate(random), coordinate(random), coordinate(random)) - Vec3::Constant(0.15);
    double best = 1e9;
    for (int i = 0; i <= 2000; ++i)
      best = std::min(best, surfaceDistance(block, a + (i / 2000.0) * d).distance);
    const double t = nearestParameter(block, a, d);
    ASSERT_GE(t, 0.0);
    ASSERT_LE(t, 1.0);
    EXPECT_LE(surfaceDistance(block, a + t * d).distance, best + kInterpolationError * voxel);
  }
}

TEST(MeshFile, AnStlIsReadWithItsCornersJoinedAndScaled)
{
  const std::string path = temporaryPath("box.stl");
  writeBinaryStl(boxMesh(Vec3(0.4, 0.3, 0.2)), path);
  const TriangleMesh read = readTriangleMesh(path, Vec3(2.0, 1.0, 0.5));
  std::remove(path.c_str());
  EXPECT_EQ(read.vertices.size(), 8u);  // the STL repeats each corner per triangle
  EXPECT_EQ(read.triangles.size(), 12u);
  EXPECT_TRUE(expectNear(read.lower(), Vec3(-0.4, -0.15, -0.05), 1e-7));  // float coordinates in the file
  EXPECT_TRUE(expectNear(read.upper(), Vec3(0.4, 0.15, 0.05), 1e-7));
  EXPECT_NEAR(windingNumber(read, Vec3(0.35, 0.1, 0.04)), 1.0, 1e-9);
}

TEST(MeshFile, EveryMeshOfAnObjFileIsJoined)
{
  const std::string path = temporaryPath("two.obj");
  {
    std::ofstream obj(path);
    obj << "o first\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
    obj << "o second\nv 2 0 0\nv 3 0 0\nv 2 1 0\nv 2 0 1\nf 5 7 6\nf 5 6 8\nf 5 8 7\nf 6 7 8\n";
  }
  const TriangleMesh read = readTriangleMesh(path, Vec3::Ones());
  std::remove(path.c_str());
  EXPECT_EQ(read.triangles.size(), 8u);
  EXPECT_TRUE(expectNear(read.upper(), Vec3(3, 1, 1), 1e-12));
}

TEST(MeshFile, AnUnreadableOrEmptyFileIsADefinitionErrorAtTheKeyMeshNamingThePath)
{
  const auto refusal = [](const std::string& path) {
    try
    {
      readTriangleMesh(path, Vec3::Ones());
    }
    catch (const DefinitionError& e)
    {
      EXPECT_EQ(e.keys(), std::vector<std::string>{ "mesh" });
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const std::string missing = refusal("/nonexistent/part.stl");
  EXPECT_NE(missing.find("'/nonexistent/part.stl'"), std::string::npos) << missing;
  EXPECT_NE(missing.find("cannot be read"), std::string::npos) << missing;
  const std::string path = temporaryPath("empty.obj");
  std::ofstream(path) << "# no faces\nv 0 0 0\n";
  const std::string empty = refusal(path);
  std::remove(path.c_str());
  EXPECT_TRUE(empty.find("holds no triangle") != std::string::npos || empty.find("cannot be read") != std::string::npos)
      << empty;
}

// --- contact -------------------------------------------------------------------------------------------

/// A 0.2 m square cloth of 11 x 11 nodes, 1 cm thick, dropped from 5 cm above the top (z = 0.1 m) of a
/// 0.4 x 0.3 x 0.2 m box: it lands within the top face, away from its edges.
SceneDef clothOnBox()
{
  SceneDef scene;
  scene.physics.integrator = IntegratorType::Xpbd;
  scene.physics.step = StepSettings{ 1.0 / 120.0, 4, 2 };
  scene.physics.drag = 1.0;
  ClothDef cloth;
  cloth.nx = cloth.ny = 11;
  cloth.corners = GridCorners{ Vec3(-0.1, 0.1, 0.15), Vec3(0.1, 0.1, 0.15), Vec3(-0.1, -0.1, 0.15) };
  cloth.mass = 0.05;
  cloth.structural = { 500.0, 0.2 };
  cloth.shear = { 100.0, 0.2 };
  scene.bodies.push_back(buildCloth("cloth", cloth));
  scene.bodies[0].contact_radius = 0.01;
  return scene;
}

// The same box as the analytic Box and as a mesh (turned and moved, so that the placement counts): the
// cloth comes to rest at the same height, on the face where the field is exact; its nodes agree within
// the field's error.
TEST(MeshContact, AClothRestsOnAMeshBoxWhereItRestsOnTheAnalyticBox)
{
  const Eigen::Quaterniond turn(Eigen::AngleAxisd(0.3, Vec3::UnitZ()));
  SceneDef analytic = clothOnBox();
  Box box;
  box.at.name = "box";
  box.at.orientation = turn;
  box.at.friction = 0.5;
  box.size = Vec3(0.4, 0.3, 0.2);
  analytic.colliders.boxes.push_back(box);
  SceneDef meshed = clothOnBox();
  Mesh mesh;
  mesh.at = box.at;
  mesh.triangles = std::make_shared<const TriangleMesh>(boxMesh(Vec3(0.4, 0.3, 0.2)));
  meshed.colliders.meshes.push_back(mesh);
  World a = buildWorld(analytic), b = buildWorld(meshed);
  for (int n = 0; n < 240; ++n)  // 2 s
  {
    a.step();
    b.step();
  }
  const double voxel = defaultVoxelSize(*mesh.triangles);
  EXPECT_TRUE(expectNear(b.state().position, a.state().position, kInterpolationError * voxel));
  // Both at rest on the top face, a contact radius above it.
  EXPECT_NEAR(b.state().position.row(2).minCoeff(), 0.1 + 0.01, 1e-4);
  EXPECT_LT(b.state().velocity.colwise().norm().maxCoeff(), 0.01);
  ASSERT_EQ(b.colliderPoses().size(), 1u);
  EXPECT_EQ(b.colliderPoses()[0].shape, ColliderPose::Shape::Mesh);
}

// A rope of 2.5 cm links dropped across the L-shaped block (its upright 5 cm thick) drapes over the upright
// and the foot, into the notch between them. Truth: brute force over the triangles at every step; no node
// and no point of a link (at its quarters) is ever inside the block, and every node keeps its contact
// radius from it, within the field's error.
TEST(MeshContact, ARopeDrapedOverANonConvexMeshNeverEntersIt)
{
  SceneDef scene;
  scene.physics.integrator = IntegratorType::Xpbd;
  scene.physics.step = StepSettings{ 1.0 / 240.0, 4, 2 };
  scene.physics.drag = 0.5;
  RopeDef rope;
  rope.nodes = 21;
  rope.from = Vec3(-0.15, 0.1, 0.3);
  rope.to = Vec3(0.35, 0.1, 0.3);
  rope.mass = 0.05;
  rope.stiffness = 5000.0;
  rope.radius = 0.004;
  scene.bodies.push_back(buildRope("rope", rope));
  Mesh block;
  block.at.name = "block";
  block.at.friction = 0.3;
  const TriangleMesh triangles = lBlock();
  block.triangles = std::make_shared<const TriangleMesh>(triangles);
  scene.colliders.meshes.push_back(block);
  World world = buildWorld(scene);
  const double tolerance = kInterpolationError * defaultVoxelSize(triangles);
  double closest_node = 1e9, deepest_link = 1e9;
  for (int n = 0; n < 360; ++n)  // 1.5 s
  {
    world.step();
    const NodeArray& x = world.state().position;
    for (int i = 0; i < rope.nodes; ++i)
      closest_node = std::min(closest_node, bruteForce(triangles, x.col(i)).distance);
    for (int i = 0; i + 1 < rope.nodes; ++i)
      for (const double t : { 0.25, 0.5, 0.75 })
        deepest_link = std::min(deepest_link, bruteForce(triangles, (1.0 - t) * x.col(i) + t * x.col(i + 1)).distance);
  }
  EXPECT_GE(closest_node, rope.radius - tolerance);
  EXPECT_GE(deepest_link, 0.0);
  // It lies on the block, draped into the notch: some node on the foot's top.
  const NodeArray& x = world.state().position;
  EXPECT_LT(x.row(2).minCoeff(), 0.05 + rope.radius + 0.005);
  EXPECT_GT(x.row(2).minCoeff(), 0.05);
  RecordProperty("closest_node_m", std::to_string(closest_node));
}

}  // namespace
}  // namespace soft_body_sim::test
