// Colliders (colliders.h, contact_stage.h): each shape's distance, normal and closest point against a brute-force
// reference; Coulomb friction on a tilted box against the closed form of a block on an incline; a
// conveyor dragging a node by friction relative to its own motion; a rope with two loads over a capsule
// against the capstan equation; a cloth dropped onto a sphere kept outside it by its thickness.
#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "soft_body_sim/core/bodies/cloth.h"
#include "soft_body_sim/core/bodies/rope.h"
#include "core/contact/shape_contacts.h"
#include "soft_body_sim/core/contact/contact_stage.h"
#include "test_util.h"

namespace soft_body_sim::test
{
namespace
{
constexpr double kPi = 3.14159265358979323846;
constexpr double kGravity = 9.81;

// --- geometry against brute force ---------------------------------------------------------------------

/// Points on the unit sphere, spread evenly (a Fibonacci lattice).
std::vector<Vec3> unitSpherePoints(int count)
{
  std::vector<Vec3> points;
  const double golden = kPi * (3.0 - std::sqrt(5.0));
  for (int k = 0; k < count; ++k)
  {
    const double z = 1.0 - 2.0 * (k + 0.5) / count;
    const double r = std::sqrt(1.0 - z * z);
    points.emplace_back(r * std::cos(golden * k), r * std::sin(golden * k), z);
  }
  return points;
}

/// A dense sampling of a surface and the spacing s of its samples: every surface point is within s of
/// one of them.
struct SampledSurface
{
  std::vector<Vec3> points;
  double spacing = 0.0;
};

SampledSurface sample(const Sphere& sphere)
{
  SampledSurface s;
  for (const Vec3& u : unitSpherePoints(40000))
    s.points.push_back(sphere.radius * u);
  s.spacing = sphere.radius * std::sqrt(4.0 * kPi / 40000.0);
  return s;
}

SampledSurface sample(const Capsule& capsule)
{
  SampledSurface s;
  const double r = capsule.radius, half = 0.5 * capsule.length;
  for (const Vec3& u : unitSpherePoints(20000))  // the two hemispheres
    s.points.push_back(r * u + Vec3(0, 0, u.z() >= 0.0 ? half : -half));
  const int around = 400, along = 600;
  for (int i = 0; i < around; ++i)
    for (int j = 0; j <= along; ++j)
    {
      const double a = 2.0 * kPi * i / around;
      s.points.emplace_back(r * std::cos(a), r * std::sin(a), -half + capsule.length * j / along);
    }
  s.spacing = std::max({ r * std::sqrt(4.0 * kPi / 20000.0), 2.0 * kPi * r / around, capsule.length / along }) * 2.0;
  return s;
}

SampledSurface sample(const Cylinder& cylinder)
{
  SampledSurface s;
  const double r = cylinder.radius, half = 0.5 * cylinder.length, step = 0.003;
  const int around = static_cast<int>(std::ceil(2.0 * kPi * r / step)), along = static_cast<int>(std::ceil(cylinder.length / step));
  for (int i = 0; i < around; ++i)
  {
    const double a = 2.0 * kPi * i / around;
    for (int j = 0; j <= along; ++j)  // the mantle
      s.points.emplace_back(r * std::cos(a), r * std::sin(a), -half + cylinder.length * j / along);
  }
  const int rings = static_cast<int>(std::ceil(r / step));
  for (const double z : { -half, half })  // the caps, as rings
    for (int k = 0; k <= rings; ++k)
    {
      const double rk = r * k / rings;
      const int count = std::max(1, static_cast<int>(std::ceil(2.0 * kPi * rk / step)));
      for (int i = 0; i < count; ++i)
        s.points.emplace_back(rk * std::cos(2.0 * kPi * i / count), rk * std::sin(2.0 * kPi * i / count), z);
    }
  s.spacing = 2.0 * step;
  return s;
}

SampledSurface sample(const Box& box)
{
  SampledSurface s;
  const Vec3 half = 0.5 * box.size;
  const double step = 0.004;
  for (int axis = 0; axis < 3; ++axis)
  {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    const int nu = static_cast<int>(std::ceil(box.size[u] / step)), nv = static_cast<int>(std::ceil(box.size[v] / step));
    for (const double side : { -1.0, 1.0 })
      for (int i = 0; i <= nu; ++i)
        for (int j = 0; j <= nv; ++j)
        {
          Vec3 p;
          p[axis] = side * half[axis];
          p[u] = -half[u] + box.size[u] * i / nu;
          p[v] = -half[v] + box.size[v] * j / nv;
          s.points.push_back(p);
        }
  }
  s.spacing = step * std::sqrt(2.0);
  return s;
}

/// Inside tests that do not use surfaceDistance.
bool inside(const Sphere& sphere, const Vec3& p) { return p.norm() < sphere.radius; }
bool inside(const Capsule& capsule, const Vec3& p)
{
  const double z = std::max(-0.5 * capsule.length, std::min(0.5 * capsule.length, p.z()));
  return (p - Vec3(0, 0, z)).norm() < capsule.radius;
}
bool inside(const Box& box, const Vec3& p) { return ((p.cwiseAbs() - 0.5 * box.size).array() < 0.0).all(); }
bool inside(const Cylinder& c, const Vec3& p)
{
  return std::hypot(p.x(), p.y()) < c.radius && std::abs(p.z()) < 0.5 * c.length;
}

template <typename Shape>
void expectAgreesWithBruteForce(const Shape& shape, const char* name)
{
  const SampledSurface surface = sample(shape);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> coordinate(-0.6, 0.6);
  for (int k = 0; k < 300; ++k)
  {
    const Vec3 p(coordinate(random), coordinate(random), coordinate(random));
    double nearest = 1e9;
    for (const Vec3& q : surface.points)
      nearest = std::min(nearest, (p - q).norm());
    const SurfaceDistance d = surfaceDistance(shape, p);
    SCOPED_TRACE(std::string(name) + " at (" + std::to_string(p.x()) + ", " + std::to_string(p.y()) + ", " +
                 std::to_string(p.z()) + ")");
    // The samples lie on the surface: their nearest is never nearer than the true distance, and at most
    // one spacing farther.
    EXPECT_LE(std::abs(d.distance), nearest + 1e-12);
    EXPECT_GE(std::abs(d.distance), nearest - surface.spacing);
    EXPECT_EQ(d.distance < 0.0, inside(shape, p));
    EXPECT_NEAR(d.normal.norm(), 1.0, 1e-12);
    // The closest point is on the surface (near a sample) and the point lies along the normal from it.
    double closest_to_sample = 1e9;
    for (const Vec3& q : surface.points)
      closest_to_sample = std::min(closest_to_sample, (d.closest - q).norm());
    EXPECT_LE(closest_to_sample, surface.spacing);
    EXPECT_LT((d.closest + d.distance * d.normal - p).norm(), 1e-12);
  }
}

/// One shape of each kind, about the origin, for the geometry tests.
struct TestShapes
{
  TestShapes()
  {
    sphere.radius = 0.3;
    capsule.radius = 0.12;
    capsule.length = 0.5;
    box.size = Vec3(0.5, 0.3, 0.2);
    cylinder.radius = 0.15;
    cylinder.length = 0.4;
  }
  Sphere sphere;
  Capsule capsule;
  Box box;
  Cylinder cylinder;
};

TEST(ColliderGeometry, DistanceNormalAndClosestPointAgreeWithABruteForceReference)
{
  const auto [sphere, capsule, box, cylinder] = TestShapes();
  expectAgreesWithBruteForce(cylinder, "cylinder");
  expectAgreesWithBruteForce(sphere, "sphere");
  expectAgreesWithBruteForce(capsule, "capsule");
  expectAgreesWithBruteForce(box, "box");
}

// Where a segment comes nearest a shape (shape_contacts.h: closed forms for spheres and capsules, a
// ternary search for boxes) against sampling the segment at 20,001 points.
TEST(ColliderGeometry, TheNearestPointOfASegmentAgreesWithSampling)
{
  const auto [sphere, capsule, box, cylinder] = TestShapes();
  std::mt19937 random(11);
  std::uniform_real_distribution<double> coordinate(-0.7, 0.7);
  // `search`: the ternary search's bracket, (2/3)^24 of the segment (0 for the closed forms).
  const auto check = [&](const auto& shape, const char* name, double search) {
    for (int k = 0; k < 200; ++k)
    {
      const Vec3 a(coordinate(random), coordinate(random), coordinate(random));
      const Vec3 d = Vec3(coordinate(random), coordinate(random), coordinate(random)) * 0.3;
      double best = 1e9;
      for (int i = 0; i <= 20000; ++i)
        best = std::min(best, surfaceDistance(shape, a + (i / 20000.0) * d).distance);
      const double t = nearestParameter(shape, a, d);
      SCOPED_TRACE(name);
      EXPECT_GE(t, 0.0);
      EXPECT_LE(t, 1.0);
      // Never farther than the best sample (but for the search's bracket), and samples lie 1/20000 of the
      // segment apart.
      EXPECT_LE(surfaceDistance(shape, a + t * d).distance, best + 1e-9 + search * d.norm());
      EXPECT_GE(surfaceDistance(shape, a + t * d).distance, best - d.norm() / 20000.0);
    }
  };
  check(sphere, "sphere", 0.0);
  check(capsule, "capsule", 0.0);
  check(box, "box", std::pow(2.0 / 3.0, 24));
  check(cylinder, "cylinder", std::pow(2.0 / 3.0, 24));
}

// --- a node on a tilted box ----------------------------------------------------------------------------

/// One free node of 1 kg resting on the top face of a large box tilted by `theta` about the x axis.
SceneDef nodeOnTiltedBox(IntegratorType integrator, double theta, double friction, double dt)
{
  SceneDef scene = oneBodyScene(integrator, dt);
  scene.physics.gravity = Vec3(0, 0, -kGravity);
  Box box;
  box.at.name = "ramp";
  box.at.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(theta, Vec3::UnitX()));
  box.at.friction = friction;
  box.size = Vec3(10.0, 10.0, 0.2);  // the fastest slide covers 2.2 m in the test
  scene.colliders.boxes.push_back(box);
  scene.bodies[0].nodes = { NodeDef{ box.at.orientation * Vec3(0, 0, 0.1), 1.0, Vec3::Zero(), false } };
  return scene;
}

// A block on an incline of angle theta with Coulomb friction mu stays put for tan(theta) < mu and
// otherwise slides down with a = g (sin(theta) - mu cos(theta)). At a ROS node's step (1/240 s) the
// discrete slide s_n = a h^2 n (n + 1) / 2 differs from a t^2 / 2 by 1/n = 0.4 % at n = 240.
TEST(ColliderFriction, ANodeOnATiltedBoxStaysPutBelowTheFrictionAngleAndSlidesAtTheClosedFormAbove)
{
  const double mu = 0.5, dt = 1.0 / 240.0;
  for (IntegratorType integrator : stableIntegrators(nodeOnTiltedBox(IntegratorType::Xpbd, 0.3, mu, dt)))
  {
    SCOPED_TRACE(integratorName(integrator));
    for (const double degrees : { 10.0, 25.0, 26.0, 35.0, 50.0 })
    {
      SCOPED_TRACE(std::to_string(degrees) + " degrees");
      const double theta = degrees * kPi / 180.0;
      World world = buildWorld(nodeOnTiltedBox(integrator, theta, mu, dt));
      const Vec3 start = world.state().position.col(0);
      const Vec3 down_slope = Eigen::AngleAxisd(theta, Vec3::UnitX()) * Vec3(0, -1, 0);
      for (int n = 0; n < 240; ++n)
        world.step();
      const Vec3 moved = Vec3(world.state().position.col(0)) - start;
      const double slid = moved.dot(down_slope);
      if (std::tan(theta) < mu)
      {
        EXPECT_LT(moved.norm(), 1e-12);
      }
      else
      {
        const double expected = 0.5 * kGravity * (std::sin(theta) - mu * std::cos(theta));
        EXPECT_NEAR(slid, expected, 0.01 * expected);
      }
      // Never into the box: on or above its top face.
      const Vec3 local = Eigen::AngleAxisd(theta, Vec3::UnitX()).inverse() * Vec3(world.state().position.col(0));
      EXPECT_GE(local.z(), 0.1 - 1e-12);
    }
  }
}

// A node resting on a conveyor (a box moving at V) is dragged by kinetic friction: its speed grows as
// mu g t until it reaches V at t = V / (mu g), then rides along.
TEST(ColliderFriction, AMovingBoxDragsARestingNodeUpToItsOwnSpeed)
{
  const double mu = 0.4, speed = 0.5, dt = 1.0 / 240.0;
  SceneDef scene = nodeOnTiltedBox(IntegratorType::SemiImplicitEuler, 0.0, mu, dt);
  scene.colliders.boxes[0].at.velocity = Vec3(speed, 0, 0);
  for (IntegratorType integrator : stableIntegrators(scene))
  {
    SCOPED_TRACE(integratorName(integrator));
    scene.physics.integrator = integrator;
    World world = buildWorld(scene);
    const int ramp_steps = 24;  // 0.1 s < V / (mu g) = 0.127 s
    for (int n = 0; n < ramp_steps; ++n)
      world.step();
    EXPECT_NEAR(world.state().velocity(0, 0), mu * kGravity * ramp_steps * dt, 0.02 * mu * kGravity * ramp_steps * dt);
    for (int n = 0; n < 96; ++n)
      world.step();
    EXPECT_NEAR(world.state().velocity(0, 0), speed, 1e-9);
    EXPECT_NEAR(world.state().position(2, 0), 0.1, 1e-9);
  }
}

// A collider that follows a path (as a tf frame drives it) lands on the path at every step's end and moves
// at the path's velocity in between, which friction sees: the conveyor above, driven by a path instead of
// a declared velocity, drags the node the same way, and a turning path's orientation is met exactly.
TEST(ColliderPath, APathDrivenColliderLandsOnItsPathAndDragsByItsVelocity)
{
  const double mu = 0.4, speed = 0.5, dt = 1.0 / 240.0;
  SceneDef scene = nodeOnTiltedBox(IntegratorType::SemiImplicitEuler, 0.0, mu, dt);
  Capsule marker;
  marker.at.name = "marker";
  marker.at.position = Vec3(0, 0, 5);
  marker.radius = 0.01;
  marker.length = 0.1;
  scene.colliders.capsules.push_back(marker);
  World world = buildWorld(scene);
  ASSERT_TRUE(world.followColliderPath("ramp", [speed](double t) {
    return std::optional<RigidPose>(RigidPose{ Vec3(speed * t, 0, 0), Eigen::Quaterniond::Identity() });
  }));
  ASSERT_TRUE(world.followColliderPath("marker", [](double t) {
    return std::optional<RigidPose>(
        RigidPose{ Vec3(0, 0, 5), Eigen::Quaterniond(Eigen::AngleAxisd(2.0 * t, Vec3::UnitZ())) });
  }));
  EXPECT_FALSE(world.followColliderPath("nothing", [](double) { return std::optional<RigidPose>(); }));
  for (int n = 0; n < 24; ++n)
    world.step();
  EXPECT_NEAR(world.state().velocity(0, 0), mu * kGravity * 24 * dt, 0.02 * mu * kGravity * 24 * dt);
  for (int n = 0; n < 96; ++n)
    world.step();
  EXPECT_NEAR(world.state().velocity(0, 0), speed, 1e-9);
  const std::vector<ColliderPose> poses = world.colliderPoses();
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_EQ(poses[0].name, "marker");  // capsules before boxes
  EXPECT_NEAR(poses[1].position.x(), speed * world.time(), 1e-12);
  const Eigen::Quaterniond expected(Eigen::AngleAxisd(2.0 * world.time(), Vec3::UnitZ()));
  EXPECT_NEAR(poses[0].orientation.angularDistance(expected), 0.0, 1e-9);
}

// A collider moved once (World::moveCollider, as Python's move_collider) is at its pose at the step's end and
// holds still there after it, instead of drifting on at the velocity of its one move; a node resting on it
// is dragged by that move's velocity while it lasts, and comes to rest again after.
TEST(ColliderPath, AColliderMovedOnceGlidesToItsPoseInOneStepAndStaysThere)
{
  const double mu = 0.4, dt = 1.0 / 240.0;
  SceneDef scene = nodeOnTiltedBox(IntegratorType::SemiImplicitEuler, 0.0, mu, dt);
  World world = buildWorld(scene);
  const RigidPose goal{ Vec3(0.002, 0, 0), Eigen::Quaterniond(Eigen::AngleAxisd(0.01, Vec3::UnitZ())) };
  ASSERT_TRUE(world.moveCollider("ramp", goal));
  EXPECT_FALSE(world.moveCollider("nothing", goal));
  world.step();
  EXPECT_GT(world.state().velocity(0, 0), 0.0);  // dragged by the box's 0.48 m/s during the step
  for (int n = 0; n < 120; ++n)
  {
    const ColliderPose pose = world.colliderPoses().at(0);
    EXPECT_EQ(pose.position, goal.position);
    EXPECT_EQ(pose.orientation.coeffs(), goal.orientation.normalized().coeffs());
    world.step();
  }
  EXPECT_NEAR(world.state().velocity(0, 0), 0.0, 1e-12);
}

// --- a rope's segments ----------------------------------------------------------------------------------

/// The distance [m] between segments p0-p1 and q0-q1, by brute force over 201 points of each.
double segmentDistance(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1)
{
  double nearest = 1e9;
  for (int i = 0; i <= 200; ++i)
    for (int j = 0; j <= 200; ++j)
      nearest = std::min(nearest, ((p0 + (p1 - p0) * (i / 200.0)) - (q0 + (q1 - q0) * (j / 200.0))).norm());
  return nearest;
}

// A gripper finger (a capsule of radius 1 cm) swept at 5 m/s through a hanging rope of 5 cm links, at a
// height between two of its nodes: the rope's segments, not only its nodes, meet the finger, so it
// pushes the rope along instead of passing between two nodes. Truth: at every step every segment keeps
// at least the finger's radius from its axis (brute-force distance; a sub-step moves the finger 5 mm, half
// its radius), and the rope's node next to the finger ends up ahead of where the finger passed it.
TEST(ColliderContact, AFingerSweptThroughAHangingRopePushesItAndNeverPassesThroughASegment)
{
  SceneDef scene;
  scene.physics.integrator = IntegratorType::Xpbd;
  scene.physics.step = StepSettings{ 1.0 / 240.0, 4, 4 };
  RopeDef rope;
  rope.nodes = 21;  // 5 cm links
  rope.from = Vec3(0, 0, 1.5);
  rope.to = Vec3(0, 0, 0.5);
  rope.mass = 0.1;
  rope.stiffness = 5000.0;
  rope.pinned = { 0 };
  scene.bodies.push_back(buildRope("rope", rope));
  Capsule finger;
  finger.at.name = "finger";
  finger.radius = 0.01;
  finger.length = 0.2;
  finger.at.position = Vec3(-0.3, 0, 1.025);  // between nodes 9 (z = 1.05) and 10 (z = 1.0)
  finger.at.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * kPi, Vec3::UnitX()));  // along y
  finger.at.velocity = Vec3(5.0, 0, 0);
  scene.colliders.capsules.push_back(finger);
  World world = buildWorld(scene);
  double closest = 1e9;
  for (int n = 0; n < 24; ++n)  // 0.1 s: the finger goes from x = -0.3 to 0.2 m
  {
    world.step();
    const Vec3 centre = world.colliderPoses()[0].position;
    const Vec3 end0 = centre - Vec3(0, 0.1, 0), end1 = centre + Vec3(0, 0.1, 0);
    for (int i = 0; i + 1 < rope.nodes; ++i)
      closest = std::min(closest, segmentDistance(world.state().position.col(i), world.state().position.col(i + 1),
                                                  end0, end1));
  }
  EXPECT_GE(closest, finger.radius - 1e-3);  // within the brute force's resolution (0.2 m / 200 along the finger)
  EXPECT_GT(world.state().position(0, 10), 0.2);  // pushed ahead of the finger's path, not left behind
}

