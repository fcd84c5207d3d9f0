// RosConverter: the dynamic_reconfigure configs (cfg/Sim.cfg, cfg/Body.cfg) to and from the world's settings.
#include "soft_body_sim/ros/ros_converter.h"

namespace soft_body_sim
{
SimConfig RosConverter::toSimConfig(const World& world)
{
  SimConfig config = SimConfig::__getDefault__();
  config.integrator = integratorName(world.integrator());
  config.dt = world.settings().dt;
  config.substeps = world.settings().substeps;
  config.iterations = world.settings().iterations;
  config.gravity_x = world.model().gravity.x();
  config.gravity_y = world.model().gravity.y();
  config.gravity_z = world.model().gravity.z();
  config.drag = world.model().drag;
  return config;
}

bool RosConverter::integratorOf(const SimConfig& config, IntegratorType& integrator, std::string& why)
{
  if (integratorFromName(config.integrator, integrator))
    return true;
  // Quoted back only as far as a name could be: the request may hold megabytes.
  const std::size_t shown = 32;
  why = "integrator '" + config.integrator.substr(0, shown) + (config.integrator.size() > shown ? "...'" : "'") +
        " is unknown; valid:";
  for (const std::string& name : integratorNames())
    why += " " + name;
  return false;
}

}  // namespace soft_body_sim
