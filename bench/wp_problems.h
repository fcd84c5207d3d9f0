// The reference problems of the work-precision benchmark, each with its truth, its error measures and
// the configurations every integrator is swept over (see docs/RESULTS.md).
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "wp_engine.h"

namespace soft_body_sim::bench
{
/// Accumulates a run's errors against the problem's truth.
class Meter
{
public:
  virtual ~Meter() = default;
  /// Called at simulated time k * sample_period, k = 1, 2, ... (only if the problem samples).
  virtual void sample(int k, Engine& engine) = 0;
  /// The errors at the end of the run, one per Problem::error_kinds.
  virtual std::vector<double> finish(Engine& engine) = 0;
};

/// A chain of point masses for Bullet's peer run: CreateRope's straight rope of `nodes` nodes and
/// `length` [m] (so its links rest at length / (nodes - 1)), then moved to `start` at rest.
struct BulletRope
{
  int nodes = 0;
  double length = 1.0;           ///< [m]
  double node_mass = 0.0;        ///< [kg] of every free node
  std::vector<int> pinned;       ///< node indices with zero inverse mass
  Eigen::Matrix3Xd start;        ///< [m] initial positions
  double gravity = 9.81;         ///< [m/s^2] along -z
  double drag = 0.0;             ///< [1/s]: Bullet's kDP = 1 - exp(-drag dt) per step
  std::vector<double> masses;    ///< [kg] per node, if given: instead of node_mass
  /// 0: links between neighbours only. d >= 2: also generateBendingConstraints(d), links from each node
  /// to its d-th neighbours at their straight distance, of kLST Config::bending_stiffness.
  int bending_distance = 0;
};

struct Problem
{
  std::string name;           ///< the CSV's `problem`
  int n_nodes = 0;
  double duration = 1.0;      ///< [s] simulated per run
  double sample_period = 0;   ///< [s]; 0 = errors only at the end of the run
  std::vector<std::string> error_kinds;
  std::function<SceneDef(const Config&)> scene;
  std::function<std::unique_ptr<Meter>()> meter;
  std::vector<Config> sweep;             ///< this package's configurations
  std::optional<BulletRope> bullet;      ///< a Bullet counterpart, if any
  std::vector<Config> bullet_sweep;
  std::string truth;                     ///< what the errors are measured against, for the log
};

struct ProblemOptions
{
  bool quick = false;  ///< fewer configurations and shorter references (a smoke test)
  std::string only;    ///< if not empty: only the problems whose name contains it (their truths only)
};

/// Every reference problem, with its truth computed (reference runs included); logs to stderr.
std::vector<Problem> makeProblems(const ProblemOptions& options);

/// The demo scene's physics cost is measured separately (no truth): its SceneDef is loaded by the caller.

}  // namespace soft_body_sim::bench
