// The work-precision benchmark's view of a simulation: something that advances by one step and shows
// its node positions, whichever engine runs it (this package's World, or Bullet's soft bodies).
#pragma once

#include <algorithm>
#include <ctime>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "soft_body_sim/core/scene_def.h"

namespace soft_body_sim::bench
{
/// CPU time [s] of the calling thread: what a step costs, whatever else the machine runs.
inline double cpuSeconds()
{
  timespec now{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}

/// How a run is stepped: an integrator of this package (or "bullet"), the step dt [s], sub-steps per
/// step and iterations (for Bullet: its position-solver iterations, piterations); for a Bullet rope with
/// bending links, their stiffness.
struct Config
{
  std::string integrator;
  double dt = 0.01;
  int substeps = 1;
  int iterations = 1;
  /// Bullet only: kLST in (0, 1] of the rope's bending links (BulletRope::bending_distance); NaN where
  /// the run has none.
  double bending_stiffness = std::numeric_limits<double>::quiet_NaN();
};

class Engine
{
public:
  virtual ~Engine() = default;
  /// Advances by one step dt.
  virtual void step() = 0;
  /// Node positions [m], one column per node, in the problem's node order.
  virtual const Eigen::Matrix3Xd& positions() = 0;
  /// Total energy [J] (kinetic + elastic + gravitational), NaN where the engine does not say.
  virtual double energy() { return std::numeric_limits<double>::quiet_NaN(); }
  /// Deepest any node has been behind a plane [m] so far, seen inside the step (before the contact
  /// pass pushes it out); 0 where not observed.
  virtual double penetration() { return 0.0; }
};

/// This package: World::step, exactly as a user runs it. Where the scene has planes, it also observes
/// the step between integration and contact (World::observeIntegration) for the penetration.
class PackageEngine final : public Engine
{
public:
  explicit PackageEngine(const SceneDef& scene) : world_(buildWorld(scene))
  {
    if (!world_.model().colliders.planes.empty())
      world_.observeIntegration([this](const Model& model, const State& state) {
        for (const Plane& plane : model.colliders.planes)
          for (Eigen::Index i = 0; i < state.position.cols(); ++i)
            penetration_ = std::max(penetration_, -(state.position.col(i) - plane.point).dot(plane.normal.normalized()));
      });
  }
  void step() override { world_.step(); }
  const Eigen::Matrix3Xd& positions() override { return world_.state().position; }
  double energy() override { return world_.energy(); }
  double penetration() override { return penetration_; }
  const World& world() const { return world_; }

private:
  World world_;
  double penetration_ = 0.0;
};

}  // namespace soft_body_sim::bench
