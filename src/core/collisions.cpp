#include "soft_body_sim/core/collisions.h"

namespace soft_body_sim
{
bool collideWithPlanes(const Model& model, State& state, double resting_speed)
{
  bool touched = false;
  for (const Plane& plane : model.planes)
  {
    for (int i = 0; i < model.nodeCount(); ++i)
    {
      if (!model.isFree(i))
        continue;
      const double depth = (state.position.col(i) - plane.point).dot(plane.normal);
      if (depth >= 0.0)
        continue;
      touched = true;
      state.position.col(i) -= depth * plane.normal;
      const Vec3 v = state.velocity.col(i);
      const double normal_speed = v.dot(plane.normal);
      if (normal_speed >= 0.0)
        continue;
      const double bounce_speed = -normal_speed > resting_speed ? -plane.restitution * normal_speed : 0.0;
      Vec3 tangential = v - normal_speed * plane.normal;
      const double tangential_speed = tangential.norm();
      const double friction_loss = plane.friction * (bounce_speed - normal_speed);
      if (tangential_speed > 0.0)
        tangential *= std::max(0.0, 1.0 - friction_loss / tangential_speed);
      state.velocity.col(i) = tangential + bounce_speed * plane.normal;
    }
  }
  return touched;
}

}  // namespace soft_body_sim
