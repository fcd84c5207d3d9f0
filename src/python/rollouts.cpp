#include "python/rollouts.h"

#include <atomic>
#include <cmath>
#include <cstring>
#include <exception>
#include <mutex>
#include <optional>
#include <system_error>
#include <thread>
#include <vector>

namespace soft_body_sim::python
{
namespace
{
/// q / |q|, the sum of squares taken left to right.
Eigen::Quaterniond normalized(double x, double y, double z, double w)
{
  const double norm = std::sqrt(x * x + y * y + z * z + w * w);
  return Eigen::Quaterniond(w / norm, x / norm, y / norm, z / norm);
}

/// Goal t of rollout b: its position, and its orientation normalized (width 7) or `orientation`.
RigidPose goalPose(const GoalBatch& batch, std::size_t b, std::size_t t, const Eigen::Quaterniond& orientation)
{
  const double* goal = batch.goals + (b * batch.count + t) * static_cast<std::size_t>(batch.width);
  RigidPose pose{ Vec3(goal[0], goal[1], goal[2]), orientation };
  if (batch.width == 7)
    pose.orientation = normalized(goal[3], goal[4], goal[5], goal[6]);
  return pose;
}

}  // namespace

RigidPose between(const RigidPose& from, const RigidPose& to, int step, int steps)
{
  const double f = static_cast<double>(step) / static_cast<double>(steps);
  const double g = 1.0 - f;
  RigidPose pose;
  // (1 - f) a + f b rather than a + f (b - a): exactly b at f = 1.
  for (int k = 0; k < 3; ++k)
    pose.position[k] = g * from.position[k] + f * to.position[k];
  const Eigen::Quaterniond& a = from.orientation;
  const Eigen::Quaterniond& b = to.orientation;
  const double dot = a.x() * b.x() + a.y() * b.y() + a.z() * b.z() + a.w() * b.w();
  const double s = dot < 0.0 ? -f : f;  // q and -q are one orientation: take the nearer
  pose.orientation = normalized(g * a.x() + s * b.x(), g * a.y() + s * b.y(), g * a.z() + s * b.z(),
                                g * a.w() + s * b.w());
  return pose;
}

void runRollouts(const World& world, const Holder& holder, const GoalBatch& batch, int steps_per_goal, int threads,
                 double* out)
{
  const RigidPose start = holder.pose(world);
  const bool turn = batch.width == 7;
  const std::size_t frame = 3 * static_cast<std::size_t>(world.model().nodeCount());
  std::atomic<std::size_t> next{ 0 };
  std::atomic<bool> failed{ false };
  std::exception_ptr error;
  std::mutex error_mutex;
  const auto work = [&] {
    std::optional<World> copy;
    try
    {
      for (std::size_t b = next++; b < batch.rollouts && !failed; b = next++)
      {
        if (copy)
          *copy = world;  // into the last rollout's buffers
        else
          copy.emplace(world);
        RigidPose from = start;
        for (std::size_t t = 0; t < batch.count; ++t)
        {
          const RigidPose to = goalPose(batch, b, t, start.orientation);
          for (int step = 1; step <= steps_per_goal; ++step)
          {
            RigidPose pose = between(from, to, step, steps_per_goal);
            if (!turn)
              pose.orientation = start.orientation;
            holder.move(*copy, pose, turn);
            copy->step();
          }
          std::memcpy(out + (b * batch.count + t) * frame, copy->state().position.data(), frame * sizeof(double));
          from = to;
        }
      }
    }
    catch (...)
    {
      const std::lock_guard<std::mutex> lock(error_mutex);
      if (!error)
        error = std::current_exception();
      failed = true;
    }
  };
  std::vector<std::thread> workers;
  for (int k = 1; k < threads; ++k)
  {
    try
    {
      workers.emplace_back(work);
    }
    catch (const std::system_error&)
    {
      break;  // no thread to be had: fewer workers give the same result, later
    }
  }
  work();  // the calling thread is the first worker
  for (std::thread& worker : workers)
    worker.join();
  if (error)
    std::rethrow_exception(error);
}

}  // namespace soft_body_sim::python