// A rope whirled at 10 m/s (its tip) into a thin upright rod wraps around it: the part beyond the rod
// swings on around it, its tip winding more than a half turn about the rod's axis in 0.15 s (turning
// freely about the pinned end instead, it would wind 2.4 rad), while no link ever enters the rod
// (brute-force distance from the rod's axis, every step). The sub-step (1/1920 s) moves the tip 5.2 mm, less than the rod's and
// rope's radii together (7 mm), the rule against passing through of docs/scenes.md, "Colliders".
TEST(ColliderContact, ARopeWhirledAt10MetresPerSecondWrapsAroundAThinRod)
{
  SceneDef scene;
  scene.physics.integrator = IntegratorType::Xpbd;
  scene.physics.step = StepSettings{ 1.0 / 240.0, 8, 2 };
  scene.physics.gravity = Vec3::Zero();
  RopeDef rope;
  rope.nodes = 41;  // 2.5 cm links
  rope.from = Vec3(0, 0, 1);
  rope.to = Vec3(1, 0, 1);
  rope.mass = 0.05;
  rope.stiffness = 2e4;
  rope.radius = 0.002;
  rope.pinned = { 0 };
  BodyDef body = buildRope("rope", rope);
  for (NodeDef& node : body.nodes)
    node.velocity = Vec3(0, 10.0 * node.position.x(), 0);  // turning about the pinned end at 10 rad/s
  scene.bodies.push_back(body);
  Capsule rod;
  rod.at.name = "rod";
  rod.at.position = Vec3(0.5, 0.2, 1);
  rod.radius = 0.005;
  rod.length = 0.4;
  scene.colliders.capsules.push_back(rod);
  World world = buildWorld(scene);
  double closest = 1e9, winding = 0.0;
  const auto bearing = [&] {
    const Vec3 from_rod = Vec3(world.state().position.col(rope.nodes - 1)) - rod.at.position;
    return std::atan2(from_rod.y(), from_rod.x());
  };
  double previous = bearing();
  for (int n = 0; n < 36; ++n)  // 0.15 s
  {
    world.step();
    winding += std::remainder(bearing() - previous, 2.0 * kPi);
    previous = bearing();
    for (int i = 0; i + 1 < rope.nodes; ++i)
      closest = std::min(closest, segmentDistance(world.state().position.col(i), world.state().position.col(i + 1),
                                                  Vec3(0.5, 0.2, 0.8), Vec3(0.5, 0.2, 1.2)));
  }
  EXPECT_GE(closest, rod.radius + rope.radius - 1e-3);
  EXPECT_GT(winding, kPi);
  RecordProperty("tip_winding_rad", std::to_string(winding));
}

