// A URDF's collisions as colliders (robot_colliders.h), parsed by ROS's urdf package, no master needed.
#include <cmath>

#include <gtest/gtest.h>

#include "soft_body_sim/ros/robot_colliders.h"
#include "test_util.h"

namespace soft_body_sim::test
{
namespace
{
const char* const kRobot = R"(<?xml version="1.0"?>
<robot name="test_robot">
  <link name="base">
    <collision><geometry><box size="0.4 0.3 0.1"/></geometry></collision>
  </link>
  <link name="arm">
    <collision>
      <origin xyz="0 0 0.25" rpy="1.5707963267948966 0 0"/>
      <geometry><cylinder radius="0.03" length="0.5"/></geometry>
    </collision>
  </link>
  <link name="hand">
    <collision><origin xyz="0.1 0 0"/><geometry><sphere radius="0.05"/></geometry></collision>
    <collision><origin xyz="-0.1 0 0"/><geometry><sphere radius="0.04"/></geometry></collision>
  </link>
  <link name="cover">
    <collision><geometry><mesh filename="package://soft_body_sim/config/meshes/cover.stl"/></geometry></collision>
  </link>
  <joint name="base_arm" type="revolute">
    <parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
  <joint name="arm_hand" type="fixed"><parent link="arm"/><child link="hand"/></joint>
  <joint name="arm_cover" type="fixed"><parent link="arm"/><child link="cover"/></joint>
</robot>)";

TEST(RobotColliders, EveryBoxSphereAndCylinderCollisionFollowsItsLinkInItsOriginsPose)
{
  RobotCollidersDef robot;
  robot.friction = 0.5;
  robot.restitution = 0.1;
  Colliders colliders;
  std::vector<std::string> skipped;
  addRobotColliders(kRobot, robot, colliders, skipped);
  ASSERT_EQ(colliders.boxes.size(), 1u);
  EXPECT_EQ(colliders.boxes[0].at.name, "base");
  EXPECT_EQ(colliders.boxes[0].at.frame, "base");
  EXPECT_EQ(colliders.boxes[0].size, Vec3(0.4, 0.3, 0.1));
  EXPECT_EQ(colliders.boxes[0].at.friction, 0.5);
  EXPECT_EQ(colliders.boxes[0].at.restitution, 0.1);
  ASSERT_EQ(colliders.cylinders.size(), 1u);
  const Cylinder& arm = colliders.cylinders[0];
  EXPECT_EQ(arm.at.frame, "arm");
  EXPECT_EQ(arm.radius, 0.03);
  EXPECT_EQ(arm.length, 0.5);
  EXPECT_EQ(arm.at.position, Vec3(0, 0, 0.25));
  // roll pi/2: the cylinder's axis (local z) points along -y of the link.
  EXPECT_NEAR((arm.at.orientation * Vec3::UnitZ() - Vec3(0, -1, 0)).norm(), 0.0, 1e-12);
  ASSERT_EQ(colliders.spheres.size(), 2u);
  EXPECT_EQ(colliders.spheres[0].at.name, "hand/0");
  EXPECT_EQ(colliders.spheres[1].at.name, "hand/1");
  EXPECT_EQ(colliders.spheres[1].radius, 0.04);
  EXPECT_EQ(colliders.spheres[1].at.position, Vec3(-0.1, 0, 0));
  ASSERT_EQ(skipped.size(), 1u);
  EXPECT_NE(skipped[0].find("cover"), std::string::npos);
  EXPECT_NE(skipped[0].find("mesh"), std::string::npos);
}

TEST(RobotColliders, NoURDFNoCollisionOrATakenNameIsRefusedSayingWhy)
{
  const auto refusal = [](const std::string& xml, Colliders colliders = {}) {
    std::vector<std::string> skipped;
    try
    {
      addRobotColliders(xml, RobotCollidersDef{}, colliders, skipped);
    }
    catch (const std::invalid_argument& e)
    {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(refusal("<robot name='r'><link name='a'/>").find("no valid URDF"), std::string::npos);
  EXPECT_NE(refusal("<robot name='bare'><link name='a'/></robot>").find("has no box, sphere or cylinder"),
            std::string::npos);
  Colliders taken;
  taken.spheres.push_back(Sphere{});
  taken.spheres[0].at.name = "base";
  EXPECT_NE(refusal(kRobot, taken).find("'base' of link 'base' is already taken"), std::string::npos);
}

}  // namespace
}  // namespace soft_body_sim::test
