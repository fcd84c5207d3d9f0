// A dynamic_reconfigure server that refuses what it cannot apply instead of clamping it.
//
// dynamic_reconfigure::Server clamps an out-of-range value to the nearest bound and calls back with
// that, so `dynparam set /soft_body_sim dt -1` would silently run at the smallest dt. This server speaks
// the same protocol (the ~set_parameters service, the latched ~parameter_descriptions and
// ~parameter_updates topics, the values mirrored on the parameter server), so dynparam and
// rqt_reconfigure work against it unchanged, but a request holding a value outside the .cfg's
// [min, max], or one the callback cannot apply, is refused whole: the node logs a warning naming the
// parameter, the value and the reason, and answers with the unchanged configuration.
#pragma once

#include <functional>
#include <map>
#include <sstream>
#include <string>

#include <dynamic_reconfigure/Config.h>
#include <dynamic_reconfigure/ConfigDescription.h>
#include <dynamic_reconfigure/Reconfigure.h>
#include <ros/ros.h>

namespace soft_body_sim
{
template <class ConfigType>
class ReconfigureServer
{
public:
  /// Applies a new configuration; returns an empty string on success or why it was not applied.
  using Apply = std::function<std::string(const ConfigType& config)>;

  /// @param nh the namespace of the services and topics (e.g. the node's ~ or ~<body>)
  /// @param initial the configuration in force (taken from the running simulation, not the .cfg's
  ///   defaults); published at once, without calling `apply`.
  ReconfigureServer(const ros::NodeHandle& nh, const ConfigType& initial, Apply apply)
    : nh_(nh), apply_(std::move(apply)), config_(initial)
  {
    const dynamic_reconfigure::ConfigDescription description = ConfigType::__getDescriptionMessage__();
    for (const auto& p : description.min.doubles)
      min_[p.name] = p.value;
    for (const auto& p : description.max.doubles)
      max_[p.name] = p.value;
    for (const auto& p : description.min.ints)
      min_[p.name] = p.value;
    for (const auto& p : description.max.ints)
      max_[p.name] = p.value;
    description_publisher_ = nh_.advertise<dynamic_reconfigure::ConfigDescription>("parameter_descriptions", 1, true);
    description_publisher_.publish(description);
    update_publisher_ = nh_.advertise<dynamic_reconfigure::Config>("parameter_updates", 1, true);
    publish();
    service_ = nh_.advertiseService("set_parameters", &ReconfigureServer::onSet, this);
  }

  const ConfigType& config() const { return config_; }

  /// Replaces the configuration shown to clients without applying it (the simulation changed it).
  void update(const ConfigType& config)
  {
    config_ = config;
    publish();
  }

private:
  bool onSet(dynamic_reconfigure::Reconfigure::Request& request, dynamic_reconfigure::Reconfigure::Response& response)
  {
    std::string why = outOfRange(request.config);
    ConfigType candidate = config_;
    if (why.empty())
    {
      candidate.__fromMessage__(request.config);
      why = apply_(candidate);
    }
    if (why.empty())
      update(candidate);
    else
      ROS_WARN("%s: reconfiguration refused: %s", nh_.getNamespace().c_str(), why.c_str());
    config_.__toMessage__(response.config);
    return true;
  }

  /// Why a requested number lies outside its [min, max], or empty.
  std::string outOfRange(const dynamic_reconfigure::Config& request) const
  {
    std::ostringstream why;
    const auto check = [&](const std::string& name, double value) {
      const auto min = min_.find(name), max = max_.find(name);
      if (why.str().empty() && min != min_.end() && max != max_.end() && !(value >= min->second && value <= max->second))
        why << name << " = " << value << " is out of range [" << min->second << ", " << max->second << "]";
    };
    for (const auto& p : request.doubles)
      check(p.name, p.value);
    for (const auto& p : request.ints)
      check(p.name, p.value);
    return why.str();
  }

  void publish()
  {
    config_.__toServer__(nh_);
    dynamic_reconfigure::Config message;
    config_.__toMessage__(message);
    update_publisher_.publish(message);
  }

  ros::NodeHandle nh_;
  Apply apply_;
  ConfigType config_;
  std::map<std::string, double> min_, max_;
  ros::Publisher description_publisher_;
  ros::Publisher update_publisher_;
  ros::ServiceServer service_;
};

}  // namespace soft_body_sim
