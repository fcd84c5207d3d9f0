// Node parameters read with their type checked: roscpp's getParam takes "abc" for a double as unset
// (and the default silently applies) and rounds 2.5 for an int, so every parameter of the node is read
// here, raw (XmlRpc), and a value of the wrong type or out of range stops the node with one line naming it.
#pragma once

#include <cmath>
#include <functional>
#include <optional>
#include <string>

#include <ros/node_handle.h>

namespace soft_body_sim
{
/// Parameter `key` of `nh`: nullopt if it is not set, else its value if it has type T (an integer where a
/// double is asked for) and `valid` accepts it. Otherwise throws std::runtime_error
/// "<resolved key>: must be <requirement>, not <the value>". T is double, int or std::string.
template <typename T>
std::optional<T> readParam(const ros::NodeHandle& nh, const std::string& key, const std::string& requirement,
                           const std::function<bool(const T&)>& valid = nullptr);

/// readParam's common checks: a finite number > 0, a finite number >= 0.
inline bool finitePositive(const double& x) { return x > 0.0 && std::isfinite(x); }
inline bool finiteNonNegative(const double& x) { return x >= 0.0 && std::isfinite(x); }

}  // namespace soft_body_sim
