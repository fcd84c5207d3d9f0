// A URDF's collisions as colliders (robot_colliders.h), parsed by ROS's urdf package, no master needed.
#include <cmath>
#include <cstdlib>

#include <gtest/gtest.h>

#include "soft_body_sim/core/contact/mesh_field.h"
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
    <collision>
      <origin xyz="0 0 0.1"/>
      <geometry><mesh filename="package://soft_body_sim/config/meshes/part.stl" scale="2 1 0.5"/></geometry>
    </collision>
  </link>
  <link name="lid">
    <collision><geometry><mesh filename="package://soft_body_sim/config/meshes/no_such_lid.stl"/></geometry></collision>
  </link>
  <joint name="base_arm" type="revolute">
    <parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
  <joint name="arm_hand" type="fixed"><parent link="arm"/><child link="hand"/></joint>
  <joint name="arm_cover" type="fixed"><parent link="arm"/><child link="cover"/></joint>
  <joint name="arm_lid" type="fixed"><parent link="arm"/><child link="lid"/></joint>
</robot>)";

/// Puts the package on ROS_PACKAGE_PATH (as `source devel/setup.bash` does) for package:// meshes.
void findThisPackage()
{
  const char* previous = std::getenv("ROS_PACKAGE_PATH");
  ::setenv("ROS_PACKAGE_PATH", (std::string(SOURCE_DIR) + (previous ? ":" + std::string(previous) : "")).c_str(), 1);
}

TEST(RobotColliders, EveryBoxSphereCylinderAndMeshCollisionFollowsItsLinkInItsOriginsPose)
{
  findThisPackage();
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
  // The mesh at its scale (scripts/make_part_stl.py's bracket: 10 x 6 x 8 cm), its file kept for drawing.
  ASSERT_EQ(colliders.meshes.size(), 1u);
  const Mesh& cover = colliders.meshes[0];
  EXPECT_EQ(cover.at.name, "cover");
  EXPECT_EQ(cover.at.frame, "cover");
  EXPECT_EQ(cover.at.position, Vec3(0, 0, 0.1));
  EXPECT_EQ(cover.uri, "package://soft_body_sim/config/meshes/part.stl");
  EXPECT_EQ(cover.scale, Vec3(2, 1, 0.5));
  ASSERT_TRUE(cover.triangles);
  EXPECT_TRUE(expectNear(Vec3(cover.triangles->upper() - cover.triangles->lower()), Vec3(0.2, 0.06, 0.04), 1e-6));
  // A mesh that cannot be read is left out, named with its file and the reason.
  ASSERT_EQ(skipped.size(), 1u);
  EXPECT_NE(skipped[0].find("lid"), std::string::npos) << skipped[0];
  EXPECT_NE(skipped[0].find("no_such_lid.stl"), std::string::npos) << skipped[0];
  EXPECT_NE(skipped[0].find("cannot be read"), std::string::npos) << skipped[0];
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
  EXPECT_NE(refusal("<robot name='bare'><link name='a'/></robot>").find("has no box, sphere, cylinder or readable mesh"),
            std::string::npos);
  Colliders taken;
  taken.spheres.push_back(Sphere{});
  taken.spheres[0].at.name = "base";
  EXPECT_NE(refusal(kRobot, taken).find("'base' of link 'base' is already taken"), std::string::npos);
}

}  // namespace
}  // namespace soft_body_sim::test
