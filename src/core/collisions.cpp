#include "soft_body_sim/core/collisions.h"

#include <stdexcept>
#include <utility>

namespace soft_body_sim
{
PlaneContacts::PlaneContacts(std::vector<Plane> planes, int nodes)
  : planes_(std::move(planes)), touching_(static_cast<std::size_t>(nodes), 0)
{
  for (Plane& plane : planes_)
  {
    if (!(plane.normal.norm() > 0.0))
      throw std::invalid_argument("plane normal must not be zero");
    plane.normal.normalize();
  }
}

bool collideWithPlanes(const std::vector<Plane>& planes, const Model& model, State& state, double resting_speed,
                       std::vector<std::uint8_t>& touching)
{
  touching.resize(static_cast<std::size_t>(model.nodeCount()), 0);
  bool touched_any = false;
  for (int i = 0; i < model.nodeCount(); ++i)
  {
    if (!model.isFree(i))
      continue;
    const bool was_touching = touching[static_cast<std::size_t>(i)] != 0;
    bool touched = false;
    for (const Plane& plane : planes)
    {
      const double depth = (state.position.col(i) - plane.point).dot(plane.normal);
      if (depth >= 0.0)
        continue;
      touched = true;
      state.position.col(i) -= depth * plane.normal;
      const Vec3 v = state.velocity.col(i);
      const double normal_speed = v.dot(plane.normal);
      if (normal_speed >= 0.0)
        continue;
      const bool impact = !was_touching && -normal_speed > resting_speed;
      const double bounce_speed = impact ? -plane.restitution * normal_speed : 0.0;
      Vec3 tangential = v - normal_speed * plane.normal;
      const double tangential_speed = tangential.norm();
      const double friction_loss = plane.friction * (bounce_speed - normal_speed);
      if (tangential_speed > 0.0)
        tangential *= std::max(0.0, 1.0 - friction_loss / tangential_speed);
      state.velocity.col(i) = tangential + bounce_speed * plane.normal;
    }
    touching[static_cast<std::size_t>(i)] = touched ? 1 : 0;
    touched_any = touched_any || touched;
  }
  return touched_any;
}

}  // namespace soft_body_sim