// --- the capstan ------------------------------------------------------------------------------------------

/// A rope over a fixed horizontal capsule with friction mu: its nodes on a half circle of radius
/// R + r over the top (`arc_links` links), straight ends hanging `hang` [m] down, a cord of
/// `density` [kg/m], and loads m1 (at x < 0) and m2 (x > 0) on its end nodes. Inextensible links.
struct CapstanRig
{
  double mu = 0.3;
  double capsule_radius = 0.05;
  double rope_radius = 0.002;
  int arc_links = 24;
  double hang = 0.3;
  double density = 0.05;
  double m1 = 0.5;

  double arcRadius() const { return capsule_radius + rope_radius; }
  double link() const { return kPi * arcRadius() / arc_links; }
  int hangingLinks() const { return static_cast<int>(std::round(hang / link())); }
  double nodeMass() const { return density * link(); }
  /// The mass [kg] below the node where the rope leaves the capsule on the side of load m.
  double below(double m) const { return m + hangingLinks() * nodeMass(); }

  /// The polygon's capstan ratio: the n - 1 nodes inside the arc bend the rope by d = pi / n and the two
  /// where it leaves the capsule by d / 2; a node bent by b, pressed on by (T1 + T2) sin(b / 2), holds
  /// (T2 - T1) cos(b / 2) along it, so T2 / T1 <= (1 + mu tan(b / 2)) / (1 - mu tan(b / 2)). It tends to
  /// e^(mu pi) as n grows (0.14 % above it for 24 links and mu = 0.3).
  double bound() const
  {
    const auto node = [this](double bend) {
      const double t = mu * std::tan(0.5 * bend);
      return (1.0 + t) / (1.0 - t);
    };
    const double d = kPi / arc_links;
    return std::pow(node(d), arc_links - 1) * node(0.5 * d) * node(0.5 * d);
  }

