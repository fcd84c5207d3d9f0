// Other bodies against a soft solid's surface (surface_contacts.h, implicit_euler's surface holds), against
// truths that do not come from them: a brute-force nearest point on a triangle, elasticity's shortening of
// two cubes stacked on the floor (the upper one's weight passed through the contact), and the geometry of
// a rope resting across a cube (no node inside it, its middle lying on the top face).
#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "soft_body_sim/core/bodies/cloth.h"
#include "soft_body_sim/core/bodies/rope.h"
#include "soft_body_sim/core/bodies/volume.h"
#include "core/contact/surface_contacts.h"
#include "soft_body_sim/core/elements/tetrahedra.h"
#include "test_util.h"

namespace soft_body_sim::test
{
namespace
{
constexpr double kGravity = 9.81;

BodyDef cube(const std::string& name, double size, const Vec3& centre, double youngs_modulus, double nu, double density,
             double friction, double resolution = 0.025)
{
  VolumeDef box = boxVolume(Vec3::Constant(size), resolution, centre, youngs_modulus, nu, density);
  box.friction = friction;
  return buildVolume(name, box);
}

/// A 40 cm rope of radius `radius` [m] (41 nodes, 20 g) along x at y = `y` [m], 5 cm above a cube of edge
/// `size` [m] whose bottom is at z = 0.
BodyDef ropeAcross(double size, double radius, double y = 0.0)
{
  RopeDef rope;
  rope.nodes = 41;
  rope.from = Vec3(-0.2, y, size + 0.05);
  rope.to = Vec3(0.2, y, size + 0.05);
  rope.mass = 0.02;
  rope.stiffness = 200.0;
  rope.damping = 0.05;
  rope.radius = radius;
  return buildRope("rope", rope);
}

SceneDef floorScene(double dt)
{
  SceneDef scene;
  scene.physics.integrator = IntegratorType::ImplicitEuler;
  scene.physics.step.dt = dt;
  scene.physics.drag = 5.0;
  scene.physics.gravity = Vec3(0.0, 0.0, -kGravity);
  scene.colliders.planes.push_back(Plane{ Vec3::Zero(), Vec3::UnitZ(), 0.0, 0.5 });
  return scene;
}

/// The mean z of the nodes of body `b` whose rest z (in `def`) is `value`.
double meanZ(const World& world, int b, const BodyDef& def, double value)
{
  const int first = world.model().bodies[static_cast<std::size_t>(b)].first;
  double sum = 0.0;
  int count = 0;
  for (std::size_t i = 0; i < def.nodes.size(); ++i)
    if (std::abs(def.nodes[i].position.z() - value) < 1e-9)
    {
      sum += world.state().position(2, first + static_cast<int>(i));
      ++count;
    }
  return sum / count;
}

/// Signed distance of p from the closed surface of `solid` at positions x: the nearest triangle's distance,
/// negative where p is inside, judged by the surface's winding number about p (the sum of its triangles'
/// solid angles, Van Oosterom and Strackee 1983, over 4 pi: 1 inside, 0 outside).
double signedDistance(const BodyRange& solid, const NodeArray& x, const Vec3& p)
{
  double nearest = INFINITY, solid_angle = 0.0;
  for (const std::array<int, 3>& t : solid.surface)
  {
    nearest = std::min(nearest, (p - nearestOnTriangle(p, x.col(t[0]), x.col(t[1]), x.col(t[2])).point).norm());
    const Vec3 a = x.col(t[0]) - p, b = x.col(t[1]) - p, c = x.col(t[2]) - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    solid_angle += 2.0 * std::atan2(a.dot(b.cross(c)), la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la);
  }
  return solid_angle > 2.0 * M_PI ? -nearest : nearest;
}

/// The edges of `triangles`, each once (its lower node first).
std::vector<std::pair<int, int>> uniqueEdges(const std::vector<std::array<int, 3>>& triangles)
{
  std::vector<std::pair<int, int>> edges;
  for (const std::array<int, 3>& t : triangles)
    for (int k = 0; k < 3; ++k)
      edges.emplace_back(std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3]));
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  return edges;
}

