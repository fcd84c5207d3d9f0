// Self-collision (self_contacts.h): the spatial hash never misses a pair of segments within reach
// (against all pairs, by brute force); a rope dropped in a coil onto the floor keeps every two of its
// links at least its diameter apart (brute-force distances), where without self-collision it passes
// through itself.
#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "soft_body_sim/core/bodies/rope.h"
#include "soft_body_sim/core/self_contacts.h"
#include "test_util.h"

namespace soft_body_sim::test
{
namespace
{
constexpr double kPi = 3.14159265358979323846;

/// The distance [m] between segments p0-p1 and q0-q1: the nearest point of q's segment to each of 401
/// points along p's (a projection clamped to the segment, exact), minimised; within (|p| / 400)^2 / (8 r)
/// of the truth for segments at r of each other.
double segmentDistance(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1)
{
  const Vec3 d = q1 - q0;
  const double length2 = d.squaredNorm();
  double nearest = 1e300;
  for (int k = 0; k <= 400; ++k)
  {
    const Vec3 p = p0 + (p1 - p0) * (k / 400.0);
    const double t = length2 > 0.0 ? std::clamp((p - q0).dot(d) / length2, 0.0, 1.0) : 0.0;
    nearest = std::min(nearest, (p - (q0 + t * d)).norm());
  }
  return nearest;
}

// 1000 random segments up to 5 cm long in a 0.5 m box: every pair within 1 cm of each other (all pairs,
// brute force) is among those the grid visits, and the grid visits each pair at most once.
TEST(SegmentGrid, VisitsEveryPairWithinReachOnce)
{
  std::mt19937 random(7);
  std::uniform_real_distribution<double> box(0.0, 0.5), offset(-0.025, 0.025);
  const int count = 1000;
  NodeArray x(3, 2 * count);
  std::vector<std::pair<int, int>> segments;
  for (int s = 0; s < count; ++s)
  {
    x.col(2 * s) = Vec3(box(random), box(random), box(random));
    x.col(2 * s + 1) = x.col(2 * s) + Vec3(offset(random), offset(random), offset(random));
    segments.emplace_back(2 * s, 2 * s + 1);
  }
  const double reach = 0.01;
  double longest = 0.0;
  for (const auto& [a, b] : segments)
    longest = std::max(longest, (x.col(a) - x.col(b)).norm());
  SegmentGrid grid;
  grid.build(x, segments, longest + reach);
  std::set<std::pair<std::size_t, std::size_t>> visited;
  int repeats = 0;
  grid.forEachNearPair([&](std::size_t s, std::size_t t) {
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
}

/// A 3 m rope of radius 5 mm (121 nodes, 2.5 cm links) in a loose coil: a helix of radius 0.1 m and
/// 2 cm pitch, from 0.3 m above the floor down, dropped onto the floor (friction 0.5). xpbd at 1/60 s
/// with 8 sub-steps: a fall of 0.3 m reaches 2.4 m/s, 5 mm per sub-step, one radius.
SceneDef coil(bool self_collision)
{
  const int nodes = 121;
  const double radius = 0.005, coil_radius = 0.1, link = 0.025;
  const double turn = 2.0 * kPi * coil_radius, pitch = 0.02;
  SceneDef scene;
  scene.physics.integrator = IntegratorType::Xpbd;
  scene.physics.step = StepSettings{ 1.0 / 60.0, 8, 2 };
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
        Vec3(coil_radius * std::cos(angle), coil_radius * std::sin(angle), 0.3 - pitch * along / turn);
  }
  // Links at rest in the coil (buildRope measured them along the straight line).
  for (SpringDef& spring : body.springs)
    spring.rest_length.reset();
  body.self_collision = self_collision;
  scene.bodies.push_back(body);
  scene.colliders.planes.push_back(Plane{ Vec3::Zero(), Vec3::UnitZ(), 0.0, 0.5 });
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
    World world = buildWorld(coil(self_collision));
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

}  // namespace
}  // namespace soft_body_sim::test
