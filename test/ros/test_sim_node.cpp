// Black-box test of the running node (launched by sim_node.test, and on the nodelet by nodelet.test):
// rates and structure of its outputs, poses through tf2, reset, pause, and bad input: non-finite,
// unknown-frame, stale, far-future and flooding poses.
#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <gtest/gtest.h>
#include <ros/master.h>
#include <ros/network.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>
#include <std_msgs/Time.h>
#include <std_srvs/Empty.h>
#include <std_srvs/SetBool.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <visualization_msgs/InteractiveMarkerFeedback.h>
#include <visualization_msgs/InteractiveMarkerUpdate.h>
#include <visualization_msgs/MarkerArray.h>
#include <xmlrpcpp/XmlRpcClient.h>

#include "soft_body_sim/SimState.h"
#include "soft_body_sim/ros/anchor_handles.h"
#include "soft_body_sim/ros/ros_converter.h"
#include "soft_body_sim/scene/scene_loader.h"
#include "wait_for.h"

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
  p.pose = RosConverter::toPose(Vec3(x, y, z));
  return p;
}

/// The process id of the node publishing `topic`: the simulator's own, or the nodelet manager holding it
/// (through the master's system state and the node's slave API, as rosnode info does). 0 if not found.
int publisherPid(const std::string& topic)
{
  XmlRpc::XmlRpcValue args, result, payload;
  args[0] = ros::this_node::getName();
  if (!ros::master::execute("getSystemState", args, result, payload, true))
    return 0;
  std::string node;
  for (int k = 0; k < payload[0].size(); ++k)
    if (static_cast<std::string>(payload[0][k][0]) == topic && payload[0][k][1].size() > 0)
      node = static_cast<std::string>(payload[0][k][1][0]);
  args[1] = node;
  std::string host;
  uint32_t port = 0;
  if (node.empty() || !ros::master::execute("lookupNode", args, result, payload, true) ||
      !ros::network::splitURI(static_cast<std::string>(payload), host, port))
    return 0;
  XmlRpc::XmlRpcClient client(host.c_str(), static_cast<int>(port), "/");
  XmlRpc::XmlRpcValue caller(ros::this_node::getName()), answer;
  if (!client.execute("getPid", caller, answer) || answer.size() < 3)
    return 0;
  return static_cast<int>(answer[2]);
}

