#include "ros/node_parameters.h"

#include <sstream>
#include <stdexcept>

namespace soft_body_sim
{
namespace
{
/// A parameter's value for an error message: a string quoted, a bool as a bool (XmlRpc writes 1), each
/// cut to 64 characters.
std::string shown(XmlRpc::XmlRpcValue value)
{
  if (value.getType() == XmlRpc::XmlRpcValue::TypeBoolean)
    return static_cast<bool>(value) ? "true" : "false";
  if (value.getType() == XmlRpc::XmlRpcValue::TypeString)
    return "'" + static_cast<std::string>(value).substr(0, 64) + "'";
  std::ostringstream out;
  value.write(out);
  return out.str().substr(0, 64);
}

/// The value as a T, if it has that type.
template <typename T>
std::optional<T> as(XmlRpc::XmlRpcValue& value);

template <>
std::optional<double> as(XmlRpc::XmlRpcValue& value)
{
  if (value.getType() == XmlRpc::XmlRpcValue::TypeDouble)
    return static_cast<double>(value);
  if (value.getType() == XmlRpc::XmlRpcValue::TypeInt)
    return static_cast<double>(static_cast<int>(value));  // `rate: 60` is a rate
  return std::nullopt;
}

template <>
std::optional<int> as(XmlRpc::XmlRpcValue& value)
{
  if (value.getType() == XmlRpc::XmlRpcValue::TypeInt)
    return static_cast<int>(value);
  return std::nullopt;
}

template <>
std::optional<std::string> as(XmlRpc::XmlRpcValue& value)
{
  if (value.getType() == XmlRpc::XmlRpcValue::TypeString)
    return static_cast<std::string>(value);
  return std::nullopt;
}
}  // namespace

template <typename T>
std::optional<T> readParam(const ros::NodeHandle& nh, const std::string& key, const std::string& requirement,
                           const std::function<bool(const T&)>& valid)
{
  XmlRpc::XmlRpcValue raw;
  if (!nh.getParam(key, raw))
    return std::nullopt;
  const std::optional<T> value = as<T>(raw);
  if (!value || (valid && !valid(*value)))
    throw std::runtime_error(nh.resolveName(key) + ": must be " + requirement + ", not " + shown(raw));
  return value;
}

template std::optional<double> readParam(const ros::NodeHandle&, const std::string&, const std::string&,
                                         const std::function<bool(const double&)>&);
template std::optional<int> readParam(const ros::NodeHandle&, const std::string&, const std::string&,
                                      const std::function<bool(const int&)>&);
template std::optional<std::string> readParam(const ros::NodeHandle&, const std::string&, const std::string&,
                                              const std::function<bool(const std::string&)>&);

}  // namespace soft_body_sim
