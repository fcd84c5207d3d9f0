// Grasps (grasps.h): which nodes a grasp takes, that they stay at their offsets while the gripper turns,
// that released nodes keep their velocities, the force a grasp carries, and that a grasp slips at the
// step where its force first exceeds its limit.
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "soft_body_sim/core/bodies/cloth.h"
#include "soft_body_sim/core/bodies/rope.h"
#include "test_util.h"

namespace soft_body_sim::test
{
namespace
{
constexpr double kGravity = 9.81;

/// A 10 x 10 cloth, 0.9 m square at z = 1 m, under gravity; `pinned` nodes stay put.
SceneDef clothScene(IntegratorType integrator)
{
  SceneDef scene = oneBodyScene(integrator, 1.0 / 60.0);
  scene.physics.gravity = Vec3(0, 0, -kGravity);
  scene.physics.step.substeps = 8;
  ClothDef cloth;
  cloth.corners.top_left = Vec3(0, 0, 1);
  cloth.corners.top_right = Vec3(0.9, 0, 1);
  cloth.corners.bottom_left = Vec3(0, 0.9, 1);
  scene.bodies[0] = buildCloth("cloth", cloth);
  return scene;
}

/// A rope of 21 nodes, 1 m and 0.1 kg, hanging from its first node, anchored as "top".
SceneDef hangingRope(IntegratorType integrator)
{
  SceneDef scene = oneBodyScene(integrator, 1.0 / 240.0);
  scene.physics.gravity = Vec3(0, 0, -kGravity);
  scene.physics.drag = 2.0;
  RopeDef rope;
  rope.nodes = 21;
  rope.from = Vec3(0, 0, 1);
  rope.to = Vec3(0, 0, 0);
  rope.mass = 0.1;
  rope.stiffness = 500.0;
  rope.damping = 0.05;
  rope.pinned = { 0 };
  scene.bodies[0] = buildRope("rope", rope);
  scene.bodies[0].anchors.emplace_back("top", 0);
  return scene;
}

RigidPose poseAt(const Vec3& position, const Eigen::Quaterniond& orientation = Eigen::Quaterniond::Identity())
{
  return RigidPose{ position, orientation };
}

TEST(Grasp, TakesEveryFreeNodeOfItsBodyWithinItsRadius)
{
  // Brute force: the nodes within the radius of the frame's origin, counted here.
  World world = buildWorld(clothScene(IntegratorType::Xpbd));
  const Vec3 origin(0.42, 0.31, 1.0);
  const double radius = 0.15;
  std::vector<int> expected;
  for (int i = 0; i < world.model().nodeCount(); ++i)
    if ((world.state().position.col(i) - origin).norm() <= radius)
      expected.push_back(i);
  ASSERT_GE(expected.size(), 4u);
  EXPECT_EQ(world.grasp("gripper", "cloth", poseAt(origin), radius), expected.size());
  EXPECT_EQ(world.grasps().at(0).nodes, expected);
  for (const int node : expected)
    EXPECT_FALSE(world.model().isFree(node));
}

TEST(Grasp, RefusesANameTakenNoNodeInReachAnUnknownBodyAndABadRadius)
{
  World world = buildWorld(clothScene(IntegratorType::Xpbd));
  world.grasp("gripper", "cloth", poseAt(Vec3(0, 0, 1)), 0.05);
  EXPECT_THROW(world.grasp("gripper", "cloth", poseAt(Vec3(0.9, 0.9, 1)), 0.05), std::invalid_argument);
  EXPECT_THROW(world.grasp("other", "cloth", poseAt(Vec3(0, 0, 3)), 0.05), std::invalid_argument);
  EXPECT_THROW(world.grasp("other", "rope", poseAt(Vec3(0.9, 0.9, 1)), 0.05), std::invalid_argument);
  EXPECT_THROW(world.grasp("other", "cloth", poseAt(Vec3(0.9, 0.9, 1)), -1.0), std::invalid_argument);
  EXPECT_THROW(world.grasp("other", "cloth", poseAt(Vec3(0.9, 0.9, 1)), 0.05, 0.0), std::invalid_argument);
  // A node held by one grasp is not free for another.
  EXPECT_THROW(world.grasp("other", "cloth", poseAt(Vec3(0, 0, 1)), 0.05), std::invalid_argument);
  EXPECT_EQ(world.grasps().size(), 1u);
}

TEST(Grasp, TheGraspedNodesKeepTheirOffsetsWhileTheFrameTurnsNinetyDegrees)
{
  // The gripper closes on a corner of the cloth, then turns by 90 degrees about its x axis in 30 steps
  // while moving 0.2 m up along a path (as a tf frame), and holds: the grasped nodes stay where the frame
  // carries them, to round-off.
  for (const IntegratorType integrator : { IntegratorType::Xpbd, IntegratorType::ImplicitEuler })
  {
    World world = buildWorld(clothScene(integrator));
    const Vec3 origin(0.05, 0.05, 1.0);
    world.grasp("gripper", "cloth", poseAt(origin), 0.12);
    const std::vector<int> nodes = world.grasps().at(0).nodes;
    std::vector<Vec3> offsets;  // in the frame, which starts unrotated at `origin`
    for (const int node : nodes)
      offsets.push_back(world.state().position.col(node) - origin);
    const auto path = [&](double t) -> std::optional<RigidPose> {
      const double s = std::min(1.0, t / (30 * world.settings().dt));
      return poseAt(origin + Vec3(0, 0, 0.2 * s), Eigen::Quaterniond(Eigen::AngleAxisd(s * M_PI / 2, Vec3::UnitX())));
    };
    ASSERT_TRUE(world.followGraspPath("gripper", path));
    for (int n = 1; n <= 60; ++n)
    {
      world.step();
      const RigidPose pose = *path(world.time());
      for (std::size_t k = 0; k < nodes.size(); ++k)
        ASSERT_TRUE(expectNear(world.state().position.col(nodes[k]),
                               Vec3(pose.position + pose.orientation * offsets[k]), 1e-9))
            << integratorName(integrator) << " step " << n << " node " << nodes[k];
    }
    EXPECT_TRUE(allFinite(world.state()));
  }
}

TEST(Grasp, ReleasedNodesGoOnWithTheGrippersVelocity)
{
  // The gripper carries the cloth's corner at 0.6 m/s along y; let go, its nodes have that velocity.
  World world = buildWorld(clothScene(IntegratorType::Xpbd));
  const Vec3 origin(0.0, 0.0, 1.0);
  world.grasp("gripper", "cloth", poseAt(origin), 0.05);
  const std::vector<int> nodes = world.grasps().at(0).nodes;
  const double dt = world.settings().dt;
  for (int n = 1; n <= 10; ++n)
  {
    world.moveGrasp("gripper", poseAt(origin + Vec3(0, 0.6 * n * dt, 0)));
    world.step();
  }
  ASSERT_TRUE(world.release("gripper"));
  EXPECT_FALSE(world.release("gripper"));
  for (const int node : nodes)
  {
    EXPECT_TRUE(world.model().isFree(node));
    EXPECT_TRUE(expectNear(world.state().velocity.col(node), Vec3(0, 0.6, 0), 1e-9));
  }
}

TEST(GraspForce, AGripperHoldingARopeAsideCarriesItsWeightAndItsMoment)
{
  // The rope hangs from a grasp of its top three nodes whose frame's origin is 5 cm beside them: at rest
  // the grasp carries the whole weight W, with the moment of W about that origin, d x (0, 0, -W).
  SceneDef scene = hangingRope(IntegratorType::ImplicitEuler);
  scene.bodies[0].anchors.clear();
  scene.bodies[0].nodes[0].pinned = false;
  World world = buildWorld(scene);
  const Vec3 origin(0.05, 0.0, 1.0);
  ASSERT_EQ(world.grasp("gripper", "rope", poseAt(origin), 0.12), 3u);
  ASSERT_TRUE(settle(world, 1e-8, 40000)) << "the rope did not come to rest";
  const double weight = 0.1 * kGravity;
  const Wrench wrench = world.graspWrenches().at(0);
  EXPECT_TRUE(expectNear(wrench.force, Vec3(0, 0, -weight), 1e-3 * weight));
  EXPECT_TRUE(expectNear(wrench.torque, Vec3(-0.05, 0, 0).cross(Vec3(0, 0, -weight)), 1e-3 * 0.05 * weight));
}

TEST(GraspForce, AGraspSlipsAtTheStepWhereItsForceFirstExceedsItsLimit)
{
  // The rope's lower end is grasped and pulled down at 5 cm/s, stretching the rope. A run without a limit
  // finds the first step whose grasp force exceeds 2 N; with max_force 2 N the grasp holds until that
  // step, lets go at its end, and says so once.
  const double limit = 2.0;
  const auto run = [](double max_force, std::vector<double>& forces) {
    World world = buildWorld(hangingRope(IntegratorType::Xpbd));
    const Vec3 end = world.state().position.col(20);
    world.grasp("gripper", "rope", poseAt(end), 0.01, max_force);
    for (int n = 1; n <= 2000 && !world.grasps().empty(); ++n)
    {
      world.moveGrasp("gripper", poseAt(end - Vec3(0, 0, 0.05 * n * world.settings().dt)));
      world.step();
      forces.push_back(world.grasps().empty() ? 0.0 : world.graspWrenches().at(0).force.norm());
    }
    return world.takeGraspSlips();
  };
  std::vector<double> unlimited;
  EXPECT_TRUE(run(std::numeric_limits<double>::infinity(), unlimited).empty());
  std::size_t first = 0;
  while (first < unlimited.size() && unlimited[first] <= limit)
    ++first;
  ASSERT_LT(first, unlimited.size()) << "the pull never reached the limit";
  ASSERT_GT(first, 10u) << "the grasp starts above the limit";
  std::vector<double> limited;
  const std::vector<GraspSlip> slips = run(limit, limited);
  ASSERT_EQ(slips.size(), 1u);
  EXPECT_EQ(limited.size(), first + 1) << "held through the steps below the limit, let go at the first above";
  EXPECT_DOUBLE_EQ(slips[0].force, unlimited[first]);
  EXPECT_NEAR(slips[0].time, (first + 1) / 240.0, 1e-12);
  EXPECT_EQ(slips[0].grasp, "gripper");
  EXPECT_EQ(slips[0].body, "rope");
  EXPECT_NE(slips[0].describe().find("slipped"), std::string::npos);
}

/// Everything observable of a world's moment: its bits, its grasps' and colliders' wrenches.
std::vector<double> observed(const World& world)
{
  std::vector<double> values(world.state().position.data(), world.state().position.data() + world.state().position.size());
  values.insert(values.end(), world.state().velocity.data(), world.state().velocity.data() + world.state().velocity.size());
  for (const Wrench& wrench : world.graspWrenches())
    values.insert(values.end(), { wrench.force.x(), wrench.force.y(), wrench.force.z(), wrench.torque.x() });
  for (const ColliderWrench& collider : world.colliderWrenches())
    values.insert(values.end(), { collider.wrench.force.x(), collider.wrench.force.y(), collider.wrench.force.z() });
  values.push_back(static_cast<double>(world.grasps().size()));
  return values;
}

TEST(GraspSnapshot, AGraspedClothPushedByAMovingSphereStepsOnBitForBitFromASnapshotAndAClone)
{
  // The cloth's corner in a gripper that lifts it along a path (a grasp with a force limit), a sphere
  // rising into the hanging cloth along a path: both carried in a world's snapshot and clone (goals,
  // paths, held offsets, the sphere's pose and what it touches, the integrator's carried state). 60 steps
  // after the moment, the restored world and the clone are where the world itself was, to the bit; so is
  // a world built afresh from the scene, restored from the snapshot's bytes and given the same paths (bytes
  // carry no functions).
  for (const IntegratorType integrator : { IntegratorType::Xpbd, IntegratorType::ImplicitEuler })
  {
    SceneDef scene = clothScene(integrator);
    Sphere ball;
    ball.at.name = "ball";
    ball.at.position = Vec3(0.25, 0.25, 0.5);
    ball.radius = 0.1;
    scene.colliders.spheres.push_back(ball);
    scene.bodies[0].contact_radius = 0.01;
    World world = buildWorld(scene);
    world.grasp("gripper", "cloth", poseAt(Vec3(0, 0, 1)), 0.12, 20.0);
    const auto lift = [](double t) { return poseAt(Vec3(0, 0, 1 + 0.3 * t)); };
    const auto rise = [](double t) { return poseAt(Vec3(0.25, 0.25, 0.5 + 0.3 * t)); };
    ASSERT_TRUE(world.followGraspPath("gripper", lift));
    ASSERT_TRUE(world.followColliderPath("ball", rise));
    for (int n = 0; n < 40; ++n)
      world.step();
    const WorldSnapshot moment = world.snapshot();
    World clone(world);
    World fresh = buildWorld(scene);
    fresh.restore(WorldSnapshot::fromBytes(moment.toBytes()));
    ASSERT_TRUE(fresh.followGraspPath("gripper", lift));
    ASSERT_TRUE(fresh.followColliderPath("ball", rise));
    for (int n = 0; n < 60; ++n)
      world.step();
    const std::vector<double> later = observed(world);
    for (World* other : { &clone, &fresh, &world })
    {
      if (other == &world)
        world.restore(moment);
      for (int n = 0; n < 60; ++n)
        other->step();
      EXPECT_EQ(observed(*other), later)
          << integratorName(integrator) << (other == &world ? ": restored" : other == &fresh ? ": from bytes" : ": clone");
    }
    // The moment did matter: the sphere reached the cloth and the grasp bore a load.
    EXPECT_GT(world.colliderWrenches().at(0).wrench.force.norm(), 0.0) << integratorName(integrator);
    ASSERT_EQ(world.grasps().size(), 1u);
    EXPECT_GT(world.graspWrenches().at(0).force.norm(), 0.0) << integratorName(integrator);
  }
}

}  // namespace
}  // namespace soft_body_sim::test
