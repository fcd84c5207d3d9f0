// Procedurally animated bodies (the creature, Bezier limbs): each runs its own small dynamics, as its
// seed describes, and drives its nodes kinematically. Its nodes are pinned in the Model, so no
// integrator moves them, while springs attached to them (tendrils) feel their motion.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "soft_body_sim/core/model.h"
#include "soft_body_sim/core/state_archive.h"

namespace soft_body_sim
{
/// Updates per physics step beyond which an animated body's own time falls behind instead. The scene
/// loader refuses a scene that asks for more when its dt is given; a `dt: auto` or live-tuned step may
/// still ask for more, and an animated body's clock caps it here.
constexpr int kMaxUpdatesPerStep = 100;

/// The most relaxation passes per update of a procedurally animated body. With the most updates per
/// physics step it multiplies the work of every step (the seeds make 1 to 4 updates of 1 to 8 passes), so
/// that a typo such as `iterations: 1000000` fails with a message rather than stalling the simulation.
constexpr int kMaxRelaxationPasses = 100;

class Controller
{
public:
  virtual ~Controller() = default;
  /// A copy in the same state (its clock, its own dynamics' history): stepped as the original is, it
  /// gives the same bits.
  virtual std::unique_ptr<Controller> clone() const = 0;
  /// Writes or reads what a clone copies but what the scene fixes (state_archive.h), into a controller
  /// made for the same body.
  virtual void carry(StateArchive& archive) = 0;
  /// Advances the procedural motion by dt [s] and writes the positions [m] and velocities [m/s] of its
  /// nodes into `state`; it may read any node (e.g. a root following a torso).
  virtual void step(double dt, State& state) = 0;
  /// True if the body moves toward a target (setTarget).
  virtual bool takesTarget() const { return false; }
  /// Sets the point [m] the body moves toward; returns false if this body takes no target.
  virtual bool setTarget(const Vec3& target)
  {
    (void)target;
    return false;
  }
  /// The point [m] the body moves toward now, if it takes a target.
  virtual std::optional<Vec3> target() const { return std::nullopt; }
  /// Polylines [m] to draw for this body beyond its nodes and springs (a limb's sampled Bezier curve).
  virtual std::vector<std::vector<Vec3>> curves(const State& state) const
  {
    (void)state;
    return {};
  }
};

/// Makes the controller of a body whose node 0 has the global index `first_node`.
using ControllerFactory = std::function<std::unique_ptr<Controller>(int first_node)>;

}  // namespace soft_body_sim
