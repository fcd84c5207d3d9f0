// SimNode's live tuning (dynamic_reconfigure: ~ for the physics, ~<body> for each body's material) and
// its health on /diagnostics.
#include <cmath>
#include <sstream>

#include <ros/names.h>

#include "soft_body_sim/core/forces.h"
#include "soft_body_sim/ros/sim_node.h"

namespace soft_body_sim
{
namespace
{
/// Below this real-time factor the node is reported as falling behind.
constexpr double kSlowRealTimeFactor = 0.9;
}  // namespace

SimConfig SimNode::simConfigFromWorld() const
{
  SimConfig config = SimConfig::__getDefault__();
  config.integrator = integratorName(world_->integrator());
  config.dt = world_->settings().dt;
  config.substeps = world_->settings().substeps;
  config.iterations = world_->settings().iterations;
  config.gravity_x = world_->model().gravity.x();
  config.gravity_y = world_->model().gravity.y();
  config.gravity_z = world_->model().gravity.z();
  config.drag = world_->model().drag;
  return config;
}

void SimNode::startReconfigure()
{
  sim_reconfigure_ = std::make_unique<ReconfigureServer<SimConfig>>(
      private_nh_, simConfigFromWorld(), [this](const SimConfig& config) { return applySimConfig(config); });
  for (const BodyDef& body : scene_.bodies)
  {
    if (body.springs.empty() && body.constraints.empty() && body.cells.empty())
      continue;  // nothing to tune (a humanoid: kinematic nodes only)
    std::string error;
    if (!ros::names::validate(body.name, error))
    {
      ROS_WARN("%s: body '%s' cannot be tuned live: its name is no valid ROS name (%s)", name_.c_str(),
               body.name.c_str(), error.c_str());
      continue;
    }
    const std::string name = body.name;
    body_reconfigure_.emplace_back(name, std::make_unique<ReconfigureServer<BodyConfig>>(
        ros::NodeHandle(private_nh_, name), BodyConfig::__getDefault__(),
        [this, name](const BodyConfig& config) { return applyBodyConfig(name, config); }));
  }
}

std::string SimNode::applySimConfig(const SimConfig& config)
{
  IntegratorType integrator;
  if (!integratorFromName(config.integrator, integrator))
  {
    std::ostringstream why;
    // Quoted back only as far as a name could be: the request may hold megabytes.
    const std::size_t shown = 32;
    why << "integrator '" << config.integrator.substr(0, shown) << (config.integrator.size() > shown ? "...'" : "'")
        << " is unknown; valid:";
    for (const std::string& name : integratorNames())
      why << " " << name;
    return why.str();
  }
  const Vec3 gravity(config.gravity_x, config.gravity_y, config.gravity_z);
  const StepSettings settings{ config.dt, config.substeps, config.iterations };
  // Only what changed is set: a new integrator object (or a new dt) restarts multistep histories.
  if (integrator != world_->integrator())
    world_->setIntegrator(integrator);
  if (settings.dt != world_->settings().dt || settings.substeps != world_->settings().substeps ||
      settings.iterations != world_->settings().iterations)
  {
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

std::string SimNode::applyBodyConfig(const std::string& body, const BodyConfig& config)
{
  const BodyScaling scaling{ config.stiffness_scale, config.damping_scale, config.pressure_scale };
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

void SimNode::watchDivergence()
{
  max_strain_ = maxStrain(world_->model(), world_->state());
  // Each catch once, as it happens: a body is caught at most eleven times (ten halvings, then frozen).
  for (const DivergenceEvent& event : world_->takeDivergenceEvents())
  {
    ++statistics_.divergence_events;
    ROS_ERROR("%s: %s; lower dt or stiffness, or pick a stable integrator, then call ~reset", name_.c_str(),
              event.describe().c_str());
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
}

}  // namespace soft_body_sim