/// The nearest that any point of the line of nodes `line` (a rope's axis: its nodes and 15 points between
/// each two) comes to the surface of `solid` at positions x [m] (signedDistance: < 0 inside).
double nearestAxisPoint(const BodyRange& solid, const BodyRange& line, const NodeArray& x)
{
  double nearest = INFINITY;
  for (int i = line.first; i + 1 < line.first + line.count; ++i)
    for (int k = 0; k <= 16; ++k)
      nearest = std::min(nearest, signedDistance(solid, x, x.col(i) + (x.col(i + 1) - x.col(i)) * (k / 16.0)));
  return nearest;
}

/// How deep the deepest point of `a`'s boundary edges lies inside the solid `b` at positions x [m] (< 0:
/// none is inside): each edge's ends and 15 points between, those inside b's bounding box judged by
/// signedDistance. Two closed surfaces cross only where an edge of one passes through the other.
double deepestEdgePoint(const BodyRange& a, const BodyRange& b, const NodeArray& x)
{
  Vec3 low = Vec3::Constant(INFINITY), high = -low;
  for (int i = b.first; i < b.first + b.count; ++i)
  {
    low = low.cwiseMin(x.col(i));
    high = high.cwiseMax(x.col(i));
  }
  const std::vector<std::pair<int, int>> edges = uniqueEdges(a.surface);
  double deepest = -INFINITY;
  const int points = 16;
  for (const auto& [i, j] : edges)
    for (int k = 0; k <= points; ++k)
    {
      const Vec3 p = x.col(i) + (x.col(j) - x.col(i)) * (static_cast<double>(k) / points);
      if ((p.array() >= low.array()).all() && (p.array() <= high.array()).all())
        deepest = std::max(deepest, -signedDistance(b, x, p));
    }
  return deepest;
}

/// `body` turned by `angle` [rad] about the vertical line through `centre`.
BodyDef turned(BodyDef body, const Vec3& centre, double angle)
{
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(angle, Vec3::UnitZ()).toRotationMatrix();
  for (NodeDef& node : body.nodes)
    node.position = centre + turn * (node.position - centre);
  return body;
}
}  // namespace

TEST(SurfaceContacts, TheNearestPointOnATriangleIsTheBruteForceOnes)
{
  // Against a dense sampling of the triangle: the sampled nearest point is within the sampling's spacing.
  std::mt19937 random(11);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const Vec3 a(0.0, 0.0, 0.0), b(1.0, 0.1, 0.0), c(0.3, 0.8, 0.2);
  const int samples = 400;
  for (int trial = 0; trial < 200; ++trial)
  {
    const Vec3 p(1.5 * uniform(random), 1.5 * uniform(random), uniform(random));
    const TrianglePoint on = nearestOnTriangle(p, a, b, c);
    EXPECT_NEAR(on.weight.sum(), 1.0, 1e-12);
    EXPECT_GE(on.weight.minCoeff(), -1e-12);
    EXPECT_TRUE((on.weight[0] * a + on.weight[1] * b + on.weight[2] * c).isApprox(on.point, 1e-12));
    double best = INFINITY;
    for (int i = 0; i <= samples; ++i)
      for (int j = 0; i + j <= samples; ++j)
      {
        const double u = static_cast<double>(i) / samples, v = static_cast<double>(j) / samples;
        best = std::min(best, (p - ((1.0 - u - v) * a + u * b + v * c)).norm());
      }
    const double found = (p - on.point).norm();
    EXPECT_LE(found, best + 1e-12);
    EXPECT_GT(found, best - 2.0 / samples);
  }
}

