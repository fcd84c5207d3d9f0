// Numbers in messages. std::to_string(double) is printf's %f: a voxel size of 1e-7 reads "0.000000", a
// force of 1e300 three hundred digits, a NaN "-nan".
#pragma once

#include <cmath>
#include <cstdio>
#include <string>

namespace soft_body_sim
{
/// `value` as %g writes it (6 significant digits, an exponent when very small or large), a NaN as "nan".
inline std::string formatNumber(double value)
{
  if (std::isnan(value))
    return "nan";
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

}  // namespace soft_body_sim
