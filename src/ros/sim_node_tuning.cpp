// SimNode's live tuning (dynamic_reconfigure: ~ for the physics, ~<body> for each body's material) and
// its health on /diagnostics.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include <ros/names.h>

#include "soft_body_sim/core/elements/forces.h"
#include "soft_body_sim/ros/sim_node.h"

namespace soft_body_sim
{
namespace
{
/// Below this real-time factor the node is reported as falling behind.
constexpr double kSlowRealTimeFactor = 0.9;
}  // namespace

void SimNode::startReconfigure()
{
  sim_reconfigure_ = std::make_unique<ReconfigureServer<SimConfig>>(
      private_nh_, RosConverter::toSimConfig(*world_), [this](const SimConfig& config) { return applySimConfig(config); });
  for (std::size_t b = 0; b < world_->model().bodies.size(); ++b)
  {
    if (!world_->hasMaterial(b))
      continue;  // nothing to tune (a humanoid: kinematic nodes only)
    const std::string name = world_->model().bodies[b].name;
    std::string error;
    if (!ros::names::validate(name, error))
    {
      ROS_WARN("%s: body '%s' cannot be tuned live: its name is no valid ROS name (%s)", name_.c_str(),
               name.c_str(), error.c_str());
      continue;
    }
    body_reconfigure_.emplace_back(name, std::make_unique<ReconfigureServer<BodyConfig>>(
        ros::NodeHandle(private_nh_, name), BodyConfig::__getDefault__(),
        [this, name](const BodyConfig& config) { return applyBodyConfig(name, config); }));
  }
}

std::string SimNode::applySimConfig(const SimConfig& config)
{
  IntegratorType integrator;
  std::string why;
  if (!RosConverter::integratorOf(config, integrator, why))
    return why;
  const Vec3 gravity = RosConverter::gravityOf(config);
  const StepSettings settings = RosConverter::stepSettingsOf(config);
  // The scene's rule against passing through, at the new step and gravity.
  SceneDef tuned = scene_;
  tuned.physics.gravity = gravity;
  if (const std::optional<TunnellingRisk> risk = tunnellingRisk(tuned, settings))
    return risk->why;
  // Only what changed is set: a new integrator object (or a new dt) restarts multistep histories.
  if (integrator != world_->integrator())
  {
    try
    {
      world_->setIntegrator(integrator);
    }
    catch (const std::invalid_argument& e)
    {
      return e.what();
    }
  }
  if (settings.dt != world_->settings().dt || settings.substeps != world_->settings().substeps ||
      settings.iterations != world_->settings().iterations)
  {
    if (integrator == world_->integrator())
      warnIfSlowerThanRealTime(settings);
    world_->setStepSettings(settings);
    max_steps_per_tick_ = std::max(1L, std::lround(std::ceil(2.0 / (rate_ * settings.dt))));
  }
  if (gravity != world_->model().gravity)
    world_->setGravity(gravity);
  if (config.drag != world_->model().drag)
    world_->setDrag(config.drag);
  ROS_INFO("%s: physics now %s, dt = %g s, %d substeps, %d iterations, gravity (%g, %g, %g) m/s^2, drag %g 1/s",
           name_.c_str(), config.integrator.c_str(), config.dt, config.substeps, config.iterations, gravity.x(),
           gravity.y(), gravity.z(), config.drag);
  return "";
}

void SimNode::warnIfSlowerThanRealTime(const StepSettings& settings) const
{
  const StepSettings& now = world_->settings();
  const double cost = statistics_.wall_seconds_per_step;  // [s] measured at `now`'s settings
  if (!(cost > 0.0))
    return;  // nothing measured yet
  // A lower bound on the new step's cost: every stage runs once per sub-step, so the cost grows at least
  // with the sub-steps; only some stages repeat per iteration (constraint sweeps, Newton solves), so more
  // iterations cost more by at most their ratio, and fewer save at most that much. Warned only when even
  // this bound cannot keep real time: the warning is then certain, whatever the integrator spends where.
  const double iterations = static_cast<double>(settings.iterations) / now.iterations;
  const double estimate = cost * settings.substeps / now.substeps * std::min(1.0, iterations);
  const double factor = settings.dt / estimate;  // simulated seconds per wall second, at most
  if (factor >= 1.0)
    return;
  ROS_WARN("%s: dt = %g s with %d substeps and %d iterations cannot keep real time on this scene: a step "
           "costs at least %.3g s (measured %.3g s at dt = %g s, %d substeps, %d iterations), a real-time factor of "
           "at most %.3g; each tick stops stepping after ~tick_budget = %g s and %s",
           name_.c_str(), settings.dt, settings.substeps, settings.iterations, estimate, cost, now.dt, now.substeps,
           now.iterations, factor, tick_budget_,
           ros::Time::isSimTime() ? "the other steps follow later, behind /clock"
                                  : "beyond two ticks' worth behind, simulated time is dropped");
}

std::string SimNode::applyBodyConfig(const std::string& body, const BodyConfig& config)
{
  const BodyScaling scaling = RosConverter::toBodyScaling(config);
  try
  {
    if (!world_->setBodyScaling(body, scaling))
      return "no body '" + body + "'";
  }
  catch (const std::invalid_argument& e)
  {
    return e.what();
  }
  return "";
}

void SimNode::noteHeldNodes()
{
  held_.clear();
  const NodeArray& position = world_->state().position;
  for (const Anchor& anchor : world_->model().anchors)
    held_.push_back({ "anchor '" + anchor.name + "'", anchor.node, position.col(anchor.node) });
  for (const GraspedNodes& grasp : world_->grasps())
    for (const int node : grasp.nodes)
      held_.push_back({ "grasp '" + grasp.name + "'", node, position.col(node) });
}

std::string SimNode::inputJump(std::size_t body) const
{
  const Model& model = world_->model();
  const NodeArray& position = world_->state().position;
  const HeldNode* largest = nullptr;
  double jump = 0.0;
  for (const HeldNode& held : held_)
  {
    const double moved = (position.col(held.node) - held.start).norm();
    if (model.bodyOf(held.node) == body && moved > jump)
    {
      jump = moved;
      largest = &held;
    }
  }
  if (!largest)
    return std::string();
  // The body's size: the box around its other nodes, which the guard has just put back where they were
  // good. A hand carries a body less than its own size in one tick (1/60 s: 60 sizes per second); a pose
  // that leaps further is a jump in the input, and it is what drags the body's springs past what any step
  // resolves.
  const BodyRange& range = model.bodies[body];
  Eigen::AlignedBox3d box;
  for (int node = range.first; node < range.first + range.count; ++node)
    if (std::none_of(held_.begin(), held_.end(), [node](const HeldNode& held) { return held.node == node; }))
      box.extend(position.col(node));
  const double size = box.isEmpty() ? 0.0 : box.diagonal().norm();
  if (jump <= size)
    return std::string();
  char text[160];
  std::snprintf(text, sizeof text, " moved its node %g m in this tick, more than the body's size (%g m)", jump, size);
  return largest->holder + text;
}

void SimNode::watchDivergence()
{
  max_strain_ = maxStrain(world_->model(), world_->state());
  // Each catch once, as it happens: a body is caught at most eleven times (ten halvings, then frozen).
  for (const DivergenceEvent& event : world_->takeDivergenceEvents())
  {
    ++statistics_.divergence_events;
    const std::vector<BodyRange>& bodies = world_->model().bodies;
    const auto body = std::find_if(bodies.begin(), bodies.end(), [&](const BodyRange& b) { return b.name == event.body; });
    const std::string jump =
        body == bodies.end() ? std::string() : inputJump(static_cast<std::size_t>(body - bodies.begin()));
    if (!jump.empty())
      ROS_ERROR("%s: %s; likely cause: an input jump (%s): move it in smaller steps, then call ~reset", name_.c_str(),
                event.describe().c_str(), jump.c_str());
    else
      ROS_ERROR("%s: %s; lower dt or stiffness, or pick a stable integrator, then call ~reset", name_.c_str(),
                event.describe().c_str());
  }
}

void SimNode::watchGrasps()
{
  for (GraspSlip& slip : world_->takeGraspSlips())
  {
    ROS_WARN("%s: %s; its nodes are free again", name_.c_str(), slip.describe().c_str());
    slips_.push_back(std::move(slip));
  }
}

void SimNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status)
{
  std::string frozen;
  for (std::size_t b = 0; b < world_->model().bodies.size(); ++b)
    if (world_->isFrozen(b))
      frozen += (frozen.empty() ? "" : ", ") + world_->model().bodies[b].name;
  if (!frozen.empty())
    status.summary(diagnostic_msgs::DiagnosticStatus::ERROR, "diverged and frozen: " + frozen + " (~reset after retuning)");
  else if (world_->divergenceCount() > 0)
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "diverged and recovered: see the log");
  else if (paused_)
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "paused");
  else if (started_ && statistics_.real_time_factor > 0.0 && statistics_.real_time_factor < kSlowRealTimeFactor)
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "falling behind real time");
  else
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "running");
  status.add("simulated time [s]", world_->time());
  status.add("real-time factor", statistics_.real_time_factor);
  status.add("step cost [s]", statistics_.wall_seconds_per_step);
  status.add("max strain", max_strain_);
  status.add("divergence events", statistics_.divergence_events);
  status.add("integrator", integratorName(world_->integrator()));
  status.add("dt [s]", world_->settings().dt);
  status.add("nodes", world_->model().nodeCount());
  for (const std::unique_ptr<CameraPublisher>& camera : cameras_)
    status.add("camera " + camera->def().name + ": frames dropped", camera->dropped());
}

}  // namespace soft_body_sim
