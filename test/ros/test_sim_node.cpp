// Black-box test of the running node (launched by sim_node.test): rates and structure of its outputs,
// poses through tf2, reset, pause, and bad input.
#include <cmath>
#include <functional>
#include <vector>
#include <limits>

#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <std_srvs/Empty.h>
#include <std_srvs/SetBool.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <visualization_msgs/MarkerArray.h>

#include "soft_body_sim/SimState.h"
#include "wait_for.h"
#include "soft_body_sim/scene/scene_loader.h"

namespace soft_body_sim
{
namespace
{
constexpr double kRate = 50.0;  // [Hz], the test scene's rate

geometry_msgs::PoseStamped pose(const std::string& frame, double x, double y, double z)
{
  geometry_msgs::PoseStamped p;
  p.header.frame_id = frame;
  p.header.stamp = ros::Time(0);
  p.pose.position.x = x;
  p.pose.position.y = y;
  p.pose.position.z = z;
  p.pose.orientation.w = 1.0;
  return p;
}

Vec3 toVec3(const geometry_msgs::Point& p) { return Vec3(p.x, p.y, p.z); }

class SimNodeTest : public ::testing::Test
{
protected:
  void SetUp() override
  {
    markers_sub_ = nh_.subscribe<visualization_msgs::MarkerArray>(
        "/soft_body_sim/markers", 10, [this](const visualization_msgs::MarkerArray::ConstPtr& m) {
          markers_ = *m;
          ++marker_count_;
        });
    state_sub_ = nh_.subscribe<SimState>("/soft_body_sim/state", 10, [this](const SimState::ConstPtr& s) {
      state_ = *s;
      stamps_.push_back(s->header.stamp);
      ++state_count_;
    });
    start_pub_ = nh_.advertise<geometry_msgs::PoseStamped>("/soft_body_sim/rope/start/pose", 10);
    end_pub_ = nh_.advertise<geometry_msgs::PoseStamped>("/soft_body_sim/rope/end/pose", 10);
    ASSERT_TRUE(ros::service::waitForService("/soft_body_sim/reset", ros::Duration(20.0)));
    ASSERT_TRUE(ros::service::waitForService("/soft_body_sim/pause", ros::Duration(20.0)));
    setPaused(false);
    ASSERT_TRUE(waitFor([this] { return state_count_ > 0 && marker_count_ > 0; }, 10.0));
    ASSERT_TRUE(waitFor([this] { return start_pub_.getNumSubscribers() > 0 && end_pub_.getNumSubscribers() > 0; }, 10.0));
  }

  /// Waits for `count` more state messages.
  void nextStates(int count)
  {
    const int target = state_count_ + count;
    ASSERT_TRUE(waitFor([&] { return state_count_ >= target; }, 10.0));
  }

  void setPaused(bool paused)
  {
    std_srvs::SetBool request;
    request.request.data = paused;
    ASSERT_TRUE(ros::service::call("/soft_body_sim/pause", request));
    EXPECT_TRUE(request.response.success);
  }

  void reset()
  {
    std_srvs::Empty request;
    ASSERT_TRUE(ros::service::call("/soft_body_sim/reset", request));
  }

  Vec3 node(int i) const { return toVec3(state_.bodies.at(0).positions.at(static_cast<std::size_t>(i))); }

