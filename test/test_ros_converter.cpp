// Message conversions as plain structs (no ROS master): markers, state, poses and reconfigure configs.
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include <gtest/gtest.h>

#include "soft_body_sim/core/bodies/humanoid.h"
#include "soft_body_sim/core/bodies/rod.h"
#include "soft_body_sim/core/bodies/rope.h"
#include "soft_body_sim/core/contact/mesh_field.h"
#include "soft_body_sim/core/elements/tetrahedra.h"
#include "soft_body_sim/ros/ros_converter.h"
#include "test_util.h"

namespace soft_body_sim::test
{
namespace
{
World twoBodies()
{
  SceneDef scene = oneBodyScene(IntegratorType::SemiImplicitEuler, 1e-3);
  RopeDef rope;
  rope.nodes = 4;
  rope.from = Vec3(0, 0, 1);
  rope.to = Vec3(0.3, 0, 1);
  scene.bodies[0] = buildRope("rope", rope);
  BodyDef pair;
  pair.name = "pair";
  pair.nodes = { NodeDef{ Vec3(1, 2, 3), 1.0, Vec3(0.5, 0, 0) }, NodeDef{ Vec3(1, 2, 4), 1.0 } };
  pair.constraints = { ConstraintDef{ 0, 1, 0.0, std::nullopt } };
  scene.bodies.push_back(pair);
  return buildWorld(scene);
}

TEST(RosConverter, MarkersHaveOneNamespacePerBodyWithNodesAndLinks)
{
  const World world = twoBodies();
  const ros::Time stamp(12.5);
  const visualization_msgs::MarkerArray array = RosConverter::toMarkers(world, "map", stamp);
  ASSERT_EQ(array.markers.size(), 4u);
  const std::string names[] = { "rope", "pair" };
  const std::size_t links[] = { 3, 1 };
  for (std::size_t b = 0; b < 2; ++b)
  {
    const visualization_msgs::Marker& nodes = array.markers[2 * b];
    const visualization_msgs::Marker& lines = array.markers[2 * b + 1];
    EXPECT_EQ(nodes.ns, names[b]);
    EXPECT_EQ(nodes.id, 0);
    EXPECT_EQ(nodes.type, visualization_msgs::Marker::SPHERE_LIST);
    EXPECT_EQ(lines.ns, names[b]);
    EXPECT_EQ(lines.id, 1);
    EXPECT_EQ(lines.type, visualization_msgs::Marker::LINE_LIST);
    EXPECT_EQ(lines.points.size(), 2 * links[b]);
    for (const visualization_msgs::Marker* m : { &nodes, &lines })
    {
      EXPECT_EQ(m->header.frame_id, "map");
      EXPECT_EQ(m->header.stamp, stamp);
      EXPECT_EQ(m->action, visualization_msgs::Marker::ADD);
      EXPECT_EQ(m->pose.orientation.w, 1.0);
      EXPECT_GT(m->scale.x, 0.0);
      EXPECT_EQ(m->color.a, 1.0f);
    }
  }
  // Node order: the rope's node 2 and the pair's node 1.
  EXPECT_DOUBLE_EQ(array.markers[0].points[2].x, 0.2);
  EXPECT_EQ(array.markers[2].points[1].z, 4.0);
  // The rope's second spring joins nodes 1 and 2.
  EXPECT_DOUBLE_EQ(array.markers[1].points[2].x, 0.1);
  EXPECT_DOUBLE_EQ(array.markers[1].points[3].x, 0.2);
}

TEST(RosConverter, StateCarriesPositionsVelocitiesAndStatistics)
{
  const World world = twoBodies();
  const SimState state = RosConverter::toState(world, "map", ros::Time(3.0), StepStatistics{ 0.98, 2e-5 });
  EXPECT_EQ(state.header.frame_id, "map");
  EXPECT_EQ(state.header.stamp, ros::Time(3.0));
  EXPECT_EQ(state.real_time_factor, 0.98);
  EXPECT_EQ(state.wall_seconds_per_step, 2e-5);
  ASSERT_EQ(state.bodies.size(), 2u);
  EXPECT_EQ(state.bodies[0].name, "rope");
  ASSERT_EQ(state.bodies[0].positions.size(), 4u);
  ASSERT_EQ(state.bodies[1].velocities.size(), 2u);
  EXPECT_EQ(state.bodies[1].positions[0].y, 2.0);
  EXPECT_EQ(state.bodies[1].velocities[0].x, 0.5);
  EXPECT_EQ(state.divergence_events, 0u);
  EXPECT_EQ(state.bodies[0].integrator, "semi_implicit_euler");
  EXPECT_EQ(state.bodies[0].divergence_events, 0u);
  EXPECT_FALSE(state.bodies[0].frozen);
}

TEST(RosConverter, StateSaysWhatTheDivergenceGuardDidToEachBody)
{
  expectGuardEvents();  // about divergence: the guard catches it
  World world = twoBodies();
  // A runaway node of the pair (body 1): caught, restored; the policy switches it to implicit_euler.
  world.setNode(world.model().bodies[1].first, Vec3(1, 2, 3), Vec3(1e6, 0, 0));
  world.step();
  StepStatistics statistics;
  statistics.divergence_events = 7;  // the node's count since it started, across resets
  const SimState state = RosConverter::toState(world, "map", ros::Time(3.0), statistics);
  EXPECT_EQ(state.divergence_events, 7u);
  EXPECT_EQ(state.bodies[0].integrator, "semi_implicit_euler");
  EXPECT_EQ(state.bodies[0].divergence_events, 0u);
  EXPECT_EQ(state.bodies[1].integrator, "implicit_euler");
  EXPECT_EQ(state.bodies[1].divergence_events, 1u);
  EXPECT_FALSE(state.bodies[1].frozen);
}

TEST(RosConverter, HoldersAreTheAnchorsThenTheGraspsWithTheirWrenchesInStateMarkersAndWrenchMessages)
{
  // A 2 kg mass hangs at rest 1 m below an anchored 0.5 kg node on a spring stretched by its weight; a
  // grasp holds the rope's end. The anchor carries both weights; the spring's tension is the mass's weight.
  SceneDef scene = oneBodyScene(IntegratorType::SemiImplicitEuler, 1e-3);
  scene.physics.gravity = Vec3(0, 0, -10.0);
  RopeDef rope;
  rope.nodes = 4;
  rope.from = Vec3(0, 0, 1);
  rope.to = Vec3(0.3, 0, 1);
  scene.bodies[0] = buildRope("rope", rope);
  BodyDef weight;
  weight.name = "weight";
  weight.nodes = { NodeDef{ Vec3(0, 0, 0), 0.5, Vec3::Zero(), true }, NodeDef{ Vec3(0, 0, -1.2), 2.0 } };
  weight.springs = { SpringDef{ 0, 1, 100.0, 0.0, 1.0 } };
  weight.anchors = { AnchorDef("hook", 0) };
  scene.bodies.push_back(weight);
  World world = buildWorld(scene);
  world.grasp("gripper", "rope", RigidPose{ Vec3(0.3, 0, 1), Eigen::Quaterniond::Identity() }, 0.01);
  const std::vector<Holder> holders = RosConverter::holders(world);
  ASSERT_EQ(holders.size(), 2u);
  EXPECT_EQ(holders[0].name, "hook");
  EXPECT_EQ(holders[0].body, 1u);
  EXPECT_TRUE(expectNear(holders[0].wrench.force, Vec3(0, 0, -25.0), 1e-12));
  EXPECT_EQ(holders[1].name, "gripper");
  EXPECT_EQ(holders[1].body, 0u);
  EXPECT_TRUE(expectNear(holders[1].origin, Vec3(0.3, 0, 1), 0.0));

  const GraspSlip slip{ 1.5, "other", "weight", 3.0, 2.0 };
  const SimState state = RosConverter::toState(world, "map", ros::Time(3.0), StepStatistics{}, holders, { slip });
  ASSERT_EQ(state.bodies.size(), 2u);
  EXPECT_EQ(state.bodies[0].holders, std::vector<std::string>{ "gripper" });
  EXPECT_EQ(state.bodies[1].holders, std::vector<std::string>{ "hook" });
  ASSERT_EQ(state.bodies[1].wrenches.size(), 1u);
  EXPECT_DOUBLE_EQ(state.bodies[1].wrenches[0].force.z, -25.0);
  EXPECT_EQ(state.bodies[0].tensions.size(), 3u);  // the rope's three segments
  ASSERT_EQ(state.bodies[1].tensions.size(), 1u);
  EXPECT_NEAR(state.bodies[1].tensions[0], 20.0, 1e-12);
  EXPECT_TRUE(state.bodies[0].slips.empty());
  EXPECT_EQ(state.bodies[1].slips,
            std::vector<std::string>{ "grasp 'other' on body 'weight' slipped at t = 1.5 s: force 3 N > max_force 2 N" });

  const visualization_msgs::MarkerArray arrows = RosConverter::toForceMarkers(holders, 0.02, "map", ros::Time(3.0));
  ASSERT_EQ(arrows.markers.size(), 3u);
  EXPECT_EQ(arrows.markers[0].action, visualization_msgs::Marker::DELETEALL);  // arrows of holders gone
  for (const visualization_msgs::Marker& m : arrows.markers)
    EXPECT_EQ(m.ns, "forces");
  const visualization_msgs::Marker& hook = arrows.markers[1];
  EXPECT_EQ(hook.type, visualization_msgs::Marker::ARROW);
  EXPECT_EQ(hook.action, visualization_msgs::Marker::ADD);
  EXPECT_EQ(hook.header.frame_id, "map");
  ASSERT_EQ(hook.points.size(), 2u);
  EXPECT_DOUBLE_EQ(hook.points[0].z, 0.0);
  EXPECT_DOUBLE_EQ(hook.points[1].z, -0.5);  // 25 N at 0.02 m/N

  const geometry_msgs::WrenchStamped wrench = RosConverter::toWrench(holders[0].wrench, "map", ros::Time(3.0));
  EXPECT_EQ(wrench.header.frame_id, "map");
  EXPECT_EQ(wrench.header.stamp, ros::Time(3.0));
  EXPECT_DOUBLE_EQ(wrench.wrench.force.z, -25.0);
  EXPECT_DOUBLE_EQ(wrench.wrench.torque.x, 0.0);
}

TEST(RosConverter, CollidersAreDrawnInTheirCurrentPoseWithTheirExtents)
{
  SceneDef scene = oneBodyScene(IntegratorType::SemiImplicitEuler, 0.5);
  scene.bodies[0].nodes = { NodeDef{ Vec3(5, 5, 5), 1.0 } };
  Sphere ball;
  ball.at.name = "ball";
  ball.radius = 0.2;
  ball.at.position = Vec3(1, 0, 0);
  Capsule rod;
  rod.at.name = "rod";
  rod.radius = 0.01;
  rod.length = 0.5;
  rod.at.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * M_PI, Vec3::UnitY()));  // along x
  rod.at.velocity = Vec3(0, 2, 0);
  Box table;
  table.at.name = "table";
  table.size = Vec3(1.0, 0.6, 0.05);
  Mesh part;
  part.at.name = "part";
  part.at.position = Vec3(0, 0, -3);
  part.uri = "package://soft_body_sim/config/meshes/part.stl";
  part.scale = Vec3(2, 1, 0.5);
  part.triangles = std::make_shared<const TriangleMesh>(TriangleMesh{
      { Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1) }, { { 0, 2, 1 }, { 0, 1, 3 }, { 0, 3, 2 }, { 1, 2, 3 } } });
  scene.colliders = Colliders{ {}, { ball }, { rod }, { table }, {}, { part } };
  World world = buildWorld(scene);
  world.step();  // the rod moves by 2 m/s x 0.5 s
  const visualization_msgs::MarkerArray markers = RosConverter::toMarkers(world, "world", ros::Time(3.0));
  std::vector<visualization_msgs::Marker> drawn;
  for (const visualization_msgs::Marker& m : markers.markers)
    if (m.ns == "colliders")
      drawn.push_back(m);
  ASSERT_EQ(drawn.size(), 6u);  // sphere, cylinder + 2 caps, cube, mesh
  EXPECT_EQ(drawn[0].type, visualization_msgs::Marker::SPHERE);
  EXPECT_EQ(drawn[0].scale.x, 0.4);
  EXPECT_EQ(drawn[0].pose.position.x, 1.0);
  EXPECT_EQ(drawn[1].type, visualization_msgs::Marker::CYLINDER);
  EXPECT_EQ(drawn[1].scale.z, 0.5);
  EXPECT_EQ(drawn[1].scale.x, 0.02);
  EXPECT_NEAR(drawn[1].pose.position.y, 1.0, 1e-12);
  EXPECT_NEAR(drawn[1].pose.orientation.y, std::sqrt(0.5), 1e-12);
  // The caps sit at the ends of the rod's axis, which points along x.
  EXPECT_EQ(drawn[2].type, visualization_msgs::Marker::SPHERE);
  EXPECT_NEAR(std::abs(drawn[2].pose.position.x), 0.25, 1e-12);
  EXPECT_NEAR(drawn[2].pose.position.x, -drawn[3].pose.position.x, 1e-12);
  EXPECT_EQ(drawn[4].type, visualization_msgs::Marker::CUBE);
  EXPECT_EQ(drawn[4].scale.y, 0.6);
  // A mesh: its file at its scale, in the colliders' colour rather than the file's.
  EXPECT_EQ(drawn[5].type, visualization_msgs::Marker::MESH_RESOURCE);
  EXPECT_EQ(drawn[5].mesh_resource, "package://soft_body_sim/config/meshes/part.stl");
  EXPECT_FALSE(drawn[5].mesh_use_embedded_materials);
  EXPECT_EQ(drawn[5].scale.x, 2.0);
  EXPECT_EQ(drawn[5].scale.z, 0.5);
  EXPECT_EQ(drawn[5].pose.position.z, -3.0);
  EXPECT_EQ(drawn[5].color.r, drawn[4].color.r);
  std::set<int> ids;
  for (const visualization_msgs::Marker& m : drawn)
  {
    EXPECT_EQ(m.header.frame_id, "world");
    EXPECT_EQ(m.action, visualization_msgs::Marker::ADD);
    ids.insert(m.id);
  }
  EXPECT_EQ(ids.size(), drawn.size());
  // The state carries each named collider's pose, as drawn: a recording draws them again (state_viewer.h).
  const SimState state = RosConverter::toState(world, "world", ros::Time(3.0), StepStatistics{});
  ASSERT_EQ(state.colliders, (std::vector<std::string>{ "ball", "rod", "table", "part" }));
  ASSERT_EQ(state.collider_poses.size(), 4u);
  for (const auto& [k, marker] : { std::pair{ 0, 0 }, { 1, 1 }, { 2, 4 }, { 3, 5 } })
    EXPECT_EQ(state.collider_poses[k], drawn[marker].pose) << state.colliders[k];
}