TEST(SurfaceContacts, TwoCubesRimsThatCrossTouchWhereTheyCrossAlongTheirCommonNormal)
{
  // A 10 cm cube, and another turned 45 degrees about the vertical and sunk 0.5 mm into its top: in plan the
  // lower top rim (|x| or |y| = 5 cm) and the upper bottom rim (|x| + |y| = 5 sqrt(2) cm) cross at eight
  // points, (5, 5 (sqrt(2) - 1)) cm and its mirror images. There SurfaceContacts finds eight touches of two
  // edges: the first edge's point on the lower rim at the crossing, the second's on the upper one 0.5 mm
  // below it, the normal straight down (out of the upper cube's bottom, into the lower cube) and the depth
  // 0.5 mm. No other pair of edges touches (the rims of the upper cube's sides are nowhere near, the edges
  // inside flat faces are left to the nodes).
  const double size = 0.1, sunk = 0.0005;
  SceneDef scene = floorScene(1.0 / 60.0);
  const Vec3 above(0.0, 0.0, 1.5 * size - sunk);
  scene.bodies = { cube("lower", size, Vec3(0.0, 0.0, 0.5 * size), 5.0e4, 0.3, 100.0, 0.5),
                   turned(cube("upper", size, above, 5.0e4, 0.3, 100.0, 0.5), above, 0.25 * M_PI) };
  World world = buildWorld(scene);
  const NodeArray& x = world.state().position;
  SurfaceContacts contacts(world.model());
  std::vector<SurfaceTouch> touches;
  contacts.find(world.model(), x, x, 1e-6, touches);
  const BodyRange& lower = world.model().bodies[0];
  const auto in_lower = [&](int node) { return node >= lower.first && node < lower.first + lower.count; };
  const double across = 0.5 * size * (std::sqrt(2.0) - 1.0);
  int edges = 0;
  for (const SurfaceTouch& touch : touches)
  {
    if (touch.edges < 0)
      continue;
    ++edges;
    Vec3 first = Vec3::Zero(), second = Vec3::Zero();
    for (std::size_t l = 0; l < 4; ++l)
    {
      EXPECT_EQ(in_lower(touch.nodes[l]), l < 2);
      (l < 2 ? first : second) += std::abs(touch.weights[l]) * x.col(touch.nodes[l]);
    }
    EXPECT_NEAR(touch.weights[0] + touch.weights[1], 1.0, 1e-12);
    EXPECT_NEAR(touch.weights[2] + touch.weights[3], -1.0, 1e-12);
    // At a crossing: one coordinate +-5 cm, the other +-across.
    const Vec3 plan(std::abs(first.x()), std::abs(first.y()), 0.0);
    EXPECT_NEAR(std::max(plan.x(), plan.y()), 0.5 * size, 1e-9) << first.transpose();
    EXPECT_NEAR(std::min(plan.x(), plan.y()), across, 1e-9) << first.transpose();
    EXPECT_NEAR(first.z(), size, 1e-12);
    EXPECT_TRUE((second - first).isApprox(Vec3(0.0, 0.0, -sunk), 1e-6)) << (second - first).transpose();
    EXPECT_TRUE(touch.normal.isApprox(-Vec3::UnitZ(), 1e-9)) << touch.normal.transpose();
    EXPECT_NEAR(touch.depth, sunk, 1e-9);
  }
  EXPECT_EQ(edges, 8);
}