  SceneDef scene(double m2) const
  {
    SceneDef scene;
    scene.physics.integrator = IntegratorType::Xpbd;
    scene.physics.step = StepSettings{ 1.0 / 60.0, 8, 1 };
    Capsule rod;
    rod.at.name = "rod";
    rod.at.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * kPi, Vec3::UnitX()));  // axis along y
    rod.at.friction = mu;
    rod.radius = capsule_radius;
    rod.length = 0.2;
    scene.colliders.capsules.push_back(rod);
    BodyDef rope;
    rope.name = "rope";
    rope.contact_radius = rope_radius;
    const auto add = [&](const Vec3& x) { rope.nodes.push_back(NodeDef{ x, nodeMass(), Vec3::Zero(), false }); };
    for (int k = hangingLinks(); k > 0; --k)
      add(Vec3(-arcRadius(), 0, -k * link()));
    for (int k = 0; k <= arc_links; ++k)
    {
      const double angle = kPi * (1.0 - static_cast<double>(k) / arc_links);  // from x < 0 over the top
      add(arcRadius() * Vec3(std::cos(angle), 0, std::sin(angle)));
    }
    for (int k = 1; k <= hangingLinks(); ++k)
      add(Vec3(arcRadius(), 0, -k * link()));
    rope.nodes.front().mass += m1;
    rope.nodes.back().mass += m2;
    for (int i = 0; i + 1 < static_cast<int>(rope.nodes.size()); ++i)
    {
      rope.constraints.push_back(ConstraintDef{ i, i + 1, 0.0, std::nullopt });
      rope.contact_segments.emplace_back(i, i + 1);
    }
    scene.bodies.push_back(rope);
    return scene;
  }

  /// How far [m] load m2 falls in t [s] once it slides: the rope runs over the capsule at one speed, the
  /// tensions where it leaves the capsule in the kinetic capstan ratio E = bound(),
  ///   T2 = M2 (g - a),  T1 = M1 (g + a),  T2 = E T1,  so  a = g (M2 - E M1) / (M2 + E M1),
  /// with M1, M2 the masses below those points, which change as rope runs from one side to the other
  /// (the rope on the capsule, 0.3 % of the moving mass, is left out). Integrated by small steps.
  double slid(double m2, double t) const
  {
    double s = 0.0, v = 0.0;
    const double dt = 1e-5;
    for (double time = 0.0; time < t; time += dt)
    {
      const double big = below(m2) + density * s, small = below(m1) - density * s, e = bound();
      v += dt * kGravity * (big - e * small) / (big + e * small);
      s += dt * v;
    }
    return s;
  }
};