TEST(RosConverter, APlaneInTheStateIsAtItsPointWithZAlongItsNormal)
{
  SceneDef scene = oneBodyScene(IntegratorType::SemiImplicitEuler, 0.5);
  scene.colliders.planes.push_back(Plane{ Vec3(0, 0, 1), Vec3(0, -2, 0), 0.0, 0.5, "wall" });
  Capsule finger;
  finger.at.name = "finger";
  finger.at.frame = "gripper";  // not placed until its frame is seen
  finger.radius = 0.01;
  scene.colliders.capsules.push_back(finger);
  const World world = buildWorld(scene);
  const SimState state = RosConverter::toState(world, "world", ros::Time(1.0), StepStatistics{});
  ASSERT_EQ(state.colliders, (std::vector<std::string>{ "wall", "finger" }));
  const std::optional<RigidPose> wall = RosConverter::toRigidPose(state.collider_poses[0]);
  ASSERT_TRUE(wall);
  EXPECT_EQ(wall->position, Vec3(0, 0, 1));
  EXPECT_NEAR((wall->orientation * Vec3::UnitZ() - Vec3(0, -1, 0)).norm(), 0.0, 1e-15);
  EXPECT_FALSE(RosConverter::toRigidPose(state.collider_poses[1]));  // all zeros: not placed
}