TEST(SurfaceContacts, ACubeStackedOnAnotherPassesItsWeightDownAsElasticityHasIt)
{
  // Two 10 cm cubes of nu = 0 on the floor, the upper one let down 1 mm above the lower: at rest the lower
  // one carries its own weight (shortening rho g H^2 / (2 E)) and the upper one's (rho g H over its whole
  // height: rho g H^2 / E), 3/2 rho g H^2 / E in all; the upper one's top lies 2 rho g H^2 / E below its
  // rest height. That is for a uniform load; the contact loads the lower top face at the upper one's nodes,
  // so that its mean shortening is off by the mesh's resolution: 4.5 % short at 2.5 cm (4 tetrahedra
  // across), 1.9 % at 1.25 cm (measured). So: within 6 % at the coarse mesh, at a ROS node's step of
  // 1/60 s and at 1/240 s, and within 2.5 % and closer at the fine one (1/60 s), after 3 s (air drag 5/s
  // settles them). No node of one cube is ever inside the other.
  const double size = 0.1, density = 100.0, youngs_modulus = 5.0e4;
  const double unit = density * kGravity * size * size / youngs_modulus;  // 0.196 mm
  struct Case
  {
    double resolution, dt, tolerance;
  };
  double coarse_error = 0.0;
  for (const Case& c : { Case{ 0.025, 1.0 / 60.0, 0.06 }, Case{ 0.025, 1.0 / 240.0, 0.06 }, Case{ 0.0125, 1.0 / 60.0, 0.025 } })
  {
    SceneDef scene = floorScene(c.dt);
    const BodyDef lower = cube("lower", size, Vec3(0.0, 0.0, 0.5 * size), youngs_modulus, 0.0, density, 0.5, c.resolution);
    const BodyDef upper =
        cube("upper", size, Vec3(0.0, 0.0, 1.5 * size + 0.001), youngs_modulus, 0.0, density, 0.5, c.resolution);
    scene.bodies = { lower, upper };
    World world = buildWorld(scene);
    // How far a node of one cube lies inside the other (< 0: none does).
    const auto deepest = [&]() {
      double depth = -INFINITY;
      for (int b = 0; b < 2; ++b)
      {
        const BodyRange& body = world.model().bodies[static_cast<std::size_t>(b)];
        const BodyRange& other = world.model().bodies[static_cast<std::size_t>(1 - b)];
        for (int i = body.first; i < body.first + body.count; ++i)
          depth = std::max(depth, -signedDistance(other, world.state().position, world.state().position.col(i)));
      }
      return depth;
    };
    const int steps = static_cast<int>(std::lround(3.0 / c.dt));
    double landing = -INFINITY;
    for (int step = 0; step < steps; ++step)
    {
      world.step();
      if (step < steps / 6)  // the landing, in the first half second
        landing = std::max(landing, deepest());
    }
    const std::string at = "resolution " + std::to_string(c.resolution) + ", dt " + std::to_string(c.dt);
    EXPECT_LT(world.state().velocity.colwise().norm().maxCoeff(), 1e-5) << at;
    // Landing at v = sqrt(2 g 1 mm) = 0.14 m/s, a node goes no further into the other than a step's travel
    // h v (a hold's normal and triangle are those of the step's start); at rest, by no more than 1e-3 of
    // the shortening.
    EXPECT_LT(landing, c.dt * std::sqrt(2.0 * kGravity * 0.001)) << at;
    EXPECT_LT(deepest(), 1e-3 * unit) << at;
    const double shortening = size - meanZ(world, 0, lower, size);
    EXPECT_NEAR(shortening, 1.5 * unit, c.tolerance * 1.5 * unit) << at;
    EXPECT_NEAR(2.0 * size + 0.001 - meanZ(world, 1, upper, 2.0 * size + 0.001), 0.001 + 2.0 * unit,
                c.tolerance * 2.0 * unit)
        << at;
    const double error = std::abs(shortening - 1.5 * unit);
    if (c.resolution == 0.025)
      coarse_error = std::max(coarse_error, error);
    else
      EXPECT_LT(error, coarse_error) << at;
  }
}

TEST(SurfaceContacts, ACubeTurnedOnAnotherNeverCutsIntoItWithItsEdges)
{
  // Two 10 cm cubes on the floor, the upper one turned 45 degrees about the vertical and let down 1 mm
  // onto the lower: their rims cross at eight points, where neither has a node on the other's face, and
  // the upper one's corners overhang. Truth: no point of either's boundary edges is inside the other
  // (brute force: 17 points along every edge, each judged by the winding number) by more than a step's
  // travel h v while landing at 0.14 m/s, and at rest by more than 3 % of the lower cube's shortening
  // (3/2 rho g H^2 / E, as in the test above). At rest two piecewise flat surfaces that meet only at their
  // nodes still cross between them, by their faces' bending over a triangle: 6.6 um here (2.3 %; measured
  // at both steps). Without the rims' contact (SurfaceContacts' edges) the rims cut 11.7 um into each
  // other where they cross, and the faces 15.3 um (5.2 %).
  const double size = 0.1, density = 100.0, youngs_modulus = 5.0e4;
  const double shortening = 1.5 * density * kGravity * size * size / youngs_modulus;
  for (const double dt : { 1.0 / 60.0, 1.0 / 240.0 })
  {
    SceneDef scene = floorScene(dt);
    const Vec3 above(0.0, 0.0, 1.5 * size + 0.001);
    scene.bodies = { cube("lower", size, Vec3(0.0, 0.0, 0.5 * size), youngs_modulus, 0.3, density, 0.5),
                     turned(cube("upper", size, above, youngs_modulus, 0.3, density, 0.5), above, 0.25 * M_PI) };
    World world = buildWorld(scene);
    const BodyRange& lower = world.model().bodies[0];
    const BodyRange& upper = world.model().bodies[1];
    const auto deepest = [&]() {
      const NodeArray& x = world.state().position;
      return std::max(deepestEdgePoint(lower, upper, x), deepestEdgePoint(upper, lower, x));
    };
    const int steps = static_cast<int>(std::lround(3.0 / dt));
    double landing = -INFINITY;
    for (int step = 0; step < steps; ++step)
    {
      world.step();
      ASSERT_TRUE(allFinite(world.state()));
      if (step < steps / 6)
        landing = std::max(landing, deepest());
    }
    const std::string at = "dt " + std::to_string(dt);
    EXPECT_LT(world.state().velocity.colwise().norm().maxCoeff(), 1e-5) << at;
    EXPECT_LT(landing, dt * std::sqrt(2.0 * kGravity * 0.001)) << at;
    EXPECT_LT(deepest(), 0.03 * shortening) << at;
  }
}

