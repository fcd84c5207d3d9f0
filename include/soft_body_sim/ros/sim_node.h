// The ROS node over the core: a timer advances the World in fixed steps and publishes markers, state
// and diagnostics; anchor and target poses arrive on topics (or from rviz handles) in any tf frame and
// take effect at the step their stamp falls in; anchors may follow tf frames; dynamic_reconfigure tunes
// the physics live; services reset, pause, attach, detach, grasp and release; each anchor's and grasp's
// wrench is published. The same class runs as a node
// (sim_node_main.cpp) and as a nodelet (sim_nodelet.cpp).
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <diagnostic_updater/diagnostic_updater.h>
#include <geometry_msgs/PoseStamped.h>
#include <ros/ros.h>
#include <std_srvs/Empty.h>
#include <std_srvs/SetBool.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include "soft_body_sim/Attach.h"
#include "soft_body_sim/BodyConfig.h"
#include "soft_body_sim/Detach.h"
#include "soft_body_sim/Grasp.h"
#include "soft_body_sim/StateFile.h"
#include "soft_body_sim/SimConfig.h"
#include "soft_body_sim/core/scene_def.h"
#include "soft_body_sim/ros/anchor_handles.h"
#include "soft_body_sim/ros/camera_publisher.h"
#include "soft_body_sim/ros/input_glide.h"
#include "soft_body_sim/ros/input_schedule.h"
#include "soft_body_sim/ros/reconfigure_server.h"
#include "soft_body_sim/ros/ros_converter.h"

namespace soft_body_sim
{
/// The largest file ~load_state reads [bytes], refused by its size before it is read: a snapshot of a
/// scene of kMaxSceneNodes nodes under implicit Euler with self-contact, at the ~1 kB a node that a cloth's
/// takes (docs/physics.md, "Snapshots and clones"), with margin.
constexpr std::uintmax_t kMaxStateFileBytes = std::uintmax_t{ 4 } << 30;

class SimNode
{
public:
  /// @param nh the node's namespace handle; @param private_nh its private (~) handle
  /// @param name the node's (or nodelet's) name, for diagnostics and log lines
  SimNode(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh, const std::string& name = ros::this_node::getName());

  /// Loads the scene named by ~scene with the package's loader, then creates the topics, services,
  /// handles, reconfigure servers and the timer. Throws SceneError (or std::runtime_error) with one
  /// clear line if it cannot start.
  void initialize();

private:
  // --- time (sim_node.cpp)
  void onTimer(const ros::TimerEvent& event);
  /// Simulates whole steps up to `now`, at most max_steps_per_tick_ of them (no cap under /use_sim_time),
  /// and none begun after tick_budget_ of wall time: the steps left wait for the next tick.
  void advance(const ros::Time& now, double elapsed);
  /// Warns (throttled) that a tick ran out of tick_budget_ after `taken` of `steps` steps in `wall` [s].
  void warnOverBudget(long steps, long taken, double wall) const;
  /// The ROS time of the simulated instant world time `t` [s].
  ros::Time rosTime(double t) const { return epoch_ + ros::Duration(t); }
  /// Publishes markers and state stamped with the ROS time of the simulated instant, and the handles.
  void publish();
  void printStatus(const ros::Time& now);
  /// Builds the world from the scene and re-applies the live tuning and the tf-following anchors.
  void buildWorldFromScene();
  /// Every anchor, collider and grasp that follows a tf frame (the scene's, ~attach's, ~grasp's) follows it
  /// afresh.
  void followFrames();
  /// What the node keeps of the world's moment starts again from the world's time and step: the catch-up
  /// cap, the state timer, the inputs waiting for their stamps, the glides, the cameras' frames.
  void restartAtWorldTime();