TEST(RosConverter, ATransformIsARigidPoseUnlessNotFiniteOrWithoutRotation)
{
  geometry_msgs::Transform transform;
  transform.translation.x = 1.0;
  transform.translation.z = -2.0;
  transform.rotation.z = 2.0;  // a half turn about z, not normalised
  const std::optional<RigidPose> pose = RosConverter::toRigidPose(transform);
  ASSERT_TRUE(pose);
  EXPECT_EQ(pose->position, Vec3(1.0, 0.0, -2.0));
  EXPECT_NEAR((pose->orientation * Vec3::UnitX() - Vec3(-1, 0, 0)).norm(), 0.0, 1e-15);
  transform.rotation.z = 0.0;
  EXPECT_FALSE(RosConverter::toRigidPose(transform));
  transform.rotation.w = 1.0;
  transform.translation.y = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(RosConverter::toRigidPose(transform));
}

TEST(RosConverter, AMarkerWithoutPointsIsSentAsDelete)
{
  SceneDef scene = oneBodyScene(IntegratorType::SemiImplicitEuler, 1e-3);
  scene.bodies[0].nodes = { NodeDef{ Vec3::Zero(), 1.0 } };  // no springs: an empty LINE_LIST
  const visualization_msgs::MarkerArray array = RosConverter::toMarkers(buildWorld(scene), "map", ros::Time(1.0));
  ASSERT_EQ(array.markers.size(), 2u);
  EXPECT_EQ(array.markers[0].action, visualization_msgs::Marker::ADD);
  EXPECT_EQ(array.markers[1].action, visualization_msgs::Marker::DELETE);
}