TEST(SurfaceContacts, AClothDrapedOverACubeKeepsItsThicknessFromTheCubesRimsAndCorners)
{
  // A 40 cm cloth of 5 cm spacing, 5 mm thick, with face contacts, dropped 2 cm onto a 10 cm foam cube on
  // the floor, its node columns and rows 2.5 cm off the cube's rims: the rims run between its nodes and
  // the top corners lie under the middle of its squares. Truth, by brute force: the nearest that any point
  // of the cube's boundary edges (17 along each) comes to the cloth's triangles, and any point of the
  // cloth's triangles (its nodes and 17 points along each triangle's edge) to the cube's surface (negative
  // inside it: signedDistance). At rest that is the thickness, within 1 %. While it lands (0.63 m/s) and
  // settles, the cloth turns around the cube's corners within a step while each hold keeps its normal and
  // its point on the cloth through the step, as a rope over an edge does (the test above): never inside,
  // never nearer than 0.7 of the thickness (measured: 0.79 at 1/60 s, 0.86 at 1/240 s). With the cube
  // meeting the cloth only at the cloth's nodes, its top corners pierced the cloth by 18 mm (measured).
  const double size = 0.1, thickness = 0.005;
  for (const double dt : { 1.0 / 60.0, 1.0 / 240.0 })
  {
    SceneDef scene = floorScene(dt);
    ClothDef sheet;
    sheet.nx = sheet.ny = 9;
    sheet.corners.top_left = Vec3(-0.175, -0.175, size + 0.02);
    sheet.corners.top_right = Vec3(0.225, -0.175, size + 0.02);
    sheet.corners.bottom_left = Vec3(-0.175, 0.225, size + 0.02);
    sheet.mass = 0.05;
    sheet.structural = { 200.0, 0.02 };
    sheet.shear = { 50.0, 0.01 };
    sheet.bending = SpringParameters{ 2.0, 0.0 };
    sheet.thickness = thickness;
    sheet.face_contacts = true;
    scene.bodies = { cube("cube", size, Vec3(0.0, 0.0, 0.5 * size), 5.0e4, 0.3, 100.0, 0.5), buildCloth("cloth", sheet) };
    World world = buildWorld(scene);
    const Model& model = world.model();
    const BodyRange& solid = model.bodies[0];
    const std::vector<std::pair<int, int>> cube_edges = uniqueEdges(solid.surface);
    const std::vector<std::pair<int, int>> cloth_edges = uniqueEdges(model.contact_triangles);
    const int points = 16;
    // The nearest distance between the cube's edges and the cloth's triangles, and between the cloth's
    // edges and the cube's surface (negative where a cloth point is inside the cube).
    const auto nearest = [&]() {
      const NodeArray& x = world.state().position;
      double least = INFINITY;
      for (const auto& [i, j] : cube_edges)
        for (int k = 0; k <= points; ++k)
        {
          const Vec3 p = x.col(i) + (x.col(j) - x.col(i)) * (static_cast<double>(k) / points);
          for (const std::array<int, 3>& t : model.contact_triangles)
            least = std::min(least, (p - nearestOnTriangle(p, x.col(t[0]), x.col(t[1]), x.col(t[2])).point).norm());
        }
      for (const auto& [i, j] : cloth_edges)
        for (int k = 0; k <= points; ++k)
        {
          const Vec3 p = x.col(i) + (x.col(j) - x.col(i)) * (static_cast<double>(k) / points);
          if (p.z() < size + 2.0 * thickness && p.head<2>().cwiseAbs().maxCoeff() < 0.5 * size + 2.0 * thickness)
            least = std::min(least, signedDistance(solid, x, p));
        }
      return least;
    };
    double closest = INFINITY;
    for (int step = 0; step < static_cast<int>(std::lround(3.0 / dt)); ++step)
    {
      world.step();
      ASSERT_TRUE(allFinite(world.state()));
      if (step % 4 == 0 || dt > 0.01)
        closest = std::min(closest, nearest());
    }
    EXPECT_GT(closest, 0.7 * thickness) << "dt " << dt;
    EXPECT_NEAR(nearest(), thickness, 0.01 * thickness) << "dt " << dt;
    EXPECT_LT(world.state().velocity.colwise().norm().maxCoeff(), 1e-3) << "dt " << dt;
  }
}