// The capstan equation (Euler-Eytelwein): a rope over a fixed cylinder with friction mu, wrapped by pi,
// holds loads whose tensions differ by less than e^(mu pi) and slides otherwise, keeping that ratio. At
// 0.9 times the bound (of the rope's polygon, CapstanRig::bound) the loads stay within 1 mm for a second
// (they settle as the rope takes up its tension); at 1.1 times it load m2 falls as the kinetic capstan
// says, within 10 % (the rope's own weight on the capsule, left out of the reference, presses it on by
// 1.6 % of the loads' weight).
TEST(ColliderFriction, ARopeOverACapsuleHoldsBelowTheCapstanBoundAndSlidesAboveIt)
{
  const CapstanRig rig;
  const double seconds = 1.0;
  for (const double factor : { 0.9, 1.1 })
  {
    SCOPED_TRACE("T2 / T1 = " + std::to_string(factor) + " of the bound");
    const double m2 = factor * rig.bound() * rig.below(rig.m1) - (rig.below(rig.m1) - rig.m1);
    World world = buildWorld(rig.scene(m2));
    const int last = world.model().nodeCount() - 1;
    const double start = world.state().position(2, last);
    for (int n = 0; n < static_cast<int>(std::round(seconds * 60.0)); ++n)
    {
      world.step();
      ASSERT_TRUE(world.takeDivergenceEvents().empty());
    }
    const double fallen = start - world.state().position(2, last);
    RecordProperty("fallen_" + std::to_string(factor), std::to_string(fallen));
    if (factor < 1.0)
    {
      EXPECT_LT(std::abs(fallen), 1e-3);
    }
    else
    {
      const double expected = rig.slid(m2, seconds);
      EXPECT_NEAR(fallen, expected, 0.1 * expected);
    }
  }
}