TEST(RosConverter, ASolidIsItsSurfaceAsATriangleListFacingOutward)
{
  // One tetrahedron, its four faces counter-clockwise seen from outside: rviz shades a triangle by
  // (b - a) x (c - a), which must point away from the solid's centre.
  SceneDef scene = oneBodyScene(IntegratorType::ImplicitEuler, 1e-3);
  BodyDef& body = scene.bodies[0];
  const Vec3 corners[4] = { Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1) };
  NodeArray x(3, 4);
  for (int k = 0; k < 4; ++k)
  {
    body.nodes.push_back(NodeDef{ corners[k], 1.0 });
    x.col(k) = corners[k];
  }
  body.tetrahedra.push_back(makeTetrahedron({ 0, 1, 2, 3 }, x, lameParameters(1.0e5, 0.3)));
  body.surface = { { 0, 2, 1 }, { 0, 1, 3 }, { 0, 3, 2 }, { 1, 2, 3 } };
  const visualization_msgs::MarkerArray array = RosConverter::toMarkers(buildWorld(scene), "map", ros::Time(1.0));
  const auto surface = std::find_if(array.markers.begin(), array.markers.end(), [](const visualization_msgs::Marker& m) {
    return m.type == visualization_msgs::Marker::TRIANGLE_LIST;
  });
  ASSERT_NE(surface, array.markers.end());
  EXPECT_EQ(surface->ns, "body");
  EXPECT_EQ(surface->action, visualization_msgs::Marker::ADD);
  ASSERT_EQ(surface->points.size(), 12u);
  const Vec3 centre(0.25, 0.25, 0.25);
  for (std::size_t t = 0; t < 4; ++t)
  {
    const auto at = [&](std::size_t k) {
      const geometry_msgs::Point& p = surface->points[3 * t + k];
      return Vec3(p.x, p.y, p.z);
    };
    EXPECT_GT((at(1) - at(0)).cross(at(2) - at(0)).dot(at(0) - centre), 0.0) << "triangle " << t;
  }
  // Its nodes are drawn in a namespace of their own, which rviz can hide.
  EXPECT_EQ(array.markers[0].type, visualization_msgs::Marker::SPHERE_LIST);
  EXPECT_EQ(array.markers[0].ns, "body/nodes");
  EXPECT_EQ(array.markers[0].points.size(), 4u);
}