TEST(SurfaceContacts, ARopeDroppedAcrossACubeRestsOnItsTopAndNeverEntersIt)
{
  // A 40 cm rope of radius 5 mm (41 nodes 1 cm apart, 20 g) dropped from 5 cm above a 10 cm foam cube
  // resting on the floor, across its middle: it lands on the top face at 1 m/s and hangs down both sides,
  // bent round the cube's rims. Across a rim node (y = 0) and between two (y = 6.25 mm; the rim's nodes
  // are 12.5 mm apart). Truth: the nearest that any point of the rope's axis (its nodes and 15 points
  // between each two) comes to the cube's surface (signedDistance), against its radius r. Its segments
  // meet the cube's rim nodes and rims, not only its nodes the cube's faces: at rest the axis keeps r from
  // the cube within 1 % (measured: 0.995 r at 1/60 s and 0.992 r at 1/240 s over a rim node, 0.9996 r and
  // 0.9998 r between two); by its nodes alone the chords over the rims came to 0.58 r and 0.38 r over a rim
  // node, 0.49 r and 0.38 r between two. Each hold's normal is kept through its step, while the rope turns
  // round the rims within a step (16 mm at 1/60 s), so that in the landing the axis comes to 0.71 r and
  // 0.69 r over a rim node, 0.39 r and 0.78 r between two (by its nodes alone 0.44 r and 0.38 r, 0.45 r and
  // 0.38 r): never inside, never nearer than 0.6 r over a rim node and 0.35 r between two. The rope's middle
  // lies on the top face at its radius.
  const double size = 0.1, radius = 0.005;
  struct Case
  {
    double y, landing;
  };
  for (const Case& c : { Case{ 0.0, 0.6 }, Case{ 0.00625, 0.35 } })
    for (const double dt : { 1.0 / 60.0, 1.0 / 240.0 })
    {
      SceneDef scene = floorScene(dt);
      scene.physics.drag = 1.0;
      scene.bodies = { cube("cube", size, Vec3(0.0, 0.0, 0.5 * size), 5.0e4, 0.3, 100.0, 0.5),
                       ropeAcross(size, radius, c.y) };
      World world = buildWorld(scene);
      const BodyRange& solid = world.model().bodies[0];
      const BodyRange& line = world.model().bodies[1];
      const auto closest = [&]() { return nearestAxisPoint(solid, line, world.state().position); };
      const std::string at = "y " + std::to_string(c.y) + ", dt " + std::to_string(dt);
      double landing = INFINITY;
      for (int step = 0; step < static_cast<int>(std::lround(10.0 / dt)); ++step)
      {
        world.step();
        ASSERT_TRUE(allFinite(world.state())) << at;
        if (step * dt < 1.0)
          landing = std::min(landing, closest());
      }
      EXPECT_GT(landing, c.landing * radius) << at;
      EXPECT_GT(closest(), 0.99 * radius) << at;
      const int middle = line.first + 20;
      EXPECT_NEAR(world.state().position(2, middle), meanZ(world, 0, scene.bodies[0], size) + radius, 0.02 * radius)
          << at;
      EXPECT_LT(world.state().velocity.colwise().norm().maxCoeff(), 1e-3) << at;
      // Its ends hang down the cube's sides, below its top.
      EXPECT_LT(world.state().position(2, line.first), size - 0.05) << at;
      EXPECT_LT(world.state().position(2, line.first + line.count - 1), size - 0.05) << at;
    }
}