/// [kB] resident memory of process `pid` (VmRSS of /proc/PID/status); -1 if unreadable.
long residentKilobytes(int pid)
{
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind("VmRSS:", 0) == 0)
      return std::stol(line.substr(6));
  return -1;
}

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
      factors_.push_back(s->real_time_factor);
      start_path_.emplace_back(s->header.stamp, RosConverter::toVec3(s->bodies.at(0).positions.at(0)));
      ++state_count_;
    });
    start_time_sub_ = nh_.subscribe<std_msgs::Time>("/soft_body_sim/start_time", 10,
                                                    [this](const std_msgs::Time::ConstPtr& t) { start_time_ = t->data; });
    log_sub_ = nh_.subscribe<rosgraph_msgs::Log>("/rosout", 1000, [this](const rosgraph_msgs::Log::ConstPtr& m) {
      if (m->level >= rosgraph_msgs::Log::WARN)
        warnings_.push_back(m->msg);
    });
    start_pub_ = nh_.advertise<geometry_msgs::PoseStamped>("/soft_body_sim/rope/start/pose", 10);
    // Room for a whole burst of the flood test: the node, not this publisher, is to be flooded.
    end_pub_ = nh_.advertise<geometry_msgs::PoseStamped>("/soft_body_sim/rope/end/pose", 20000);
    ASSERT_TRUE(ros::service::waitForService("/soft_body_sim/reset", ros::Duration(20.0)));
    ASSERT_TRUE(ros::service::waitForService("/soft_body_sim/pause", ros::Duration(20.0)));
    setPaused(false);
    ASSERT_TRUE(waitFor([this] { return state_count_ > 0 && marker_count_ > 0; }, 10.0));
    ASSERT_TRUE(waitFor([this] { return start_pub_.getNumSubscribers() > 0 && end_pub_.getNumSubscribers() > 0; }, 10.0));
  }

  // The divergence guard is a safety net for users; a catch in a test not about it is a bug it would hide.
  void TearDown() override
  {
    ros::spinOnce();
    EXPECT_EQ(state_.divergence_events, 0u) << "the divergence guard caught a body";
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

  Vec3 node(int i) const { return RosConverter::toVec3(state_.bodies.at(0).positions.at(static_cast<std::size_t>(i))); }

  /// Whether a warning logged since warnings_[from] holds every one of `parts`.
  bool warned(std::size_t from, const std::vector<std::string>& parts) const
  {
    for (std::size_t k = from; k < warnings_.size(); ++k)
    {
      bool all = true;
      for (const std::string& part : parts)
        all = all && warnings_[k].find(part) != std::string::npos;
      if (all)
        return true;
    }
    return false;
  }

  /// Publishes `count` poses of the rope's end, stamped now, from `from` in steps of `step` [m] along
  /// x, in bursts of ten per millisecond (10 kHz), spinning callbacks between bursts. Returns the last.
  Vec3 flood(const Vec3& from, double step, int count)
  {
    Vec3 last = from;
    ros::WallTime next = ros::WallTime::now();
    for (int k = 0; k < count; ++k)
    {
      last = from + Vec3(step * k, 0.0, 0.0);
      geometry_msgs::PoseStamped p = pose("world", last.x(), last.y(), last.z());
      p.header.stamp = ros::Time::now();
      end_pub_.publish(p);
      if (k % 10 == 9)
      {
        ros::spinOnce();
        next += ros::WallDuration(0.001);
        const ros::WallDuration ahead = next - ros::WallTime::now();
        if (ahead > ros::WallDuration(0))
          ahead.sleep();
      }
    }
    return last;
  }

  ros::NodeHandle nh_;
  ros::Subscriber markers_sub_, state_sub_, start_time_sub_, log_sub_;
  ros::Publisher start_pub_, end_pub_;
  visualization_msgs::MarkerArray markers_;
  SimState state_;
  ros::Time start_time_;              ///< the latest ~start_time: the ROS time of simulated time 0
  std::vector<std::string> warnings_;  ///< every WARN or worse on /rosout
  std::vector<ros::Time> stamps_;
  std::vector<double> factors_;  ///< the real-time factor of every state
  std::vector<std::pair<ros::Time, Vec3>> start_path_;  ///< (stamp, node 0) of every state
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
    EXPECT_EQ(RosConverter::toVec3(nodes.points[static_cast<std::size_t>(i)]), node(i)) << "node " << i;
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

TEST_F(SimNodeTest, AFrameIdWithALeadingSlashIsTakenWithoutItWithOneWarningPerTopic)
{
  const std::size_t from = warnings_.size();
  const Vec3 expected(0.05, 0.02, 1.1);
  // "/world" is the scene's frame "world": no transform, the node goes exactly there.
  ASSERT_TRUE(waitFor(
      [&] {
        start_pub_.publish(pose("/world", expected.x(), expected.y(), expected.z()));
        return node(0) == expected;
      },
      10.0));
  nextStates(5);
  EXPECT_EQ(node(0), expected);
  const auto slash_warnings = [&] {
    int count = 0;
    for (std::size_t k = from; k < warnings_.size(); ++k)
      count += warnings_[k].find("leading slash") != std::string::npos;
    return count;
  };
  EXPECT_TRUE(waitFor([&] { return warned(from, { "/soft_body_sim/rope/start/pose", "leading slash" }); }, 10.0));
  EXPECT_EQ(slash_warnings(), 1);
}

// The handles on their own (in this process, whose spinner serves their server): rviz, or anyone on
// ~handles/feedback, may send a NaN pose, which interactive_markers' server takes for the handle's next
// update before the callback sees it.
TEST(AnchorHandlesTest, ANonFiniteFeedbackPoseIsNeitherPassedOnNorSentBackToClients)
{
  ros::NodeHandle nh;
  const std::string ns = "/nan_test/handles";
  AnchorHandles handles(ns, "world");
  handles.add("a", "/nan_test/a/pose", Vec3(0.0, 0.0, 1.0));
  handles.add("b", "/nan_test/b/pose", Vec3(1.0, 0.0, 1.0));
  handles.applyChanges();
  std::vector<geometry_msgs::Pose> sent;  // every pose on a's topic and in the server's updates
  int updates_of_a = 0;
  ros::Subscriber a_sub = nh.subscribe<geometry_msgs::PoseStamped>(
      "/nan_test/a/pose", 10, [&](const geometry_msgs::PoseStamped::ConstPtr& p) { sent.push_back(p->pose); });
  ros::Subscriber update_sub = nh.subscribe<visualization_msgs::InteractiveMarkerUpdate>(
      ns + "/update", 100, [&](const visualization_msgs::InteractiveMarkerUpdate::ConstPtr& update) {
        for (const visualization_msgs::InteractiveMarker& marker : update->markers)
          sent.push_back(marker.pose);
        for (const visualization_msgs::InteractiveMarkerPose& pose : update->poses)
        {
          sent.push_back(pose.pose);
          updates_of_a += pose.name == "a";
        }
      });
  ros::Publisher feedback_pub = nh.advertise<visualization_msgs::InteractiveMarkerFeedback>(ns + "/feedback", 10);
  ASSERT_TRUE(waitFor([&] { return feedback_pub.getNumSubscribers() > 0 && update_sub.getNumPublishers() > 0; }, 10.0));
  visualization_msgs::InteractiveMarkerFeedback feedback;
  feedback.header.frame_id = "world";
  feedback.client_id = "/test_sim_node/rviz";
  feedback.marker_name = "a";
  feedback.control_name = "move_3d";
  feedback.event_type = visualization_msgs::InteractiveMarkerFeedback::POSE_UPDATE;
  feedback.pose.position.x = std::numeric_limits<double>::quiet_NaN();
  feedback.pose.orientation.w = 1.0;
  feedback_pub.publish(feedback);
  // As the node's ticks do: b follows its (moving) node and the batch goes out, until an update of a.
  int tick = 0;
  ASSERT_TRUE(waitFor(
      [&] {
        handles.follow("b", Vec3(1.0 + 0.01 * ++tick, 0.0, 1.0));
        handles.applyChanges();
        return updates_of_a > 0;
      },
      10.0));
  for (const geometry_msgs::Pose& pose : sent)
  {
    const Vec3 orientation(pose.orientation.x, pose.orientation.y, pose.orientation.z);
    EXPECT_TRUE(RosConverter::toVec3(pose.position).allFinite() && orientation.allFinite() &&
                std::isfinite(pose.orientation.w));
  }
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

TEST_F(SimNodeTest, NaNInfiniteUnknownAndHugeFramePosesAreDroppedAndNothingNonFiniteIsPublished)
{
  nextStates(2);
  const Vec3 held = node(0);
  const std::size_t from = warnings_.size();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  geometry_msgs::PoseStamped bad_orientation = pose("world", 0.0, 0.0, 0.0);
  bad_orientation.pose.orientation.x = nan;
  const geometry_msgs::PoseStamped huge_frame = pose(std::string(1 << 20, 'f'), 0.5, 0.5, 0.5);  // 1 MB
  for (int repeat = 0; repeat < 20; ++repeat)
  {
    start_pub_.publish(huge_frame);
    start_pub_.publish(pose("world", nan, 0.0, 0.0));
    start_pub_.publish(pose("world", 0.0, inf, 0.0));
    start_pub_.publish(pose("no_such_frame", 0.5, 0.5, 0.5));
    start_pub_.publish(pose("", 0.5, 0.5, 0.5));
    start_pub_.publish(bad_orientation);
    nextStates(1);
  }
  nextStates(5);  // the node is alive and still publishing
  EXPECT_EQ(node(0), held);
  EXPECT_TRUE(waitFor([&] { return warned(from, { "/soft_body_sim/rope/start/pose", "1048576 characters" }); }, 10.0));
  for (const BodyState& body : state_.bodies)
    for (std::size_t i = 0; i < body.positions.size(); ++i)
      EXPECT_TRUE(RosConverter::toVec3(body.positions[i]).allFinite() &&
                  Vec3(body.velocities[i].x, body.velocities[i].y, body.velocities[i].z).allFinite());
  for (const visualization_msgs::Marker& m : markers_.markers)
    for (const geometry_msgs::Point& p : m.points)
      EXPECT_TRUE(RosConverter::toVec3(p).allFinite());
}

TEST_F(SimNodeTest, StaleAndFarFuturePosesAreDroppedWithAWarningNamingTheTopicOthersWaitForTheirStep)
{
  reset();
  nextStates(2);
  const Vec3 held = node(0);
  const std::size_t from = warnings_.size();
  const std::string topic = "/soft_body_sim/rope/start/pose";
  geometry_msgs::PoseStamped stale = pose("world", 0.3, 0.3, 1.3);
  stale.header.stamp = ros::Time::now() - ros::Duration(5.0);  // the default ~max_input_age: 1 s
  start_pub_.publish(stale);
  geometry_msgs::PoseStamped future = pose("world", 0.3, 0.3, 1.3);
  future.header.stamp = ros::Time::now() + ros::Duration(60.0);  // the default ~max_input_lead: 5 s
  start_pub_.publish(future);
  geometry_msgs::PoseStamped last_stamp = pose("world", 0.3, 0.3, 1.3);  // 2106: no overflow, no crash
  last_stamp.header.stamp = ros::Time(std::numeric_limits<uint32_t>::max(), 999999999);
  start_pub_.publish(last_stamp);
  ASSERT_TRUE(waitFor([&] { return warned(from, { topic, "behind", "max_input_age" }) &&
                                   warned(from, { topic, "ahead", "max_input_lead" }); }, 10.0));
  nextStates(5);
  EXPECT_EQ(node(0), held);

  // Stamped 0.3 s ago, as over a slow network: applied at the next step.
  const Vec3 late(0.05, 0.0, 1.0);
  geometry_msgs::PoseStamped late_pose = pose("world", late.x(), late.y(), late.z());
  late_pose.header.stamp = ros::Time::now() - ros::Duration(0.3);
  start_pub_.publish(late_pose);
  ASSERT_TRUE(waitFor([&] { return (node(0) - late).norm() < 1e-9; }, 10.0)) << node(0).transpose();

  // Stamped 0.5 s ahead: held, then applied in the step its stamp falls in (dt = 1 ms), to the state.
  const Vec3 ahead(-0.05, 0.0, 1.0);
  geometry_msgs::PoseStamped ahead_pose = pose("world", ahead.x(), ahead.y(), ahead.z());
  const ros::Time due = ros::Time::now() + ros::Duration(0.5);
  ahead_pose.header.stamp = due;
  const std::size_t first = start_path_.size();
  start_pub_.publish(ahead_pose);
  ASSERT_TRUE(waitFor([&] { return state_.header.stamp > due + ros::Duration(0.1); }, 10.0));
  int before = 0, after = 0;
  for (std::size_t k = first; k < start_path_.size(); ++k)
  {
    const auto& [stamp, position] = start_path_[k];
    if (stamp <= due)
    {
      EXPECT_LT((position - late).norm(), 1e-9) << "at " << stamp << ", due " << due;
      ++before;
    }
    else if (stamp >= due + ros::Duration(0.001))
    {
      EXPECT_LT((position - ahead).norm(), 1e-9) << "at " << stamp << ", due " << due;
      ++after;
    }
  }
  EXPECT_GT(before, 5);
  EXPECT_GT(after, 2);
}

TEST_F(SimNodeTest, APoseFloodAt10kHzKeepsMemoryBoundedTheLatestPoseWinsAndTheFactorIsHonest)
{
  reset();
  nextStates(2);
  const int pid = publisherPid("/soft_body_sim/state");
  ASSERT_GT(pid, 0);
  const Vec3 start(0.4, 0.0, 1.0);  // the rope's end, as loaded
  // A short flood first, so that buffers and queues have their working size when memory is measured.
  flood(start, 0.0, 2000);
  nextStates(10);
  ASSERT_TRUE(waitFor([&] { return !start_time_.isZero(); }, 10.0));
  const long before = residentKilobytes(pid);

  // 1. Running: 3 s of poses stamped now, each a step 10 um further along x.
  const ros::WallTime wall_a = ros::WallTime::now();
  const double simulated_a = (state_.header.stamp - start_time_).toSec();
  const std::size_t factors_a = factors_.size();
  const Vec3 last = flood(start, 1e-5, 30000);
  ASSERT_TRUE(waitFor([&] { return (node(4) - last).norm() < 1e-9; }, 30.0)) << node(4).transpose();
  // The reported real-time factor against the simulated time the stamps and ~start_time show (stamp =
  // start time + simulated time; falling behind moves the start time on): not a speed requirement.
  const double wall = (ros::WallTime::now() - wall_a).toSec();
  const double measured = ((state_.header.stamp - start_time_).toSec() - simulated_a) / wall;
  double reported = 0.0;
  for (std::size_t k = factors_a; k < factors_.size(); ++k)
    reported += factors_[k] / static_cast<double>(factors_.size() - factors_a);
  std::cout << "flood: real-time factor " << measured << " measured, " << reported << " reported, over " << wall
            << " s" << std::endl;
  EXPECT_NEAR(reported, measured, 0.15);

  // 2. Paused: nothing falls due, so the poses pile up to ~max_held_inputs (default 1000), then the
  // earliest go. Held without that bound, these 40000 would take some 5 MB (~125 B each, measured).
  setPaused(true);
  nextStates(2);
  const std::size_t from = warnings_.size();
  const Vec3 back = flood(last, -0.75e-5, 40000);
  ASSERT_TRUE(waitFor([&] { return warned(from, { "/soft_body_sim/rope/end/pose", "max_held_inputs" }); }, 30.0));
  setPaused(false);
  ASSERT_TRUE(waitFor([&] { return (node(4) - back).norm() < 1e-9; }, 30.0)) << node(4).transpose();
  nextStates(5);
  const long after = residentKilobytes(pid);
  std::cout << "flood: resident memory " << before << " kB before, " << after << " kB after" << std::endl;
  for (const BodyState& body : state_.bodies)
    for (const geometry_msgs::Point& p : body.positions)
      EXPECT_TRUE(RosConverter::toVec3(p).allFinite());
  EXPECT_LT(after - before, 2048);
}

}  // namespace
}  // namespace soft_body_sim

int main(int argc, char** argv)
{
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_sim_node");
  return RUN_ALL_TESTS();
}