TEST(RosConverter, NonFiniteNodesAreLeftOutOfTheMarkers)
{
  World world = twoBodies();
  world.setNode(1, Vec3(std::numeric_limits<double>::quiet_NaN(), 0, 0), Vec3::Zero());
  const visualization_msgs::MarkerArray array = RosConverter::toMarkers(world, "map", ros::Time(1.0));
  EXPECT_EQ(array.markers[0].points.size(), 3u);  // rope nodes 0, 2, 3
  EXPECT_EQ(array.markers[1].points.size(), 2u);  // only the spring 2-3 has two finite ends
  for (const visualization_msgs::Marker& m : array.markers)
    for (const geometry_msgs::Point& p : m.points)
      EXPECT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
}

TEST(RosConverter, PosesWithNaNOrInfinityAreRejected)
{
  geometry_msgs::Pose pose;
  pose.position.x = 1.0;
  pose.position.y = -2.0;
  pose.position.z = 0.5;
  pose.orientation.w = 1.0;
  Vec3 position;
  std::string why;
  ASSERT_TRUE(RosConverter::fromPose(pose, position, why));
  EXPECT_EQ(position, Vec3(1.0, -2.0, 0.5));

  geometry_msgs::Pose bad = pose;
  bad.position.y = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(RosConverter::fromPose(bad, position, why));
  EXPECT_EQ(why, "position is not finite");
  bad = pose;
  bad.position.z = -std::numeric_limits<double>::infinity();
  EXPECT_FALSE(RosConverter::fromPose(bad, position, why));
  bad = pose;
  bad.orientation.x = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(RosConverter::fromPose(bad, position, why));
  EXPECT_EQ(why, "orientation is not finite");
  EXPECT_EQ(position, Vec3(1.0, -2.0, 0.5));  // untouched by the rejected poses
}