TEST(SurfaceContacts, ARopeRestsOnAPinnedBlockWhoseFreeNodesFormChains)
{
  // A solid with every node pinned is a fixed block, and a rope's free nodes form a chain: alone they
  // would take the block-tridiagonal solve, which has no place for a hold's couplings to the block's
  // triangles. The 40 cm rope of radius 5 mm dropped across the 10 cm block comes to rest on its top face
  // at its radius and never enters it, at both steps. The same with two neighbouring nodes of the top face
  // left free under the rope: their pair and the rope again form chains, and the block gives under it.
  // Its axis (nodes and 15 points between each two) keeps within 1 % of r at rest (0.9999 r to r; by its
  // nodes alone the chords over the rims came to 0.38 to 0.54 r) and, landing, comes no nearer than 0.6 r
  // (0.72 to 0.86 r measured), as in the test above.
  const double size = 0.1, radius = 0.005;
  for (const bool two_free : { false, true })
    for (const double dt : { 1.0 / 60.0, 1.0 / 240.0 })
    {
      SceneDef scene = floorScene(dt);
      scene.physics.drag = 1.0;
      BodyDef block = cube("block", size, Vec3(0.0, 0.0, 0.5 * size), 5.0e4, 0.3, 100.0, 0.5);
      for (NodeDef& node : block.nodes)
        node.pinned = true;
      if (two_free)
      {
        // The top node nearest the rope's middle, and its top neighbour nearest the rope's line.
        const auto top = [&](std::size_t i) { return std::abs(block.nodes[i].position.z() - size) < 1e-9; };
        const auto off_middle = [&](std::size_t i) { return block.nodes[i].position.head<2>().norm(); };
        std::size_t middle = block.nodes.size();
        for (std::size_t i = 0; i < block.nodes.size(); ++i)
          if (top(i) && (middle == block.nodes.size() || off_middle(i) < off_middle(middle)))
            middle = i;
        std::size_t neighbour = middle;
        for (const Tetrahedron& tet : block.tetrahedra)
          for (const int a : tet.nodes)
            for (const int b : tet.nodes)
              if (static_cast<std::size_t>(a) == middle && b != a && top(static_cast<std::size_t>(b)) &&
                  (neighbour == middle ||
                   std::abs(block.nodes[static_cast<std::size_t>(b)].position.y()) < std::abs(block.nodes[neighbour].position.y())))
                neighbour = static_cast<std::size_t>(b);
        ASSERT_NE(neighbour, middle);
        block.nodes[middle].pinned = block.nodes[neighbour].pinned = false;
      }
      scene.bodies = { block, ropeAcross(size, radius) };
      World world = buildWorld(scene);
      const BodyRange& solid = world.model().bodies[0];
      const BodyRange& line = world.model().bodies[1];
      const std::string at = std::string(two_free ? "two free nodes" : "pinned") + ", dt " + std::to_string(dt);
      const auto distance = [&](int i) { return signedDistance(solid, world.state().position, world.state().position.col(i)); };
      const auto closest = [&]() { return nearestAxisPoint(solid, line, world.state().position); };
      double landing = INFINITY;
      for (int step = 0; step < static_cast<int>(std::lround(5.0 / dt)); ++step)
      {
        world.step();
        ASSERT_TRUE(allFinite(world.state())) << at;
        if (step * dt < 1.0)  // the landing
          landing = std::min(landing, closest());
      }
      EXPECT_GT(landing, 0.6 * radius) << at;
      EXPECT_GT(closest(), 0.99 * radius) << at;
      EXPECT_NEAR(distance(line.first + 20), radius, 0.02 * radius) << at;
      EXPECT_LT(world.state().velocity.colwise().norm().maxCoeff(), 1e-3) << at;
    }
}

}  // namespace soft_body_sim::test
