// The fixed-period clock of the procedurally animated bodies (private to the core library).
// The seeds update their little dynamics at a fixed rate ("a determinate timer" in
// fuzzy-physics-constraints.txt, one update per frame of 1/room_speed in verlet-bezier-limbs.txt), and
// their constants are per update. Running them from an accumulator at their own period keeps the motion
// independent of the physics dt; the nodes are drawn between two updates by linear interpolation.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "soft_body_sim/core/bodies/controller.h"
#include "soft_body_sim/core/model.h"

namespace soft_body_sim
{
class FixedPeriodClock
{
public:
  /// @param period the update period T [s], > 0
  /// @param max_periods_per_step at most this many periods of the body's time pass per call of advance()
  ///        (the limb seed's "min(delta / period, 4)" cap against long frames); infinity = no cap
  explicit FixedPeriodClock(double period,
                            double max_periods_per_step = std::numeric_limits<double>::infinity())
    : period_(period), max_periods_per_step_(max_periods_per_step)
  {
  }

  /// Advances the body's time by min(dt, max_periods_per_step T, kMaxUpdatesPerStep T) and returns how many update instants
  /// n T were passed (reached counts as passed).
  std::int64_t advance(double dt)
  {
    elapsed_periods_ += std::min({ dt / period_, max_periods_per_step_, static_cast<double>(kMaxUpdatesPerStep) });
    // The sum of many dt / T lands a few ulps short of an exact multiple of T: 1e-9 period of slack
    // (33 ps at T = 1/30 s) makes t = n T count as reached whatever dt it was summed from.
    const auto reached = static_cast<std::int64_t>(std::floor(elapsed_periods_ + 1e-9));
    const std::int64_t passed = reached - reached_;
    reached_ = reached;
    return passed;
  }

  /// Keeps a body's dynamics one update ahead of the world: the first call runs `update` once; then, for
  /// every update instant that dt passes, `keep` saves the points of that instant (where the line they
  /// are drawn on starts) and `update` computes the next update.
  template <typename Keep, typename Update>
  void run(double dt, Keep&& keep, Update&& update)
  {
    if (!started_)
    {
      update();
      started_ = true;
    }
    for (std::int64_t due = advance(dt); due > 0; --due)
    {
      keep();
      update();
    }
  }

  /// How far the body's time is into the current period, as a fraction in [0, 1).
  double phase() const { return std::clamp(elapsed_periods_ - static_cast<double>(reached_), 0.0, 1.0); }

  double period() const { return period_; }

  void carry(StateArchive& archive) { archive(elapsed_periods_, reached_, started_); }

private:
  double period_;
  double max_periods_per_step_;
  double elapsed_periods_ = 0.0;  ///< the body's time / T
  std::int64_t reached_ = 0;      ///< update instants n T passed so far
  bool started_ = false;          ///< run() has computed the first update
};

/// Draws node `node` on the straight line from `from` (its point at the update instant passed) to `to`
/// (at the next), at `phase` of the way, with the line's slope over `period` [s] as its velocity: at
/// t = n T it is exactly at update n, and attached springs feel a continuous motion.
inline void drawBetween(State& state, int node, const Vec3& from, const Vec3& to, double phase, double period)
{
  const Vec3 span = to - from;
  state.position.col(node) = from + phase * span;
  state.velocity.col(node) = span / period;
}

}  // namespace soft_body_sim