TEST(RosConverter, APositionGoesIntoAPoseWithTheIdentityOrientationAndBack)
{
  const Vec3 p(1.5, -2.25, 0.125);
  const geometry_msgs::Pose pose = RosConverter::toPose(p);
  EXPECT_EQ(pose.position.x, 1.5);
  EXPECT_EQ(pose.position.y, -2.25);
  EXPECT_EQ(pose.position.z, 0.125);
  EXPECT_EQ(pose.orientation.x, 0.0);
  EXPECT_EQ(pose.orientation.y, 0.0);
  EXPECT_EQ(pose.orientation.z, 0.0);
  EXPECT_EQ(pose.orientation.w, 1.0);
  EXPECT_EQ(RosConverter::toVec3(pose.position), p);
  geometry_msgs::Vector3 translation;
  translation.x = 3.0;
  translation.y = 4.0;
  translation.z = -5.0;
  EXPECT_EQ(RosConverter::toVec3(translation), Vec3(3.0, 4.0, -5.0));
}

TEST(RosConverter, APoseGivesAnOrientationMadeUnitOrNoneWhenItIsAllZeros)
{
  geometry_msgs::Pose pose = RosConverter::toPose(Vec3(1.0, 2.0, 3.0));
  pose.orientation.x = 2.0;
  pose.orientation.w = 0.0;
  Vec3 position;
  std::optional<Eigen::Quaterniond> orientation;
  std::string why;
  ASSERT_TRUE(RosConverter::fromPose(pose, position, orientation, why));
  ASSERT_TRUE(orientation);
  EXPECT_TRUE(orientation->isApprox(Eigen::Quaterniond(0.0, 1.0, 0.0, 0.0), 1e-15));
  pose.orientation.x = 0.0;  // all zeros: a message that sets only a position
  ASSERT_TRUE(RosConverter::fromPose(pose, position, orientation, why));
  EXPECT_FALSE(orientation);
  EXPECT_EQ(position, Vec3(1.0, 2.0, 3.0));
}