  // --- inputs (sim_node_inputs.cpp)
  /// ~max_input_age [s], ~max_input_lead [s] and ~max_held_inputs (see InputLimits); throws, naming the
  /// parameter, if one is set to a wrong type or out of range.
  InputLimits readInputLimits() const;
  /// Reads the input limits and subscribes to every anchor's pose topic and every target topic.
  void subscribeInputs();
  void addHandles();
  /// Queues an input for the step its stamp falls in (stamp 0 means now), or drops it with a throttled
  /// warning naming `topic` (stale, too far ahead); warns when its source was full.
  void schedule(const std::string& topic, const ros::Time& stamp, const ScheduledInput& input);
  void applyDueInputs(const ros::Time& step_end);
  /// Warns (throttled) when an anchor input would move a rod's held end more than a segment per sub-step.
  void warnIfRodEndJumps(const ScheduledInput& input) const;
  /// The pose's position in the scene frame (its frame_id through tfFrame), and if `orientation` is given
  /// its orientation there (nullopt when the message's is all zeros, RosConverter::fromPose); false (with a
  /// throttled warning naming `topic` and the reason) if it is not finite or its frame cannot be transformed.
  bool toSceneFrame(const geometry_msgs::PoseStamped& pose, const std::string& topic, Vec3& position,
                    std::optional<Eigen::Quaterniond>* orientation = nullptr);
  /// Why a position [m] in the scene frame is no input the node takes (beyond ~workspace_radius), or empty.
  std::string outsideWorkspace(const Vec3& position) const;
  /// `frame` without leading slashes ("/world" is "world": tf2 refuses the slash, which tf1 allowed and
  /// many still write); warns the first time `source` (a topic, a service) sends one.
  std::string tfFrame(const std::string& frame, const std::string& source);
  /// The pose of tf frame `frame` in the scene frame at ROS time `stamp` (the latest transform if tf has
  /// none that recent yet); nullopt with a throttled warning if tf has none at all, or one that is not
  /// finite or beyond ~workspace_radius; `why`, if given, is set to the reason; `newest`, if given, to the
  /// latest transform's stamp when that was used (the frame is late, or `stamp` is 0), to nullopt when tf
  /// interpolated.
  std::optional<RigidPose> framePose(const std::string& frame, const ros::Time& stamp, std::string* why = nullptr,
                                     std::optional<ros::Time>* newest = nullptr);
  /// A holder's or collider's glide along the tf frame it follows, and the pause count it glides in.
  struct FrameGlide
  {
    InputGlide glide;
    std::uint64_t pauses = 0;
  };
  /// The pose of a holder or collider following `frame` at the end of the step that ends at simulated
  /// time t [s]: tf's where it has transforms on both sides of t, else where `follower`'s glide has the
  /// newest transform gliding in since the step that first saw it (input_glide.h; ~max_input_interval).
  /// After a pause it starts afresh: the frame moved while the simulation stood, and it goes there at once.
  std::optional<RigidPose> followedPose(const std::string& frame, double t, FrameGlide& follower);
  /// framePose's position.
  std::optional<Vec3> frameOrigin(const std::string& frame, const ros::Time& stamp, std::string* why = nullptr);
  /// Makes anchor `anchor` follow tf frame `frame` every step.
  void followFrame(int anchor, const std::string& frame);
  /// The scene's robot_colliders: the URDF's collisions join scene_'s colliders (throws, saying why).
  void addRobotColliders();
  /// A collider with a tf frame follows it: its scene pose is relative to the frame.
  void followFrame(const ColliderPlacement& collider);
  /// The scene's cameras: their publishers and their static tf frames (<name>_link under the scene frame
  /// or their `frame`, <name>_color_optical_frame under it).
  void addCameras();
  /// Each camera with a frame due at the world's time and someone listening takes it, stamped with that instant.
  void shootCameras();
  bool onAttach(Attach::Request& request, Attach::Response& response);
  bool onDetach(Detach::Request& request, Detach::Response& response);
  bool onGrasp(Grasp::Request& request, Grasp::Response& response);
  bool onRelease(Detach::Request& request, Detach::Response& response);
  /// Publishes each holder's wrench on ~<body>/<name>/wrench, advertising new holders' topics and
  /// dropping those of holders gone.
  void publishWrenches(const std::vector<Holder>& holders, const ros::Time& stamp);
  /// Publishes each named collider's wrench (World::colliderWrenches) on ~colliders/<name>/wrench.
  void publishColliderWrenches(const ros::Time& stamp);

  // --- tuning and health (sim_node_tuning.cpp)
  void startReconfigure();
  /// Applies `config` to the world; an empty string, or why it cannot.
  std::string applySimConfig(const SimConfig& config);
  /// Warns when stepping at `settings` cannot keep real time on this scene, by the measured step cost
  /// scaled to the new sub-steps and iterations (before the change: the cost measured is the old one).
  void warnIfSlowerThanRealTime(const StepSettings& settings) const;
  std::string applyBodyConfig(const std::string& body, const BodyConfig& config);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);
  /// Notes where every node held by an anchor or grasp is as a tick begins (HeldNode).
  void noteHeldNodes();
  /// "anchor 'end' moved its node 1e+03 m ..." if an anchor or grasp of body `body` carried a node
  /// further in the last tick than the body's free nodes span: an input jump. Empty otherwise.
  std::string inputJump(std::size_t body) const;
  /// Logs the divergence guard's catches of the last tick, naming an input jump where there was one,
  /// and measures the largest strain.
  void watchDivergence();
  /// Logs the grasps that slipped in the last tick and keeps them for the next state message.
  void watchGrasps();

  bool onReset(std_srvs::Empty::Request& request, std_srvs::Empty::Response& response);
  bool onPause(std_srvs::SetBool::Request& request, std_srvs::SetBool::Response& response);
  /// ~save_state: the world's snapshot (WorldSnapshot::toBytes) into request.path, written whole or not at all.
  bool onSaveState(StateFile::Request& request, StateFile::Response& response);
  /// ~load_state: the world back to the moment of request.path, a ~save_state file of this scene; simulated
  /// time goes on from that moment, ROS time from now. The live tuning becomes the moment's.
  bool onLoadState(StateFile::Request& request, StateFile::Response& response);

