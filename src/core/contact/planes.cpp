#include "core/contact/planes.h"

#include <stdexcept>
#include <utility>

#include "core/contact/contact_response.h"

namespace soft_body_sim
{
PlaneContacts::PlaneContacts(std::vector<Plane> planes, int nodes)
  : planes_(std::move(planes)), touching_(static_cast<std::size_t>(nodes), 0), received_(planes_.size())
{
  for (Plane& plane : planes_)
  {
    if (!(plane.normal.norm() > 0.0))
      throw std::invalid_argument("plane normal must not be zero");
    plane.normal.normalize();
  }
}

bool collideWithPlanes(const std::vector<Plane>& planes, const Model& model, const NodeArray& start, State& state,
                       double resting_speed, std::vector<std::uint8_t>& touching, double h,
                       std::vector<ReceivedImpulse>& received)
{
  touching.resize(static_cast<std::size_t>(model.nodeCount()), 0);
  bool touched_any = false;
  for (int i = 0; i < model.nodeCount(); ++i)
  {
    if (!model.isFree(i))
      continue;
    const bool was_touching = touching[static_cast<std::size_t>(i)] != 0;
    bool touched = false;
    for (std::size_t k = 0; k < planes.size(); ++k)
    {
      const Plane& plane = planes[k];
      const double depth = model.contact_radius[i] - (state.position.col(i) - plane.point).dot(plane.normal);
      if (!(depth > 0.0))
        continue;
      touched = true;
      const Vec3 v0 = state.velocity.col(i);
      const bool impact = !was_touching && -v0.dot(plane.normal) > resting_speed;
      leaveSurface({ plane.normal, Vec3::Zero(), plane.friction, plane.restitution }, depth, impact, h,
                   state.position.col(i) - start.col(i), state.position.col(i), state.velocity.col(i));
      const Vec3 point = state.position.col(i) - model.contact_radius[i] * plane.normal;
      received[k].add(point - plane.point, model.mass[i] * (v0 - state.velocity.col(i)));
    }
    touching[static_cast<std::size_t>(i)] = touched ? 1 : 0;
    touched_any = touched_any || touched;
  }
  return touched_any;
}

}  // namespace soft_body_sim