TEST(RosConverter, ARodIsAStripOfItsDiameterWithItsSegmentsFramesTurnedByItsTwist)
{
  // A weightless rod along x, clamped at its first node, its last turned a quarter turn about x.
  RodDef def;
  def.nodes = 11;
  def.from = Vec3::Zero();
  def.to = Vec3(1.0, 0.0, 0.0);
  def.radius = 0.01;
  def.clamped = { 0 };
  SceneDef scene;
  scene.physics.integrator = IntegratorType::ImplicitEuler;
  scene.physics.gravity = Vec3::Zero();
  scene.bodies.push_back(buildRod("cable", def));
  scene.bodies[0].anchors.push_back(AnchorDef("tip", 10));
  World world = buildWorld(scene);
  for (int k = 1; k <= 10; ++k)
  {
    world.moveAnchor(0, Vec3(1.0, 0.0, 0.0), Eigen::Quaterniond(Eigen::AngleAxisd(0.1 * M_PI / 2 * k, Vec3::UnitX())));
    world.step();
  }
  const visualization_msgs::MarkerArray array = RosConverter::toMarkers(world, "map", ros::Time(1.0));
  const visualization_msgs::Marker* strip = nullptr;
  const visualization_msgs::Marker* axes = nullptr;
  for (const visualization_msgs::Marker& m : array.markers)
  {
    if (m.ns == "cable" && m.type == visualization_msgs::Marker::LINE_STRIP)
      strip = &m;
    if (m.ns == "cable/frames")
      axes = &m;
  }
  ASSERT_TRUE(strip && axes);
  EXPECT_EQ(strip->points.size(), 11u);
  EXPECT_DOUBLE_EQ(strip->scale.x, 0.02);
  ASSERT_EQ(axes->points.size(), 10u * 6u);  // per segment: x, y and z from its midpoint
  ASSERT_EQ(axes->colors.size(), axes->points.size());
  // Segment j's y axis (points 6 j + 2, 6 j + 3) is turned about x by (j + 1/2) / 10 of the quarter turn.
  for (int j = 0; j < 10; ++j)
  {
    const geometry_msgs::Point& from = axes->points[static_cast<std::size_t>(6 * j + 2)];
    const geometry_msgs::Point& to = axes->points[static_cast<std::size_t>(6 * j + 3)];
    const double angle = std::atan2(to.z - from.z, to.y - from.y);
    EXPECT_NEAR(angle, M_PI / 2 * (j + 0.5) / 10, 1e-9) << "segment " << j;
    EXPECT_EQ(axes->colors[static_cast<std::size_t>(6 * j + 2)].g, 1.0f);
  }
  // The state carries the twist per node, and the markers drawn from a state rebuilt from the message
  // are the world's (state_viewer.h).
  const SimState message = RosConverter::toState(world, "map", ros::Time(1.0), StepStatistics{});
  ASSERT_EQ(message.bodies[0].twists.size(), 11u);
  State recorded;
  recorded.position = world.state().position;
  recorded.velocity.setZero(3, 11);
  recorded.twist.setZero(11);
  for (int i = 0; i < 11; ++i)
    recorded.twist[i] = message.bodies[0].twists[static_cast<std::size_t>(i)];
  EXPECT_TRUE(recorded.twist.isApprox(world.state().twist));
  EXPECT_GT(recorded.twist.cwiseAbs().maxCoeff(), 0.1);
  EXPECT_EQ(RosConverter::toMarkers(world.model(), recorded, world.controllers(), world.colliderPoses(), "map",
                                    ros::Time(1.0)),
            array);
}

