// sim.rollouts: many futures of one world, each a sequence of goals for one holder, stepped on worker
// threads that each own a copy of the world (a sampling planner's inner loop: MPPI, CEM).
#pragma once

#include <cstddef>

#include "python/holder.h"
#include "soft_body_sim/core/world.h"

namespace soft_body_sim::python
{
/// The goals of a batch, row-major: goal t of rollout b is goals[(b * count + t) * width ...], `width` 3 (a
/// position [m]) or 7 (a position and an orientation x, y, z, w of any norm > 0), every number finite.
struct GoalBatch
{
  const double* goals = nullptr;
  std::size_t rollouts = 0;
  std::size_t count = 0;  ///< goals per rollout
  int width = 3;
};

/// Where a holder is sent for step `step` (1 to `steps`) of a goal: `step / steps` of the way from `from`
/// (the previous goal, or the holder's pose at the start) to `to`, the position by linear interpolation
/// (1 - f) from + f to, the orientation by normalized linear interpolation the shorter way (nlerp, written
/// out in scalars so that a caller can repeat it to the bit), so that the holder moves smoothly and is
/// exactly at `to` when the goal's steps end.
RigidPose between(const RigidPose& from, const RigidPose& to, int step, int steps);

/// Runs every rollout of `batch` from `world` as it is (which stays unchanged): before each of the
/// `steps_per_goal` steps of a goal, `holder` moves to `between` the previous goal and this one (for width
/// 3 the position only: an anchor is not turned, a grasp keeps the orientation it had at the start); after them every node's
/// position goes to out[((b * count + t) * nodes + i) * 3 + k]. `threads` (>= 1) workers each own a copy of
/// `world` and take the next rollout as they finish one, assigning `world` to their copy first: a rollout
/// never depends on the one before it on its worker, so the result is the same for any number of threads.
/// Rethrows the first exception a worker met, after every worker stopped.
void runRollouts(const World& world, const Holder& holder, const GoalBatch& batch, int steps_per_goal, int threads,
                 double* out);

}  // namespace soft_body_sim::python