// --- a cloth onto a sphere -------------------------------------------------------------------------------

TEST(ColliderContact, AClothDroppedOntoASphereRestsOnItNoNodeCloserThanRadiusPlusThickness)
{
  const double radius = 0.3, thickness = 0.01;
  SceneDef scene;
  scene.physics.integrator = IntegratorType::Xpbd;
  scene.physics.step = StepSettings{ 1.0 / 120.0, 4, 2 };
  scene.physics.drag = 0.5;
  Sphere sphere;
  sphere.at.name = "ball";
  sphere.at.friction = 0.5;
  sphere.radius = radius;
  scene.colliders.spheres.push_back(sphere);
  ClothDef cloth;
  cloth.nx = cloth.ny = 21;
  cloth.corners = GridCorners{ Vec3(-0.5, 0.5, 0.5), Vec3(0.5, 0.5, 0.5), Vec3(-0.5, -0.5, 0.5) };
  cloth.mass = 0.2;
  cloth.structural = { 2000.0, 0.5 };
  cloth.shear = { 500.0, 0.5 };
  scene.bodies.push_back(buildCloth("cloth", cloth));
  scene.bodies[0].contact_radius = thickness;
  World world = buildWorld(scene);
  double closest = 1e9;
  for (int n = 0; n < 720; ++n)  // 6 s
  {
    world.step();
    closest = std::min(closest, world.state().position.colwise().norm().minCoeff());
  }
  EXPECT_GE(closest, radius + thickness - 1e-9);
  // It rests: draped over the ball (its middle on top), nearly still.
  const int middle = (cloth.ny / 2) * cloth.nx + cloth.nx / 2;
  EXPECT_NEAR(world.state().position(2, middle), radius + thickness, 1e-3);
  EXPECT_LT(world.state().velocity.colwise().norm().maxCoeff(), 0.05);
  RecordProperty("max_speed_at_6s", std::to_string(world.state().velocity.colwise().norm().maxCoeff()));
}

}  // namespace
}  // namespace soft_body_sim::test
