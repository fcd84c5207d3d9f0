// Contact with the scene's planes (walls and floors): the contact stage's first kind of collider.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "core/contact/contact_response.h"
#include "soft_body_sim/core/contact/contact_stage.h"
#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
/// Pushes every free node that is behind a plane (closer than its contact radius) back onto it and, if
/// it was moving into the plane, takes away its normal velocity, applies Coulomb friction (leaveSurface,
/// contact_response.h) and, on a new impact, bounces it with the plane's restitution. A plane is a
/// half-space, so a fast node cannot tunnel through it.
/// An impact is new when the node did not touch any plane in the previous sub-step (`touching`, one
/// flag per node, updated here) and approaches faster than `resting_speed` [m/s] (restingSpeed,
/// contact_response.h): a node resting on a floor, alone or under the weight of others, gains approach
/// speed every step and must not jitter.
/// Each plane receives the opposite of the momentum its contacts gave the nodes (their mass times their
/// velocity change) in `received` (one per plane), at the contact point, with the moment about its `point`.
/// Returns true if any node was touched.
/// `planes` have unit normals; h [s] is the sub-step just taken, which started at `start` [m].
bool collideWithPlanes(const std::vector<Plane>& planes, const Model& model, const NodeArray& start, State& state,
                       double resting_speed, std::vector<std::uint8_t>& touching, double h,
                       std::vector<ReceivedImpulse>& received);

/// The scene's planes as a kind of collider of the contact stage.
class PlaneContacts final : public ColliderKind
{
public:
  std::unique_ptr<ColliderKind> clone() const override { return std::make_unique<PlaneContacts>(*this); }
  void carry(StateArchive& archive) override { archive(touching_, received_); }
  /// Keeps the planes with unit normals; throws std::invalid_argument on a zero normal.
  PlaneContacts(std::vector<Plane> planes, int nodes);

  bool resolve(const Model& model, const NodeArray& start, State& state, double h) override
  {
    return collideWithPlanes(planes_, model, start, state, restingSpeed(model.gravity, h), touching_, h, received_);
  }

  bool touching(const Model& model, int node, const Vec3& x, double margin, NodeContact& contact) const override
  {
    bool found = false;
    for (std::size_t k = 0; k < planes_.size(); ++k)
    {
      const Plane& plane = planes_[k];
      const double depth = model.contact_radius[node] - (x - plane.point).dot(plane.normal);
      if (depth > -margin && (!found || depth > contact.depth))
      {
        contact = NodeContact{ plane.normal, Vec3::Zero(), plane.friction, depth, static_cast<int>(k) };
        found = true;
      }
    }
    return found;
  }

  std::size_t count() const override { return planes_.size(); }

  void receive(std::size_t plane, const Vec3& point, const Vec3& impulse) override
  {
    received_[plane].add(point - planes_[plane].point, impulse);
  }

  void clearImpulses() override { std::fill(received_.begin(), received_.end(), ReceivedImpulse{}); }

  void appendWrenches(double dt, std::vector<ColliderWrench>& wrenches) const override
  {
    for (std::size_t k = 0; k < planes_.size(); ++k)
      if (!planes_[k].name.empty())
        wrenches.push_back({ planes_[k].name, received_[k].over(dt) });
  }

private:
  std::vector<Plane> planes_;
  std::vector<std::uint8_t> touching_;  ///< per node: on a plane after the last sub-step
  std::vector<ReceivedImpulse> received_;  ///< per plane: from the bodies since the step began
};

}  // namespace soft_body_sim
