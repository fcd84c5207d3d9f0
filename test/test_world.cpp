// The world's stages against independent truth: kinematic anchors and plane contacts.
#include <cmath>

#include <gtest/gtest.h>

#include "soft_body_sim/core/bodies/rope.h"
#include "test_util.h"

namespace soft_body_sim::test
{
namespace
{
TEST(Anchors, AnAnchoredNodeArrivesExactlyWhereItWasSentWithinOneStep)
{
  RopeDef rope;
  rope.nodes = 5;
  SceneDef scene = oneBodyScene(IntegratorType::SemiImplicitEuler, 1e-3);
  scene.bodies[0] = buildRope("rope", rope);
  scene.bodies[0].anchors = { AnchorDef{ "end", 4 } };
  scene.physics.step.substeps = 3;
  World world = buildWorld(scene);
  const std::optional<int> anchor = world.findAnchor("rope", "end");
  ASSERT_TRUE(anchor);
  EXPECT_FALSE(world.findAnchor("rope", "start"));
  const Vec3 goal(1.5, 0.2, -0.1);
  world.moveAnchor(*anchor, goal);
  world.step();
  EXPECT_EQ(Vec3(world.state().position.col(4)), goal);
  // It moved at constant velocity over the step: (goal - start) / dt.
  EXPECT_TRUE(expectNear(Vec3(world.state().velocity.col(4)), Vec3((goal - Vec3(1, 0, 0)) / 1e-3), 1e-9));
  world.step();
  EXPECT_EQ(Vec3(world.state().position.col(4)), goal);
  EXPECT_TRUE(world.state().velocity.col(4).isZero(0.0));
}

}  // namespace
}  // namespace soft_body_sim::test