  ros::NodeHandle nh_;
  ros::NodeHandle private_nh_;
  std::string name_;
  std::string scene_path_;
  SceneDef scene_;  ///< as loaded: its frame and rate, and what ~reset rebuilds; the World answers the rest
  std::unique_ptr<World> world_;
  double rate_ = 60.0;          ///< [Hz] of the timer
  double status_period_ = 0.0;  ///< [s] between status lines on the console; 0 = none
  double state_period_ = 0.0;   ///< 1 / ~state_rate [s] between ~state messages; 0 = every tick
  double next_state_time_ = 0.0;  ///< [s] of simulated time: ~state goes out at the first tick from it on
  long max_steps_per_tick_ = 1;  ///< catch-up cap: two ticks' worth of steps
  double tick_budget_ = 0.0;     ///< ~tick_budget [s]: wall time after which a tick begins no further step
  double workspace_radius_ = 1.0e4;  ///< ~workspace_radius [m]: inputs further from the scene origin are dropped

  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  ros::Publisher markers_publisher_;
  ros::Publisher force_markers_publisher_;
  ros::Publisher state_publisher_;
  ros::Publisher start_time_publisher_;
  std::vector<ros::Subscriber> subscribers_;
  ros::ServiceServer reset_service_;
  ros::ServiceServer pause_service_;
  ros::ServiceServer attach_service_;
  ros::ServiceServer detach_service_;
  ros::ServiceServer grasp_service_;
  ros::ServiceServer release_service_;
  ros::ServiceServer save_state_service_;
  ros::ServiceServer load_state_service_;
  std::map<std::string, ros::Publisher> wrench_publishers_;  ///< by topic, per anchor and grasp
  std::map<std::string, ros::Publisher> collider_wrench_publishers_;  ///< by collider name
  ros::Timer timer_;
  std::unique_ptr<AnchorHandles> handles_;
  std::unique_ptr<ReconfigureServer<SimConfig>> sim_reconfigure_;
  /// (body name, its server) per tunable body
  std::vector<std::pair<std::string, std::unique_ptr<ReconfigureServer<BodyConfig>>>> body_reconfigure_;
  std::unique_ptr<diagnostic_updater::Updater> diagnostics_;

  InputSchedule inputs_;
  /// ~max_input_interval [s]: the longest an anchor, a target or a holder on a late tf frame glides to an
  /// input (input_glide.h); 0: each input is reached in the step its stamp falls in
  double max_input_interval_ = 0.5;
  std::map<int, InputGlide> glides_;  ///< per anchor index, once it has had an input
  std::map<std::string, InputGlide> target_glides_;  ///< per body, once it has had a target
  std::uint64_t pauses_ = 0;  ///< ticks spent paused since the start: a frame's glide restarts after one
  std::vector<std::unique_ptr<CameraPublisher>> cameras_;  ///< the scene's cameras; none: nothing made
  std::unique_ptr<tf2_ros::StaticTransformBroadcaster> camera_frames_;  ///< their links and optical frames
  std::vector<std::string> handle_names_;  ///< per scene anchor: its handle ("" = follows a frame)
  std::vector<std::pair<std::string, std::string>> target_handles_;  ///< (body, handle) per target
  std::map<std::string, Vec3> targets_;  ///< last target set per body [m]

  bool started_ = false;
  std::optional<ros::Time> start_time_;  ///< ~start_time: the ROS time of simulated time 0, if given
  ros::Time last_tick_;
  /// The ROS time of simulated time 0: the first tick (to the millisecond) or ~start_time, moved on by
  /// pauses, dropped catch-up and resets, so that epoch_ + world time stamps each output.
  ros::Time epoch_;
  ros::Time published_epoch_;
  ros::Time last_status_;
  double window_elapsed_ = 0.0;    ///< [s] of ROS time in the current real-time-factor window
  double window_simulated_ = 0.0;  ///< [s] simulated in it
  bool paused_ = false;
  StepStatistics statistics_;
  double max_strain_ = 0.0;       ///< [-] largest |l - L| / L of a spring or constraint, last tick
  std::vector<GraspSlip> slips_;  ///< grasps that slipped since the last state message
  /// A node held by an anchor or a grasp, where it was as the tick began.
  struct HeldNode
  {
    std::string holder;  ///< "anchor 'end'" or "grasp 'hand'"
    int node;            ///< global node index
    Vec3 start;          ///< [m]
  };
  std::vector<HeldNode> held_;  ///< as the current tick began
  std::set<std::string> slash_warned_;  ///< sources warned about a frame name's leading slash (tfFrame)
  double force_scale_ = RosConverter::kForceScale;  ///< ~force_scale [m/N]: the arrows on ~force_markers
};

}  // namespace soft_body_sim