  ros::NodeHandle nh_;
  ros::Subscriber markers_sub_, state_sub_;
  ros::Publisher start_pub_, end_pub_;
  visualization_msgs::MarkerArray markers_;
  SimState state_;
  std::vector<ros::Time> stamps_;
  int marker_count_ = 0;
  int state_count_ = 0;
};

TEST_F(SimNodeTest, MarkersAndStateArriveAtTheConfiguredRateWithMatchingPositions)
{
  const int markers_before = marker_count_, states_before = state_count_;
  const ros::WallTime start = ros::WallTime::now();
  waitFor([] { return false; }, 2.0);
  const double seconds = (ros::WallTime::now() - start).toSec();
  // Timer jitter and delivery on a loaded 2-core machine: within 25 % of the rate.
  EXPECT_NEAR((state_count_ - states_before) / seconds, kRate, 0.25 * kRate);
  EXPECT_NEAR((marker_count_ - markers_before) / seconds, kRate, 0.25 * kRate);

  // Stamps are simulated instants: they advance in whole steps of dt = 1 ms (to the stamp's 1 ns).
  for (std::size_t k = stamps_.size() - 50; k < stamps_.size(); ++k)
  {
    const double advance = (stamps_[k] - stamps_[k - 1]).toSec();
    EXPECT_GT(advance, 0.0);
    EXPECT_NEAR(advance * 1000.0, std::round(advance * 1000.0), 1e-5) << "stamp advance " << advance << " s";
  }

  ASSERT_TRUE(waitFor([this] { return markers_.markers.size() == 2 && markers_.markers[0].header.stamp == state_.header.stamp; }, 5.0));
  EXPECT_EQ(state_.header.frame_id, "world");
  ASSERT_EQ(state_.bodies.size(), 1u);
  EXPECT_EQ(state_.bodies[0].name, "rope");
  ASSERT_EQ(state_.bodies[0].positions.size(), 5u);
  EXPECT_EQ(state_.bodies[0].velocities.size(), 5u);
  const visualization_msgs::Marker& nodes = markers_.markers[0];
  const visualization_msgs::Marker& springs = markers_.markers[1];
  EXPECT_EQ(nodes.ns, "rope");
  EXPECT_EQ(nodes.id, 0);
  EXPECT_EQ(nodes.type, visualization_msgs::Marker::SPHERE_LIST);
  EXPECT_EQ(nodes.header.frame_id, "world");
  EXPECT_EQ(springs.id, 1);
  EXPECT_EQ(springs.type, visualization_msgs::Marker::LINE_LIST);
  EXPECT_EQ(springs.points.size(), 8u);
  ASSERT_EQ(nodes.points.size(), 5u);
  for (int i = 0; i < 5; ++i)
    EXPECT_EQ(toVec3(nodes.points[static_cast<std::size_t>(i)]), node(i)) << "node " << i;
}

TEST_F(SimNodeTest, AnAnchorPoseInAnotherFrameMovesTheNodeToTheTransformedPose)
{
  // offset = world translated by (1, 2, 3) and turned 90 degrees about z: (0.1, 0, 0) in offset is
  // (1, 2.1, 3) in world.
  tf2_ros::StaticTransformBroadcaster broadcaster;
  geometry_msgs::TransformStamped transform;
  transform.header.stamp = ros::Time::now();
  transform.header.frame_id = "world";
  transform.child_frame_id = "offset";
  transform.transform.translation.x = 1.0;
  transform.transform.translation.y = 2.0;
  transform.transform.translation.z = 3.0;
  transform.transform.rotation.z = std::sqrt(0.5);
  transform.transform.rotation.w = std::sqrt(0.5);
  broadcaster.sendTransform(transform);
  const Vec3 expected(1.0, 2.1, 3.0);
  // The transform needs a moment to reach the node's listener; re-send the pose until it lands.
  ASSERT_TRUE(waitFor(
      [&] {
        start_pub_.publish(pose("offset", 0.1, 0.0, 0.0));
        return (node(0) - expected).norm() < 1e-9;
      },
      10.0));
  // Held there, exactly, while the rope swings below it.
  nextStates(5);
  EXPECT_LT((node(0) - expected).norm(), 1e-12);
}

TEST_F(SimNodeTest, DraggingTheRopeEndDragsTheRope)
{
  reset();
  nextStates(2);
  const Vec3 before = node(3);
  const Vec3 goal(0.9, 0.0, 1.0);
  ASSERT_TRUE(waitFor(
      [&] {
        end_pub_.publish(pose("world", goal.x(), goal.y(), goal.z()));
        return (node(4) - goal).norm() < 1e-9;
      },
      10.0));
  // The neighbour follows the dragged end: it moves toward +x by a good part of the 0.5 m pull.
  ASSERT_TRUE(waitFor([&] { return node(3).x() > before.x() + 0.2; }, 5.0)) << "node 3 stayed at " << node(3).transpose();
}

TEST_F(SimNodeTest, ResetRestoresTheInitialPositionsAndPauseStopsTheMotion)
{
  const SceneDef scene = loadSceneFile(std::string(SOURCE_DIR) + "/test/ros/node_test_scene.yaml");
  nextStates(10);  // the rope has moved
  setPaused(true);
  reset();
  nextStates(2);
  for (int i = 0; i < 5; ++i)
    EXPECT_EQ(node(i), scene.bodies[0].nodes[static_cast<std::size_t>(i)].position) << "node " << i;
  // Paused: nothing moves.
  const Vec3 held = node(2);
  nextStates(10);
  EXPECT_EQ(node(2), held);
  // Resumed: the free nodes fall.
  setPaused(false);
  ASSERT_TRUE(waitFor([&] { return node(2).z() < held.z() - 1e-3; }, 5.0));
}

TEST_F(SimNodeTest, NaNInfiniteAndUnknownFramePosesAreDroppedAndNothingNonFiniteIsPublished)
{
  nextStates(2);
  const Vec3 held = node(0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  geometry_msgs::PoseStamped bad_orientation = pose("world", 0.0, 0.0, 0.0);
  bad_orientation.pose.orientation.x = nan;
  for (int repeat = 0; repeat < 20; ++repeat)
  {
    start_pub_.publish(pose("world", nan, 0.0, 0.0));
    start_pub_.publish(pose("world", 0.0, inf, 0.0));
    start_pub_.publish(pose("no_such_frame", 0.5, 0.5, 0.5));
    start_pub_.publish(pose("", 0.5, 0.5, 0.5));
    start_pub_.publish(bad_orientation);
    nextStates(1);
  }
  nextStates(5);  // the node is alive and still publishing
  EXPECT_EQ(node(0), held);
  for (const BodyState& body : state_.bodies)
    for (std::size_t i = 0; i < body.positions.size(); ++i)
      EXPECT_TRUE(toVec3(body.positions[i]).allFinite() &&
                  Vec3(body.velocities[i].x, body.velocities[i].y, body.velocities[i].z).allFinite());
  for (const visualization_msgs::Marker& m : markers_.markers)
    for (const geometry_msgs::Point& p : m.points)
      EXPECT_TRUE(toVec3(p).allFinite());
}

}  // namespace
}  // namespace soft_body_sim

int main(int argc, char** argv)
{
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_sim_node");
  return RUN_ALL_TESTS();
}
