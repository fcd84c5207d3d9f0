// Self-collision (self_contacts.h): the spatial hash never misses a pair of segments within reach
// (against all pairs, by brute force); a rope dropped in a coil onto the floor keeps every two of its
// links at least its diameter apart (brute-force distances), where without self-collision it passes
// through itself.
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "soft_body_sim/core/bodies/cloth.h"
#include "soft_body_sim/core/bodies/rod.h"
#include "soft_body_sim/core/bodies/rope.h"
#include "soft_body_sim/core/contact/self_contacts.h"
#include "soft_body_sim/scene/scene_loader.h"
#include "test_util.h"

namespace soft_body_sim::test
{
namespace
{
constexpr double kPi = 3.14159265358979323846;
constexpr double kGravity = 9.81;  // [m/s^2], PhysicsDef's default

/// An empty scene stepped by xpbd at 1/60 s with 8 sub-steps and 2 iterations, with a floor at z = 0 of
/// Coulomb coefficient `floor_friction` (none if negative).
SceneDef xpbdScene(double floor_friction)
{
  SceneDef scene;
  scene.physics.integrator = IntegratorType::Xpbd;
  scene.physics.step = StepSettings{ 1.0 / 60.0, 8, 2 };
  if (floor_friction >= 0.0)
    scene.colliders.planes.push_back(Plane{ Vec3::Zero(), Vec3::UnitZ(), 0.0, floor_friction });
  return scene;
}

/// The distance [m] between segments p0-p1 and q0-q1: the distance from the point p(u) = p0 + u (p1 - p0)
/// to q's segment (its projection clamped to the segment, exact) is convex in u (the distance to a
/// convex set along a line), so a golden-section search over u in [0, 1] finds its least value; 60
/// steps narrow u to 0.618^60 = 3e-13.
double segmentDistance(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1)
{
  const Vec3 d = q1 - q0;
  const double length2 = d.squaredNorm();
  const auto distance = [&](double u) {
    const Vec3 p = p0 + u * (p1 - p0);
    const double t = length2 > 0.0 ? std::clamp((p - q0).dot(d) / length2, 0.0, 1.0) : 0.0;
    return (p - (q0 + t * d)).norm();
  };
  const double golden = 0.5 * (std::sqrt(5.0) - 1.0);
  double low = 0.0, high = 1.0;
  double left = high - golden * (high - low), right = low + golden * (high - low);
  double at_left = distance(left), at_right = distance(right);
  for (int step = 0; step < 60; ++step)
    if (at_left < at_right)
    {
      high = right;
      right = left;
      at_right = at_left;
      left = high - golden * (high - low);
      at_left = distance(left);
    }
    else
    {
      low = left;
      left = right;
      at_left = at_right;
      right = low + golden * (high - low);
      at_right = distance(right);
    }
  return std::min({ distance(0.0), distance(1.0), at_left, at_right });
}

// 1000 random segments up to 5 cm long in a 0.5 m box, each as a ball about its midpoint through its
// ends: every pair within 1 cm of each other (all pairs, brute force) is among those the grid visits, each
// visited at most once and in ascending order of its first; and every segment within 1 cm of a point is
// among those visited about it.
TEST(BallGrid, VisitsEveryPairAndEveryBallWithinReachOnce)
{
  std::mt19937 random(7);
  std::uniform_real_distribution<double> box(0.0, 0.5), offset(-0.025, 0.025);
  const int count = 1000;
  NodeArray x(3, 2 * count), middle(3, count);
  std::vector<double> half(count);
  for (int s = 0; s < count; ++s)
  {
    x.col(2 * s) = Vec3(box(random), box(random), box(random));
    x.col(2 * s + 1) = x.col(2 * s) + Vec3(offset(random), offset(random), offset(random));
    middle.col(s) = 0.5 * (x.col(2 * s) + x.col(2 * s + 1));
    half[static_cast<std::size_t>(s)] = 0.5 * (x.col(2 * s) - x.col(2 * s + 1)).norm();
  }
  const double reach = 0.01;
  const double longest = 2.0 * *std::max_element(half.begin(), half.end());
  BallGrid grid;
  grid.build(middle, half, longest + reach);
  std::set<std::pair<std::size_t, std::size_t>> visited;
  int repeats = 0;
  grid.forEachNearPair(reach, [&](std::size_t s, std::size_t t) {
    repeats += visited.insert({ s, t }).second ? 0 : 1;
    EXPECT_LT(s, t);
  });
  EXPECT_EQ(repeats, 0);
  int within = 0;
  for (int s = 0; s < count; ++s)
    for (int t = s + 1; t < count; ++t)
      if (segmentDistance(x.col(2 * s), x.col(2 * s + 1), x.col(2 * t), x.col(2 * t + 1)) <= reach)
      {
        ++within;
        EXPECT_TRUE(visited.count({ static_cast<std::size_t>(s), static_cast<std::size_t>(t) }))
            << "pair " << s << ", " << t << " missed";
      }
  EXPECT_GT(within, 50);  // the scene has such pairs to miss
  RecordProperty("pairs_within_reach", within);
  RecordProperty("pairs_visited", static_cast<int>(visited.size()));
  int near_points = 0;
  for (int k = 0; k < 200; ++k)
  {
    const Vec3 point(box(random), box(random), box(random));
    std::set<std::size_t> around;
    grid.forEachNear(point, 0.0, reach, [&](std::size_t t) { EXPECT_TRUE(around.insert(t).second) << t; });
    for (int t = 0; t < count; ++t)
      if (segmentDistance(point, point, x.col(2 * t), x.col(2 * t + 1)) <= reach)
      {
        ++near_points;
        EXPECT_TRUE(around.count(static_cast<std::size_t>(t))) << "segment " << t << " missed near point " << k;
      }
  }
  EXPECT_GT(near_points, 10);
}

// The Verlet list's rule: two cloths of 10 x 10 nodes (2.5 cm apart, 1 cm thick, self-colliding), one
// 1.5 cm above the other, so that every node of the upper one touches the lower one (contact distance
// 2 cm). Carried together by 1.5 cm at a time, at least half the skin (3 thicknesses for balls, 2 for
// edges) each time, the list found at the start holds (one search in 40 moves), and each resolution
// equals that of a fresh search at the moved positions bit for bit (the pairs are taken in an order no
// search changes). A node moved 4 cm relative to the others (2 cm from the middle of the displacements)
// makes it search again. By the cloths' nodes as balls, and by their triangles' edges and faces.
class CandidateList : public ::testing::TestWithParam<bool>
{
};
TEST_P(CandidateList, HoldsWhileEverythingMovesTogetherAndEqualsAFreshSearch)
{
  SceneDef scene = xpbdScene(-1.0);
  for (const double height : { 0.0, 0.015 })
  {
    ClothDef cloth;
    cloth.nx = 10;
    cloth.ny = 10;
    cloth.corners = GridCorners{ Vec3(0, 0, height), Vec3(0.225, 0, height), Vec3(0, 0.225, height) };
    cloth.thickness = 0.01;
    cloth.self_collision = true;
    cloth.face_contacts = GetParam();
    scene.bodies.push_back(buildCloth(height > 0.0 ? "upper" : "lower", cloth));
  }
  const World world = buildWorld(scene);
  const Model& model = world.model();
  const State rest = world.state();
  SelfContacts carried(model, rest.position);
  const Vec3 step(0.015, 0.0, 0.0);
  for (int k = 0; k < 40; ++k)
  {
    State moved = rest;
    moved.position.colwise() += static_cast<double>(k) * step;
    State fresh_moved = moved;
    SelfContacts fresh(model, rest.position);
    carried.remember(moved);  // as a sub-step does before its integration: where a face's nodes start
    fresh.remember(fresh_moved);
    EXPECT_TRUE(carried.resolve(model, moved));
    EXPECT_TRUE(fresh.resolve(model, fresh_moved));
    EXPECT_TRUE((moved.position.array() == fresh_moved.position.array()).all()) << "move " << k;
    EXPECT_TRUE((moved.velocity.array() == fresh_moved.velocity.array()).all()) << "move " << k;
  }
  EXPECT_EQ(carried.searches(), 1u);
  State apart = rest;
  apart.position.col(150) += Vec3(0.0, 0.0, 0.04);
  carried.remember(apart);
  carried.resolve(model, apart);
  EXPECT_EQ(carried.searches(), 2u);
}
INSTANTIATE_TEST_SUITE_P(Cloths, CandidateList, ::testing::Values(false, true),
                         [](const ::testing::TestParamInfo<bool>& info) { return info.param ? "by_faces" : "by_nodes"; });

/// A 3 m rope of radius 5 mm (121 nodes, 2.5 cm links) in a loose coil: a helix of radius 0.1 m and
/// 2 cm pitch, from 0.29 m above the floor down, dropped onto the floor (friction 0.5). xpbd at 1/60 s
/// with 8 sub-steps: a fall of 0.29 m reaches 2.39 m/s, 4.97 mm per sub-step, within one radius (the
/// loader's rule against passing through, tunnellingRisk).
SceneDef coil(bool self_collision)
{
  const int nodes = 121;
  const double radius = 0.005, coil_radius = 0.1, link = 0.025;
  const double turn = 2.0 * kPi * coil_radius, pitch = 0.02;
  SceneDef scene = xpbdScene(0.5);
  RopeDef rope;
  rope.nodes = nodes;
  rope.mass = 0.15;
  rope.stiffness = 1e4;
  rope.damping = 0.05;
  rope.radius = radius;
  BodyDef body = buildRope("rope", rope);
  for (int i = 0; i < nodes; ++i)
  {
    const double along = i * link, angle = along / coil_radius;
    body.nodes[static_cast<std::size_t>(i)].position =
        Vec3(coil_radius * std::cos(angle), coil_radius * std::sin(angle), 0.29 - pitch * along / turn);
  }
  // Links at rest in the coil (buildRope measured them along the straight line).
  for (SpringDef& spring : body.springs)
    spring.rest_length.reset();
  body.self_collision = self_collision;
  scene.bodies.push_back(body);
  return scene;
}

/// The least distance [m] between two links of the rope more than kSkippedLinks apart.
double closestLinks(const World& world)
{
  const NodeArray& x = world.state().position;
  const int links = world.model().nodeCount() - 1;
  double closest = 1e300;
  for (int i = 0; i < links; ++i)
    for (int j = i + SelfContacts::kSkippedLinks + 1; j < links; ++j)
      closest = std::min(closest, segmentDistance(x.col(i), x.col(i + 1), x.col(j), x.col(j + 1)));
  return closest;
}

// The coil falls onto the floor and its turns pile on each other: at the end of every step for 1.5 s,
// every two links (not neighbours) stay at least the rope's diameter apart, less 10 % (a sub-step's push
// apart is exact for one pair; links pressed from several sides at once keep part of their overlap).
// Without self-collision the same coil collapses into one layer, its links through each other.
TEST(SelfContacts, ACoiledRopeDroppedOnTheFloorNeverPassesThroughItself)
{
  const double diameter = 0.01;
  for (const bool self_collision : { true, false })
  {
    SCOPED_TRACE(self_collision ? "self_collision" : "without");
    const SceneDef scene = coil(self_collision);
    EXPECT_FALSE(tunnellingRisk(scene, scene.physics.step).has_value());
    World world = buildWorld(scene);
    double closest = closestLinks(world);
    for (int n = 0; n < 90; ++n)
    {
      world.step();
      ASSERT_TRUE(world.takeDivergenceEvents().empty());
      closest = std::min(closest, closestLinks(world));
    }
    RecordProperty(self_collision ? "closest_with" : "closest_without", std::to_string(closest));
    if (self_collision)
      EXPECT_GE(closest, 0.9 * diameter);
    else
      EXPECT_LT(closest, 0.5 * diameter);
  }
}

// A rod's segments keep apart by its radius as a rope's do (docs/scenes.md, "Rods"). The cable of cable.yaml, its
// tip moved half its length in and turned four turns in 2 s: the twist coils the sagging slack into a
// plectoneme, whose turns press on each other. With self-collision every two segments (not neighbours)
// stay at least the diameter apart, less 10 % (as the coil above; measured 0.94 of it); without, the coil
// passes through itself (measured 0.16 of it).
TEST(SelfContacts, ATwistedRodCoilingIntoAPlectonemeNeverPassesThroughItself)
{
  const double diameter = 0.01;
  for (const bool self_collision : { true, false })
  {
    SCOPED_TRACE(self_collision ? "self_collision" : "without");
    RodDef def;
    def.nodes = 41;
    def.from = Vec3(-0.5, 0.0, 1.0);
    def.to = Vec3(0.5, 0.0, 1.0);
    def.radius = 0.5 * diameter;
    def.youngs_modulus = 5.0e7;
    def.shear_modulus = 1.9e7;
    def.density = 1500.0;
    def.damping = 0.02;
    def.clamped = { 0 };
    def.self_collision = self_collision;
    SceneDef scene;
    scene.physics.integrator = IntegratorType::ImplicitEuler;
    scene.physics.step = StepSettings{ 0.004, 1, 1 };
    scene.physics.drag = 0.5;
    BodyDef body = buildRod("cable", def);
    body.anchors.push_back(AnchorDef("tip", def.nodes - 1));
    scene.bodies.push_back(body);
    World world = buildWorld(scene);
    const int tip = *world.findAnchor("cable", "tip");
    double closest = closestLinks(world);
    const int steps = 1000;  // 4 s
    for (int n = 1; n <= steps; ++n)
    {
      const double s = std::min(1.0, 2.0 * n / steps);  // moved and turned in the first 2 s
      world.moveAnchor(tip, Vec3(0.5 - 0.5 * s, 0.0, 1.0), Eigen::Quaterniond(Eigen::AngleAxisd(8.0 * kPi * s, Vec3::UnitX())));
      world.step();
      ASSERT_TRUE(world.takeDivergenceEvents().empty());
      closest = std::min(closest, closestLinks(world));
    }
    RecordProperty(self_collision ? "closest_with" : "closest_without", std::to_string(closest));
    if (self_collision)
      EXPECT_GE(closest, 0.9 * diameter);
    else
      EXPECT_LT(closest, 0.5 * diameter);
  }
}

// --- friction between links: a rope in a tilted groove ---------------------------------------------------

/// Two straight rails (ropes pinned at every node, `rail_nodes` of them) 2 m long, tilted by theta about
/// the y axis, downhill towards +x, and a free rope 0.3 m long lying in the groove between them: every rope
/// 5 mm in radius, the rails 2 r sin(alpha) either side of the free rope's axis so that it touches them
/// along normals at alpha = 45 degrees from the groove's upward normal. Coulomb friction `friction` on
/// every rope.
SceneDef ropeInAGroove(double theta, double friction, int rail_nodes)
{
  const double radius = 0.005, alpha = kPi / 4.0;
  const Vec3 down(std::cos(theta), 0.0, -std::sin(theta)), up(std::sin(theta), 0.0, std::cos(theta));
  const Vec3 side = Vec3::UnitY() * 2.0 * radius * std::sin(alpha);
  SceneDef scene = xpbdScene(-1.0);
  for (const double sign : { -1.0, 1.0 })
  {
    RopeDef rail;
    rail.nodes = rail_nodes;
    rail.from = sign * side;
    rail.to = rail.from + 2.0 * down;
    rail.mass = 1.0;
    rail.stiffness = 1e4;
    rail.radius = radius;
    for (int i = 0; i < rail.nodes; ++i)
      rail.pinned.push_back(i);
    BodyDef body = buildRope(sign < 0 ? "left_rail" : "right_rail", rail);
    body.self_collision = true;
    body.self_friction = friction;
    scene.bodies.push_back(body);
  }
  RopeDef rope;
  rope.nodes = 16;
  rope.from = 2.0 * radius * std::cos(alpha) * up + 0.2 * down;
  rope.to = rope.from + 0.3 * down;
  rope.mass = 0.03;
  rope.stiffness = 1e4;
  rope.damping = 0.01;
  rope.radius = radius;
  BodyDef body = buildRope("rope", rope);
  body.self_collision = true;
  body.self_friction = friction;
  scene.bodies.push_back(body);
  return scene;
}

// A body in a V-groove, its two contact normals at alpha either side of the groove's normal, is pressed on
// each side by N = m g cos(theta) / (2 cos(alpha)): it stays put while tan(theta) < mu / cos(alpha) and
// otherwise slides with a = g (sin(theta) - mu cos(theta) / cos(alpha)) (the tilted plane's closed form
// with the wedge's larger normal force). mu = 0.3, alpha = 45 degrees: the bound is tan(theta) = 0.424.
// At 0.8 times it the rope stays within 1 mm in 1 s; at 1.2 times it slides 0.37 m, and the friction
// coefficient that its slide implies is mu within 6 %. That error depends on how the rails' joints fall
// under the rope's (-2.4 % to +4.7 % for rail links of 1, 2, 2.5 and 5 cm under a rope of 2 cm links):
// where a link lies along a chain of others, its pairs with the two links meeting at a joint share one
// contact, and the share moves as the rope slides past the joint. Closer to the bound, at 0.9 times it,
// the rope creeps by ~2 mm/s at 8 sub-steps (1 mm/s at 16): each contact holds its own share, and a link
// short of its share in a sub-step slips before its neighbours' surplus reaches it through the chain.
TEST(SelfContacts, ARopeInATiltedGrooveHoldsBelowTheWedgeFrictionAngleAndSlidesAtTheClosedFormAbove)
{
  const double mu = 0.3, alpha = kPi / 4.0, bound = mu / std::cos(alpha);
  for (const int rail_nodes : { 41, 81, 101, 201 })
    for (const double factor : { 0.8, 1.2 })
    {
      SCOPED_TRACE("rails of " + std::to_string(rail_nodes) + " nodes, tan(theta) = " + std::to_string(factor) +
                   " x the bound");
      const double theta = std::atan(factor * bound);
      World world = buildWorld(ropeInAGroove(theta, mu, rail_nodes));
      const int first = 2 * rail_nodes;
      const Vec3 down(std::cos(theta), 0.0, -std::sin(theta));
      const auto centre = [&] { return Vec3(world.state().position.middleCols(first, 16).rowwise().mean()); };
      const Vec3 start = centre();
      const int steps = 60;
      for (int n = 0; n < steps; ++n)
      {
        world.step();
        ASSERT_TRUE(world.takeDivergenceEvents().empty());
      }
      const double slid = (centre() - start).dot(down);
      const double t = steps / 60.0;
      if (factor < 1.0)
      {
        EXPECT_LT(std::abs(slid), 1e-3);
      }
      else
      {
        const double implied =
            (std::sin(theta) - 2.0 * slid / (t * t) / kGravity) * std::cos(alpha) / std::cos(theta);
        RecordProperty("implied_friction_" + std::to_string(rail_nodes), std::to_string(implied));
        EXPECT_NEAR(implied, mu, 0.06 * mu);
      }
      // In the groove, not through a rail: the rope's axis stays on the groove's centre line.
      for (int i = first; i < first + 16; ++i)
        EXPECT_NEAR(world.state().position(1, i), 0.0, 1e-3);
    }
}

// --- two ropes across each other ------------------------------------------------------------------------

/// Rope A along y lies on a floor (friction 0.2); rope B along x lies across it, 1 cm above. In 0.5 s
/// B's two anchored ends come down to the floor and 5 cm in each (B drapes over A), then both move 0.2 m
/// along B's axis in 1 s, and stop. Every rope 5 mm in radius with 1 cm links, friction `friction`
/// between the two.
SceneDef crossedRopes(double friction)
{
  const double radius = 0.005;
  SceneDef scene = xpbdScene(0.2);
  RopeDef lower;
  lower.nodes = 101;
  lower.from = Vec3(0.0, -0.5, radius);
  lower.to = Vec3(0.0, 0.5, radius);
  lower.mass = 0.05;
  lower.stiffness = 1e4;
  lower.damping = 0.01;
  lower.radius = radius;
  RopeDef upper = lower;
  upper.from = Vec3(-0.5, 0.0, 3.0 * radius);
  upper.to = Vec3(0.5, 0.0, 3.0 * radius);
  upper.mass = 0.2;
  for (BodyDef body : { buildRope("lower", lower), buildRope("upper", upper) })
  {
    body.self_collision = true;
    body.self_friction = friction;
    if (body.name == "upper")
      body.anchors = { AnchorDef("left", 0), AnchorDef("right", upper.nodes - 1) };
    scene.bodies.push_back(body);
  }
  return scene;
}

/// Where B's end anchored at `start` is at time t: see crossedRopes.
std::optional<Vec3> draped(const Vec3& start, double inwards, double t)
{
  const double lowered = std::min(t, 0.5) / 0.5, pulled = std::clamp(t - 0.5, 0.0, 1.0);
  return start + Vec3(inwards * lowered + 0.2 * pulled, 0.0, -0.01 * lowered);
}

// Pulled along its own axis, the upper rope drags the lower one, under the crossing, along with it by
// friction: with friction 0.5 the lower rope's middle node moves at least 0.8 times as far as the
// upper rope's middle (observed 1.0). Without friction it still moves, 0.2 times as far: a rope of
// straight links lies over another as a polygon, its corners catch the rope under it like teeth, and
// only the floor's friction holds that back (with a frictionless floor both ropes move as one). The two
// never pass through each other (the least distance between their links stays above 0.9 diameters).
TEST(SelfContacts, ARopePulledAlongItsAxisDragsARopeLyingUnderItByFriction)
{
  std::map<double, double> followed;
  for (const double friction : { 0.5, 0.0 })
  {
    SCOPED_TRACE("friction " + std::to_string(friction));
    World world = buildWorld(crossedRopes(friction));
    const Vec3 left = world.state().position.col(101), right = world.state().position.col(201);
    world.followPath(0, [=](double t) { return draped(left, 0.05, t); });
    world.followPath(1, [=](double t) { return draped(right, -0.05, t); });
    const double lower_start = world.state().position(0, 50), upper_start = world.state().position(0, 151);
    double closest = 1e300;
    for (int n = 0; n < 120; ++n)
    {
      world.step();
      ASSERT_TRUE(world.takeDivergenceEvents().empty());
      if (n % 3 != 2)
        continue;  // every third step (20 Hz): brute force is slow under the sanitizers
      const NodeArray& x = world.state().position;
      for (int i = 0; i < 100; ++i)
        for (int j = 101; j < 201; ++j)
          closest = std::min(closest, segmentDistance(x.col(i), x.col(i + 1), x.col(j), x.col(j + 1)));
    }
    followed[friction] =
        (world.state().position(0, 50) - lower_start) / (world.state().position(0, 151) - upper_start);
    RecordProperty(friction > 0.0 ? "followed_with_friction" : "followed_without", std::to_string(followed[friction]));
    EXPECT_GE(closest, 0.9 * 0.01);
  }
  EXPECT_GE(followed[0.5], 0.8);
  EXPECT_LT(followed[0.0], 0.5 * followed[0.5]);
}

// --- an overhand knot pulled tight -------------------------------------------------------------------------

/// A point of the trefoil knot (sin t + 2 sin 2t, cos t - 2 cos 2t, -sin 3t).
Vec3 trefoil(double t)
{
  return Vec3(std::sin(t) + 2.0 * std::sin(2.0 * t), std::cos(t) - 2.0 * std::cos(2.0 * t), -std::sin(3.0 * t));
}

/// An overhand knot as a polyline of links `link` [m] long: the trefoil scaled by 2 cm with one lobe's
/// tip (t = pi, at -y) cut out (t within 0.5 of it), and from the two cut ends tails that turn away from
/// each other (quadratic Bezier curves, 4 cm down and 4 cm out) and run 0.25 m along +x and -x. 114
/// nodes for 1 cm links; no two links more than 3 apart come closer than 2.4 cm.
std::vector<Vec3> overhandKnot(double link)
{
  const double scale = 0.02, cut = 0.5, tail = 0.25, turn = 0.04;
  const Vec3 down(0.0, -turn, 0.0);
  std::vector<Vec3> dense;
  const auto addTail = [&](const Vec3& end, double side, bool outwards) {
    std::vector<Vec3> points;
    for (int k = 0; k <= 400; ++k)
    {
      const double u = k / 400.0;  // the Bezier curve end -> end + down -> end + down + side turn
      const Vec3 out = end + down + side * turn * Vec3::UnitX();
      points.push_back((1 - u) * (1 - u) * end + 2 * u * (1 - u) * (end + down) + u * u * out);
    }
    for (int k = 1; k <= 200; ++k)
      points.push_back(points[400] + side * tail * k / 200.0 * Vec3::UnitX());
    if (!outwards)
      std::reverse(points.begin(), points.end());
    dense.insert(dense.end(), points.begin(), points.end());
  };
  const int samples = 20000;
  addTail(scale * trefoil(kPi + cut), 1.0, false);
  for (int k = 1; k < samples; ++k)
    dense.push_back(scale * trefoil(kPi + cut + (2.0 * kPi - 2.0 * cut) * k / samples));
  addTail(scale * trefoil(3.0 * kPi - cut), -1.0, true);
  // Resampled at equal arc lengths.
  std::vector<double> along{ 0.0 };
  for (std::size_t k = 1; k < dense.size(); ++k)
    along.push_back(along.back() + (dense[k] - dense[k - 1]).norm());
  const int links = static_cast<int>(std::lround(along.back() / link));
  std::vector<Vec3> nodes;
  std::size_t k = 1;
  for (int i = 0; i <= links; ++i)
  {
    const double s = along.back() * i / links;
    while (k + 1 < dense.size() && along[k] < s)
      ++k;
    const double u = std::clamp((s - along[k - 1]) / (along[k] - along[k - 1]), 0.0, 1.0);
    nodes.push_back(dense[k - 1] + u * (dense[k] - dense[k - 1]));
  }
  return nodes;
}

/// A crossing of the knot's diagram: where, along the closed polyline, it passes over and under.
struct Crossing
{
  double over, under;  ///< positions along the polyline: segment index + fraction
};

/// The crossings of the polyline `nodes` in its projection on the xy plane, closed far outside it by a
/// path that crosses nothing: from each end straight out (away from the centroid) to ten times the
/// polyline's reach, joined by an arc there. The ends must be outermost along those lines, as a knot's
/// pulled tails are.
std::vector<Crossing> crossings(std::vector<Vec3> nodes)
{
  Vec3 centre = Vec3::Zero();
  for (const Vec3& node : nodes)
    centre += node / static_cast<double>(nodes.size());
  double reach = 0.0;
  for (const Vec3& node : nodes)
    reach = std::max(reach, (node - centre).head<2>().norm());
  const auto angle = [&](const Vec3& node) { return std::atan2(node.y() - centre.y(), node.x() - centre.x()); };
  const double from = angle(nodes.back());
  double to = angle(nodes.front());
  if (to < from)
    to += 2.0 * kPi;
  for (int k = 0; k <= 64; ++k)
  {
    const double a = from + (to - from) * k / 64.0;
    nodes.push_back(centre + 10.0 * reach * Vec3(std::cos(a), std::sin(a), 0.0));
  }
  const int count = static_cast<int>(nodes.size());  // segment k joins node k to node (k + 1) % count
  std::vector<Crossing> found;
  for (int a = 0; a < count; ++a)
    for (int b = a + 2; b < count; ++b)
    {
      if (a == 0 && b == count - 1)
        continue;  // neighbours round the closing point
      const Vec3 p = nodes[static_cast<std::size_t>(a)], q = nodes[static_cast<std::size_t>(b)];
      const Vec3 dp = nodes[static_cast<std::size_t>((a + 1) % count)] - p;
      const Vec3 dq = nodes[static_cast<std::size_t>((b + 1) % count)] - q;
      const double denominator = dp.x() * dq.y() - dp.y() * dq.x();
      if (denominator == 0.0)
        continue;
      const Vec3 r = q - p;
      const double u = (r.x() * dq.y() - r.y() * dq.x()) / denominator;
      const double v = (r.x() * dp.y() - r.y() * dp.x()) / denominator;
      if (u < 0.0 || u >= 1.0 || v < 0.0 || v >= 1.0)
        continue;
      const bool a_over = p.z() + u * dp.z() > q.z() + v * dq.z();
      found.push_back(a_over ? Crossing{ a + u, b + v } : Crossing{ b + v, a + u });
    }
  return found;
}

/// The determinant of the knot that `nodes` make when closed as in crossings(): |det| of the diagram's
/// colouring matrix with one row and column removed (each crossing: 2 x its over-arc - its two
/// under-arcs; arcs end where the curve passes under). A knot invariant: 1 for the unknot, 3 for the
/// trefoil (the overhand knot closed), whatever the diagram (Livingston, Knot Theory, 3.4).
long knotDeterminant(const std::vector<Vec3>& nodes)
{
  const std::vector<Crossing> found = crossings(nodes);
  const int n = static_cast<int>(found.size());
  if (n == 0)
    return 1;
  std::vector<double> unders;
  for (const Crossing& c : found)
    unders.push_back(c.under);
  std::sort(unders.begin(), unders.end());
  // Arc k runs from the k-th passage under to the next (cyclically): the arc through position s.
  const auto arc = [&](double s) {
    const long before = std::upper_bound(unders.begin(), unders.end(), s) - unders.begin();
    return static_cast<int>((before - 1 + n) % n);
  };
  Eigen::MatrixXd colouring = Eigen::MatrixXd::Zero(n, n);
  for (int c = 0; c < n; ++c)
  {
    const Crossing& crossing = found[static_cast<std::size_t>(c)];
    const int leaving = arc(crossing.under);
    colouring(c, arc(crossing.over)) += 2.0;
    colouring(c, leaving) -= 1.0;
    colouring(c, (leaving - 1 + n) % n) -= 1.0;
  }
  if (n == 1)
    return 1;
  return std::lround(std::abs(colouring.bottomRightCorner(n - 1, n - 1).determinant()));
}

// The determinant tells the knots apart: 3 for the overhand knot, 1 for a rope in a helix (coiled but
// not knotted) and for a straight one.
TEST(KnotDeterminant, IsThreeForTheOverhandKnotAndOneForUnknottedRopes)
{
  EXPECT_EQ(knotDeterminant(overhandKnot(0.01)), 3);
  std::vector<Vec3> helix, straight;
  for (int i = 0; i <= 200; ++i)
  {
    const double t = i / 200.0;
    helix.push_back(Vec3(0.1 * std::sin(6.0 * t * 2.0 * kPi), -t, 0.1 * std::cos(6.0 * t * 2.0 * kPi)));
    straight.push_back(Vec3(0.0, -t, 0.0));
  }
  EXPECT_EQ(knotDeterminant(helix), 1);
  EXPECT_EQ(knotDeterminant(straight), 1);
}

/// The length [m] of rope in a knot of 1 cm links: from the first to the last link that passes within 3 cm
/// of a link more than 5 places away (the tails, straight and apart, have none).
double knotLength(const World& world)
{
  const NodeArray& x = world.state().position;
  const int nodes = world.model().nodeCount();
  int first = nodes, last = -1;
  for (int i = 0; i + 1 < nodes; ++i)
    for (int j = 0; j + 1 < nodes; ++j)
      if (std::abs(i - j) > 5 && segmentDistance(x.col(i), x.col(i + 1), x.col(j), x.col(j + 1)) < 0.03)
      {
        first = std::min(first, i);
        last = std::max(last, i);
        break;
      }
  return (last - first + 1) * 0.01;
}

/// The overhand knot as a rope of radius 5 mm and 1 cm links (xpbd, no gravity), its two ends anchored
/// and pulled apart along its tails, each 0.15 m at 0.1 m/s, then held.
SceneDef knotScene(double friction)
{
  SceneDef scene = xpbdScene(-1.0);
  scene.physics.gravity = Vec3::Zero();
  RopeDef rope;
  const std::vector<Vec3> shape = overhandKnot(0.01);
  rope.nodes = static_cast<int>(shape.size());
  rope.mass = 0.05;
  rope.stiffness = 1e4;
  rope.damping = 0.01;
  rope.radius = 0.005;
  BodyDef body = buildRope("rope", rope);
  for (std::size_t i = 0; i < shape.size(); ++i)
    body.nodes[i].position = shape[i];
  for (SpringDef& spring : body.springs)
    spring.rest_length.reset();
  body.self_collision = true;
  body.self_friction = friction;
  body.anchors = { AnchorDef("start", 0), AnchorDef("end", rope.nodes - 1) };
  scene.bodies.push_back(body);
  return scene;
}

// Pulled tight, the overhand knot stays an overhand knot: its determinant is 3 at the end, with friction
// 0.5 and without friction (it cannot undo itself by passing through), its links never come closer than
// 0.9 diameters (observed 0.997), and it tightens (the rope in the knot shortens to less than half).
TEST(SelfContacts, AnOverhandKnotPulledTightStaysAKnot)
{
  for (const double friction : { 0.5, 0.0 })
  {
    SCOPED_TRACE("friction " + std::to_string(friction));
    World world = buildWorld(knotScene(friction));
    const int nodes = world.model().nodeCount();
    const Vec3 start = world.state().position.col(0), end = world.state().position.col(nodes - 1);
    world.followPath(0, [=](double t) { return std::optional<Vec3>(start + Vec3::UnitX() * 0.1 * std::min(t, 1.5)); });
    world.followPath(1, [=](double t) { return std::optional<Vec3>(end - Vec3::UnitX() * 0.1 * std::min(t, 1.5)); });
    const double loose = knotLength(world);
    double closest = 1e300;
    for (int n = 0; n < 150; ++n)
    {
      world.step();
      ASSERT_TRUE(world.takeDivergenceEvents().empty());
      if (n % 3 == 2)  // every third step (20 Hz): brute force is slow under the sanitizers
        closest = std::min(closest, closestLinks(world));
    }
    std::vector<Vec3> x;
    for (int i = 0; i < nodes; ++i)
      x.push_back(world.state().position.col(i));
    const double tight = knotLength(world);
    RecordProperty(friction > 0.0 ? "knot_closest_with_friction" : "knot_closest_without", std::to_string(closest));
    RecordProperty(friction > 0.0 ? "knot_length_with_friction" : "knot_length_without",
                   std::to_string(loose) + " -> " + std::to_string(tight));
    EXPECT_EQ(knotDeterminant(x), 3);
    EXPECT_GE(closest, 0.9 * 0.01);
    EXPECT_LT(tight, 0.5 * loose);
  }
}

// config/scenes/knot.yaml: the loose overhand knot in a rope hanging from its top end is pulled tight by
// the lower tail's weight within 3 s (the rope in the knot shortens to less than 0.6 times its length),
// stays an overhand knot (determinant 3, in the projection on the vertical xz plane, where the tails are
// outermost) and its links keep 0.9 diameters apart.
TEST(SelfContacts, TheKnotSceneTightensUnderItsOwnWeightAndStaysAKnot)
{
  World world = buildWorld(loadSceneFile(std::string(SOURCE_DIR) + "/config/scenes/knot.yaml"));
  const int nodes = world.model().nodeCount();
  const double loose = knotLength(world);
  double closest = 1e300;
  for (int n = 0; n < 180; ++n)
  {
    world.step();
    ASSERT_TRUE(world.takeDivergenceEvents().empty());
    if (n % 3 == 2)
      closest = std::min(closest, closestLinks(world));
  }
  std::vector<Vec3> xz;  // (x, z, y): the diagram seen from -y
  for (int i = 0; i < nodes; ++i)
  {
    const Vec3 p = world.state().position.col(i);
    xz.push_back(Vec3(p.x(), p.z(), p.y()));
  }
  const double tight = knotLength(world);
  RecordProperty("knot_scene_length", std::to_string(loose) + " -> " + std::to_string(tight));
  RecordProperty("knot_scene_closest", std::to_string(closest));
  EXPECT_EQ(knotDeterminant(xz), 3);
  EXPECT_GE(closest, 0.9 * 0.01);
  EXPECT_LT(tight, 0.6 * loose);
}

// --- a cloth folded onto itself -----------------------------------------------------------------------------

/// A cloth of 21 x 11 nodes, 0.5 m x 0.25 m (2.5 cm spacing), 1 cm thick, lying flat on the floor (friction
/// 0.5); its two right corners are anchors that carry its right half over the fold line x = 0.25 m in a
/// half circle in 1.5 s and lay it onto the left half, 2 thicknesses up, then hold. xpbd, 8 sub-steps.
SceneDef foldedCloth(bool self_collision, double thickness = 0.01, bool faces = false)
{
  SceneDef scene = xpbdScene(0.5);
  ClothDef cloth;
  cloth.nx = 21;
  cloth.ny = 11;
  cloth.corners.top_left = Vec3(0.0, 0.0, thickness);
  cloth.corners.top_right = Vec3(0.5, 0.0, thickness);
  cloth.corners.bottom_left = Vec3(0.0, 0.25, thickness);
  cloth.mass = 0.1;
  cloth.structural = { 1000.0, 0.05 };
  cloth.shear = { 500.0, 0.05 };
  cloth.thickness = thickness;
  cloth.self_collision = self_collision;
  cloth.self_friction = self_collision ? 0.3 : 0.0;
  cloth.face_contacts = faces;
  BodyDef body = buildCloth("cloth", cloth);
  body.anchors = { AnchorDef("top_right", 20), AnchorDef("bottom_right", 230) };
  scene.bodies.push_back(body);
  return scene;
}

/// Where a right corner that starts at `start` is at time t (foldedCloth).
std::optional<Vec3> folded(const Vec3& start, double t, double thickness = 0.01)
{
  const double angle = kPi * std::min(t, 1.5) / 1.5;
  return Vec3(0.25 + 0.24 * std::cos(angle), start.y(), thickness + 0.24 * std::sin(angle) + 2.0 * thickness * angle / kPi);
}

/// The least height [m] of a node of the cloth's right half (columns 11 to 20) above the triangles of its
/// left half (columns 0 to 9, two per square) under it, over the nodes that lie over the left half; 1e300
/// if none does. Negative once a node has crossed the lower layer.
double heightAboveLowerLayer(const NodeArray& x)
{
  const auto node = [](int i, int j) { return j * 21 + i; };
  double least = 1e300;
  for (int i = 11; i < 21; ++i)
    for (int j = 0; j < 11; ++j)
    {
      const Vec3 p = x.col(node(i, j));
      for (int a = 0; a < 9; ++a)
        for (int b = 0; b < 10; ++b)
          for (const auto& corners : { std::array<int, 3>{ node(a, b), node(a + 1, b), node(a + 1, b + 1) },
                                       std::array<int, 3>{ node(a, b), node(a + 1, b + 1), node(a, b + 1) } })
          {
            const Vec3 p0 = x.col(corners[0]), p1 = x.col(corners[1]), p2 = x.col(corners[2]);
            // Barycentric coordinates of p's projection on the xy plane.
            const double area = (p1.x() - p0.x()) * (p2.y() - p0.y()) - (p2.x() - p0.x()) * (p1.y() - p0.y());
            if (std::abs(area) < 1e-12)
              continue;
            const double u = ((p.x() - p0.x()) * (p2.y() - p0.y()) - (p2.x() - p0.x()) * (p.y() - p0.y())) / area;
            const double v = ((p1.x() - p0.x()) * (p.y() - p0.y()) - (p.x() - p0.x()) * (p1.y() - p0.y())) / area;
            if (u < 0.0 || v < 0.0 || u + v > 1.0)
              continue;
            least = std::min(least, p.z() - (p0.z() + u * (p1.z() - p0.z()) + v * (p2.z() - p0.z())));
          }
    }
  return least;
}

// Folded in half, the cloth's upper layer never crosses the lower one: every node of the folded half
// that lies over the lower half stays above its triangles at every step, by at least 0.8 thicknesses
// (nodes are balls of the thickness t; an upper ball nested in the hollow between four lower ones at
// spacing 2.5 t sits sqrt(4 - 3.125) t = 0.935 t above their plane; observed 0.92 t). Without
// self-collision the upper layer sinks into the lower one.
TEST(SelfContacts, AClothFoldedOntoItselfKeepsItsLayersApart)
{
  for (const bool self_collision : { true, false })
  {
    SCOPED_TRACE(self_collision ? "self_collision" : "without");
    World world = buildWorld(foldedCloth(self_collision));
    const Vec3 top_right = world.state().position.col(20), bottom_right = world.state().position.col(230);
    world.followPath(0, [=](double t) { return folded(top_right, t); });
    world.followPath(1, [=](double t) { return folded(bottom_right, t); });
    double least = 1e300;
    for (int n = 0; n < 150; ++n)
    {
      world.step();
      ASSERT_TRUE(world.takeDivergenceEvents().empty());
      least = std::min(least, heightAboveLowerLayer(world.state().position));
    }
    RecordProperty(self_collision ? "least_height_with" : "least_height_without", std::to_string(least));
    for (int j = 0; j < 11; ++j)  // folded: the right half lies over the left
      for (int i = 11; i < 21; ++i)
        EXPECT_LT(world.state().position(0, j * 21 + i), 0.27) << "node " << i << ", " << j;
    if (self_collision)
      EXPECT_GE(least, 0.8 * 0.01);
    else
      EXPECT_LT(least, 0.5 * 0.01);
  }
}

// With face_contacts the cloth collides by its triangles' edges and faces: a cloth 1 mm thick at 2.5 cm
// spacing (0.04 of it, where its nodes as balls need 0.36) folded the same way keeps its layers apart,
// every node of the upper half at least 0.8 of the contact distance (its radius plus the lower faces'
// thickness, 2 mm) above the lower half's triangles at every step (observed 0.95).
TEST(SelfContacts, AThinClothWithFaceContactsFoldedOntoItselfKeepsItsLayersApart)
{
  const double thickness = 0.001;
  World world = buildWorld(foldedCloth(true, thickness, true));
  const Vec3 top_right = world.state().position.col(20), bottom_right = world.state().position.col(230);
  world.followPath(0, [=](double t) { return folded(top_right, t, thickness); });
  world.followPath(1, [=](double t) { return folded(bottom_right, t, thickness); });
  double least = 1e300;
  for (int n = 0; n < 150; ++n)
  {
    world.step();
    ASSERT_TRUE(world.takeDivergenceEvents().empty());
    least = std::min(least, heightAboveLowerLayer(world.state().position));
  }
  RecordProperty("least_height", std::to_string(least));
  for (int j = 0; j < 11; ++j)
    for (int i = 11; i < 21; ++i)
      EXPECT_LT(world.state().position(0, j * 21 + i), 0.27) << "node " << i << ", " << j;
  EXPECT_GE(least, 0.8 * 2.0 * thickness);
}

// --- a rope on a cloth trampoline (a cloth's faces and edges, face_contacts) -----------------------------

/// A 1 m trampoline, a cloth of 21 x 21 nodes (5 cm spacing, 5 mm thick) pinned all round its border at
/// z = 1 m, with face_contacts and self_collision, and a 5 mm rope of 61 nodes (1 cm links), 0.6 m long,
/// dropped from 5 cm above it along x at y = 0.025 m: midway between two node rows, where the cloth's
/// nodes as balls (thickness at least 0.36 of the spacing) leave a gap of 3.5 cm that the rope falls
/// through. A floor 0.5 m below; 12 sub-steps of 1/60 s (the loader's rule against passing through for
/// the 5 mm thickness).
std::string trampoline(const std::string& integrator)
{
  std::string pinned;
  for (int j = 0; j < 21; ++j)
    for (int i = 0; i < 21; ++i)
      if (i == 0 || j == 0 || i == 20 || j == 20)
        pinned += (pinned.empty() ? "" : ", ") + std::to_string(j * 21 + i);
  return "physics: {integrator: " + integrator + ", dt: 0.016666666666666666, substeps: 12, drag: 0.5}\n"
         "planes:\n"
         "  - {point: [0, 0, 0.5], normal: [0, 0, 1]}\n"
         "bodies:\n"
         "  - {name: trampoline, type: cloth, nx: 21, ny: 21, top_left: [-0.5, 0.5, 1.0], top_right: [0.5, 0.5, 1.0],\n"
         "     bottom_left: [-0.5, -0.5, 1.0], mass: 0.3, thickness: 0.005, face_contacts: true,\n"
         "     self_collision: true, self_friction: 0.3, structural: {stiffness: 1000.0, damping: 0.02},\n"
         "     shear: {stiffness: 200.0, damping: 0.01}, bending: {stiffness: 20.0}, pinned: [" + pinned + "]}\n"
         "  - {name: rope, type: rope, nodes: 61, from: [-0.3, 0.025, 1.05], to: [0.3, 0.025, 1.05], mass: 0.05,\n"
         "     stiffness: 2000.0, damping: 0.01, radius: 0.005, self_collision: true, self_friction: 0.3}\n";
}

class RopeOnATrampoline : public ::testing::TestWithParam<std::string>
{
};

// Truth: no rope link ever passes through a triangle of the cloth (brute force over every link and
// triangle after every step), and after 2 s the rope lies on the cloth: every rope node over the cloth by
// at least 90 % of the rope's radius plus the cloth's thickness, measured along the normal of the
// triangle it is over (the trampoline sags under both by several centimetres: it carries them).
TEST_P(RopeOnATrampoline, AFiveMillimetreRopeStaysOnAClothOfFiveCentimetreSpacing)
{
  World world = buildWorld(parseScene(trampoline(GetParam()), "trampoline.yaml"));
  const Model& model = world.model();
  const int cloth = model.bodies[0].first, rope = model.bodies[1].first;
  const std::vector<std::array<int, 3>>& triangles = model.contact_triangles;
  ASSERT_EQ(triangles.size(), 800u);
  int crossings = 0;
  while (world.time() < 2.0)
  {
    world.step();
    ASSERT_TRUE(world.takeDivergenceEvents().empty());
    const NodeArray& x = world.state().position;
    for (int k = 0; k + 1 < 61; ++k)
      for (const std::array<int, 3>& t : triangles)
        if (crossesTriangle(x.col(rope + k), x.col(rope + k + 1), x.col(t[0]), x.col(t[1]), x.col(t[2])))
          ++crossings;
  }
  EXPECT_EQ(crossings, 0);
  const NodeArray& x = world.state().position;
  double least = 1e300, sag = 0.0;
  for (int k = 0; k < 61; ++k)
  {
    const Vec3 p = x.col(rope + k);
    for (const std::array<int, 3>& t : triangles)
    {
      // The triangle below the node (seen from above), and the node's height over it along its normal.
      const Vec3 a = x.col(t[0]), b = x.col(t[1]), c = x.col(t[2]);
      Vec3 n = (b - a).cross(c - a);
      if (n.z() < 0.0)
        n = -n;
      const Vec3 down = -Vec3::UnitZ();
      const double along = n.dot(a - p) / n.dot(down);
      if (crossesTriangle(p, p + (along + 1e-9) * down, a, b, c))
        least = std::min(least, n.normalized().dot(p - a));
    }
    sag = std::max(sag, 1.0 - x(2, rope + k));
  }
  EXPECT_GE(least, 0.9 * (0.005 + 0.005));
  EXPECT_GT(sag, 0.02) << "the cloth carries the rope";
  EXPECT_GT(x.row(2).segment(cloth, 441).minCoeff(), 0.5 + 0.005 + 0.01) << "the cloth is off the floor";
  RecordProperty("least_height", std::to_string(least));
}

INSTANTIATE_TEST_SUITE_P(Integrators, RopeOnATrampoline, ::testing::Values("xpbd", "implicit_euler"),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

}  // namespace
}  // namespace soft_body_sim::test