TEST(RosConverter, TheLivePhysicsGoIntoTheReconfigureConfigAndBack)
{
  World world = twoBodies();
  world.setIntegrator(IntegratorType::Xpbd);
  world.setStepSettings(StepSettings{ 0.004, 3, 7 });
  world.setGravity(Vec3(0.5, -1.0, -9.0));
  world.setDrag(0.25);
  const SimConfig config = RosConverter::toSimConfig(world);
  EXPECT_EQ(config.integrator, "xpbd");
  EXPECT_EQ(config.dt, 0.004);
  EXPECT_EQ(config.substeps, 3);
  EXPECT_EQ(config.iterations, 7);
  EXPECT_EQ(config.drag, 0.25);
  EXPECT_EQ(RosConverter::gravityOf(config), Vec3(0.5, -1.0, -9.0));
  const StepSettings step = RosConverter::stepSettingsOf(config);
  EXPECT_EQ(step.dt, 0.004);
  EXPECT_EQ(step.substeps, 3);
  EXPECT_EQ(step.iterations, 7);
  IntegratorType integrator = IntegratorType::Rk4;
  std::string why;
  ASSERT_TRUE(RosConverter::integratorOf(config, integrator, why));
  EXPECT_EQ(integrator, IntegratorType::Xpbd);
  EXPECT_EQ(why, "");
}

TEST(RosConverter, AnUnknownIntegratorIsRefusedQuotingAtMost32CharactersAndListingTheValidOnes)
{
  SimConfig config = SimConfig::__getDefault__();
  config.integrator = std::string(1000, 'x');
  IntegratorType integrator = IntegratorType::Rk4;
  std::string why;
  EXPECT_FALSE(RosConverter::integratorOf(config, integrator, why));
  EXPECT_EQ(integrator, IntegratorType::Rk4);
  EXPECT_EQ(why.find("integrator '" + std::string(32, 'x') + "...' is unknown; valid:"), 0u) << why;
  for (const std::string& name : integratorNames())
    EXPECT_NE(why.find(" " + name), std::string::npos) << name;
  EXPECT_LT(why.size(), 200u);
}

TEST(RosConverter, ABodyConfigIsTheBodysMaterialFactors)
{
  BodyConfig config = BodyConfig::__getDefault__();
  config.stiffness_scale = 2.0;
  config.damping_scale = 0.5;
  config.pressure_scale = 3.0;
  const BodyScaling scaling = RosConverter::toBodyScaling(config);
  EXPECT_EQ(scaling.stiffness, 2.0);
  EXPECT_EQ(scaling.damping, 0.5);
  EXPECT_EQ(scaling.pressure, 3.0);
}

TEST(World, ABodyHasAMaterialToTuneOnlyIfBuiltWithSpringsConstraintsOrCells)
{
  SceneDef scene = oneBodyScene(IntegratorType::SemiImplicitEuler, 1e-3);
  RopeDef rope;
  rope.nodes = 3;
  scene.bodies[0] = buildRope("rope", rope);
  scene.bodies.push_back(buildHumanoid("person", HumanoidDef{}));
  BodyDef pair;
  pair.name = "pair";
  pair.nodes = { NodeDef{ Vec3(1, 2, 3), 1.0 }, NodeDef{ Vec3(1, 2, 4), 1.0 } };
  pair.constraints = { ConstraintDef{ 0, 1, 0.0, std::nullopt } };
  scene.bodies.push_back(pair);
  const World world = buildWorld(scene);
  EXPECT_TRUE(world.hasMaterial(0));   // springs
  EXPECT_FALSE(world.hasMaterial(1));  // kinematic nodes only
  EXPECT_TRUE(world.hasMaterial(2));   // a constraint
}

}  // namespace
}  // namespace soft_body_sim::test
