// How bodies look: the default colours (model.h).
#include <cmath>

#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
Eigen::Vector3d defaultBodyColor(std::size_t body)
{
  // Hues 137.5 degrees apart (the golden angle) never repeat and keep neighbours' colours far apart;
  // lifted to 0.2 + 0.8 c so that no body is black.
  const double hue = std::fmod(static_cast<double>(body) * 137.508, 360.0) / 60.0;
  const double x = 1.0 - std::abs(std::fmod(hue, 2.0) - 1.0);
  const double rgb[6][3] = { { 1, x, 0 }, { x, 1, 0 }, { 0, 1, x }, { 0, x, 1 }, { x, 0, 1 }, { 1, 0, x } };
  const auto& c = rgb[static_cast<int>(hue) % 6];
  return Eigen::Vector3d(0.2 + 0.8 * c[0], 0.2 + 0.8 * c[1], 0.2 + 0.8 * c[2]);
}

}  // namespace soft_body_sim
