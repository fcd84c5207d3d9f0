// Work-precision benchmark: speed against error, every integrator on every reference problem, side by
// side with Bullet's soft bodies (see docs/RESULTS.md; `scripts/bench OUT` runs it and plots).
//   work_precision OUT [--quick] [--only NAME] [--demo SCENE] [--no-bullet]
// Writes into the folder OUT:
//   work_precision.csv  problem,integrator,n_nodes,dt,substeps,iterations,cpu_s_per_sim_s,error,error_kind,
//                       bending_kLST (one row per configuration and error kind; error inf = diverged, cost
//                       nan then; bending_kLST: Bullet's bending links' stiffness, empty where none)
//   best_cost.csv       the cheapest configuration per engine at each error level
//   ratios.csv          the hanging chain at 1 mm: this package's best against Bullet's best
//   demo.csv            the demo scene's physics cost
//   machine.txt         where it ran
// --only NAME makes and runs only the problems whose name contains NAME (e.g. rod_cantilever).
// and prints a short table. Cost = CPU seconds per simulated second, the median of 3 timed runs after
// an untimed warm-up run (which also measures the errors); 1 timed run when a run takes over 0.5 s.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <sys/stat.h>
#include <thread>
#include <vector>

#include "soft_body_sim/scene/scene_loader.h"
#include "wp_bullet.h"
#include "wp_engine.h"
#include "wp_problems.h"

namespace soft_body_sim::bench
{
namespace
{
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
/// A configuration whose run would take longer than this [s CPU] is skipped (keeps `scripts/bench`
/// within its time budget); the log says so.
constexpr double kMaxRunSeconds = 2.0;

struct Measurement
{
  Config config;
  bool diverged = false;
  bool skipped = false;
  double cost = kNaN;  ///< CPU s per simulated s
  std::vector<double> errors;
};

bool finiteAndBounded(const Eigen::Matrix3Xd& x) { return x.allFinite() && x.cwiseAbs().maxCoeff() < 1e3; }

double median(std::vector<double> values)
{
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

Measurement measure(const Problem& problem, const std::function<std::unique_ptr<Engine>()>& make, const Config& config)
{
  Measurement m;
  m.config = config;
  const long steps = std::lround(problem.duration / config.dt);
  long per_sample = 0;
  if (problem.sample_period > 0.0)
  {
    per_sample = std::lround(problem.sample_period / config.dt);
    if (per_sample < 1 || std::abs(per_sample * config.dt - problem.sample_period) > 1e-9 * problem.sample_period)
    {
      std::fprintf(stderr, "[work_precision]   dt %g does not divide the sample period: skipped\n", config.dt);
      m.skipped = true;
      return m;
    }
  }
  // Warm-up run: untimed, measures the errors, stops early on divergence or when it would take too long.
  std::unique_ptr<Engine> engine = make();
  std::unique_ptr<Meter> meter = problem.meter();
  const long check_every = per_sample > 0 ? per_sample : std::max(1L, std::min(1000L, steps / 100));
  const double start = cpuSeconds();
  for (long s = 1; s <= steps; ++s)
  {
    engine->step();
    if (per_sample > 0 && s % per_sample == 0)
      meter->sample(static_cast<int>(s / per_sample), *engine);
    if (s % check_every == 0)
    {
      if (!finiteAndBounded(engine->positions()))
      {
        m.diverged = true;
        m.errors.assign(problem.error_kinds.size(), kInf);
        return m;
      }
      const double elapsed = cpuSeconds() - start;
      if (elapsed > 0.05 && elapsed * static_cast<double>(steps) / static_cast<double>(s) > kMaxRunSeconds)
      {
        std::fprintf(stderr, "[work_precision]   %s dt %g x%d it %d: a run would take ~%.0f s: skipped\n",
                     config.integrator.c_str(), config.dt, config.substeps, config.iterations,
                     elapsed * static_cast<double>(steps) / static_cast<double>(s));
        m.skipped = true;
        return m;
      }
    }
  }
  const double warm_up = cpuSeconds() - start;
  m.errors = meter->finish(*engine);
  for (double& e : m.errors)
    if (!std::isfinite(e))
      m.diverged = true;
  if (!finiteAndBounded(engine->positions()) || m.diverged)
  {
    m.diverged = true;
    m.errors.assign(problem.error_kinds.size(), kInf);
    return m;
  }
  // Timed runs: stepping only.
  const int repeats = warm_up < 0.5 ? 3 : 1;
  std::vector<double> costs;
  for (int r = 0; r < repeats; ++r)
  {
    engine = make();
    const double t0 = cpuSeconds();
    for (long s = 0; s < steps; ++s)
      engine->step();
    costs.push_back((cpuSeconds() - t0) / problem.duration);
  }
  m.cost = median(costs);
  return m;
}

std::string formatDouble(double value)
{
  if (std::isnan(value))
    return "nan";
  if (std::isinf(value))
    return "inf";
  char text[40];
  std::snprintf(text, sizeof text, "%.6g", value);
  return text;
}

/// The value, or nothing where it is NaN (a setting the run does not have).
std::string optionalDouble(double value) { return std::isnan(value) ? std::string() : formatDouble(value); }

struct Row
{
  std::string problem;
  int n_nodes;
  Measurement m;
};

/// The cheapest measured configuration of `engine` whose error of `kind` is at most `level`.
const Row* cheapestAt(const std::vector<Row>& rows, const Problem& problem, std::size_t kind, const std::string& engine,
                      double level)
{
  const Row* best = nullptr;
  for (const Row& row : rows)
  {
    if (row.problem != problem.name || row.n_nodes != problem.n_nodes || row.m.config.integrator != engine ||
        row.m.diverged || row.m.skipped || !(row.m.errors[kind] <= level))
      continue;
    if (!best || row.m.cost < best->m.cost)
      best = &row;
  }
  return best;
}

/// Cost at exactly error `level`, interpolated in log-log between the two points of the engine's
/// Pareto front (cheapest for its error) that bracket it; NaN if none reaches it.
double interpolatedCostAt(const std::vector<Row>& rows, const Problem& problem, std::size_t kind,
                          const std::string& engine, double level)
{
  std::vector<std::pair<double, double>> points;  // (cost, error)
  for (const Row& row : rows)
    if (row.problem == problem.name && row.n_nodes == problem.n_nodes && row.m.config.integrator == engine &&
        !row.m.diverged && !row.m.skipped && row.m.errors[kind] > 0.0)
      points.emplace_back(row.m.cost, row.m.errors[kind]);
  std::sort(points.begin(), points.end());
  std::vector<std::pair<double, double>> front;  // cost rising, error falling
  for (const auto& point : points)
    if (front.empty() || point.second < front.back().second)
      front.push_back(point);
  for (std::size_t k = 0; k < front.size(); ++k)
  {
    if (front[k].second > level)
      continue;
    if (k == 0)
      return front[0].first;
    const double t = (std::log(level) - std::log(front[k - 1].second)) / (std::log(front[k].second) - std::log(front[k - 1].second));
    return std::exp(std::log(front[k - 1].first) + t * (std::log(front[k].first) - std::log(front[k - 1].first)));
  }
  return kNaN;
}

std::string machineDescription()
{
  std::string model = "unknown CPU";
  std::ifstream cpuinfo("/proc/cpuinfo");
  std::string line;
  while (std::getline(cpuinfo, line))
    if (line.rfind("model name", 0) == 0)
    {
      model = line.substr(line.find(':') + 2);
      break;
    }
  std::ostringstream out;
  out << model << ", " << std::thread::hardware_concurrency() << " cores; compiler " << __VERSION__
      << "; Eigen " << EIGEN_WORLD_VERSION << "." << EIGEN_MAJOR_VERSION << "." << EIGEN_MINOR_VERSION << "; "
      << bulletDescription();
  return out.str();
}

/// The demo scene's physics: CPU seconds per simulated second over `seconds`, after a 1 s warm-up.
void measureDemo(const std::string& path, const std::string& out_dir)
{
  const SceneDef scene = loadSceneFile(path);
  World world = buildWorld(scene);
  const double dt = world.settings().dt;
  for (long s = 0; s < std::lround(1.0 / dt); ++s)
    world.step();
  std::vector<double> costs;
  const double seconds = 10.0;
  for (int r = 0; r < 3; ++r)
  {
    const double t0 = cpuSeconds();
    for (long s = 0; s < std::lround(seconds / dt); ++s)
      world.step();
    costs.push_back((cpuSeconds() - t0) / seconds);
  }
  const double cost = median(costs);
  std::printf("\ndemo scene %s: %d nodes, %s dt %g x %d sub-steps: physics %.4f CPU s per simulated s = %.1f %% of one core\n",
              path.c_str(), world.model().nodeCount(), integratorName(world.integrator()).c_str(), dt,
              world.settings().substeps, cost, 100.0 * cost);
  std::ofstream csv(out_dir + "/demo.csv");
  csv << "scene,n_nodes,integrator,dt,substeps,iterations,cpu_s_per_sim_s\n"
      << path << "," << world.model().nodeCount() << "," << integratorName(world.integrator()) << "," << dt << ","
      << world.settings().substeps << "," << world.settings().iterations << "," << formatDouble(cost) << "\n";
}

int run(int argc, char** argv)
{
  std::string out_dir, demo;
  ProblemOptions options;
  bool use_bullet = true;
  for (int i = 1; i < argc; ++i)
  {
    const std::string arg = argv[i];
    if (arg == "--quick")
      options.quick = true;
    else if (arg == "--no-bullet")
      use_bullet = false;
    else if (arg == "--only" && i + 1 < argc)
      options.only = argv[++i];
    else if (arg == "--demo" && i + 1 < argc)
      demo = argv[++i];
    else if (!arg.empty() && arg[0] != '-' && out_dir.empty())
      out_dir = arg;
    else
    {
      std::fprintf(stderr, "usage: work_precision OUT [--quick] [--only NAME] [--demo SCENE] [--no-bullet]\n");
      return 2;
    }
  }
  if (out_dir.empty())
  {
    std::fprintf(stderr, "usage: work_precision OUT [--quick] [--only NAME] [--demo SCENE] [--no-bullet]\n");
    return 2;
  }
  mkdir(out_dir.c_str(), 0755);
  const double start = cpuSeconds();
  const std::string machine = machineDescription();
  std::printf("machine: %s\n", machine.c_str());
  std::ofstream(out_dir + "/machine.txt") << machine << "\n";
  if (!bulletAvailable() || !use_bullet)
    std::printf("Bullet peer skipped: %s\n", use_bullet ? bulletDescription().c_str() : "--no-bullet");

  std::vector<Problem> problems = makeProblems(options);
  std::ofstream csv(out_dir + "/work_precision.csv");
  csv << "problem,integrator,n_nodes,dt,substeps,iterations,cpu_s_per_sim_s,error,error_kind,bending_kLST\n";
  std::vector<Row> rows;
  for (const Problem& problem : problems)
  {
    std::fprintf(stderr, "[work_precision] %s, %d nodes: %zu configurations%s\n", problem.name.c_str(), problem.n_nodes,
                 problem.sweep.size(),
                 problem.bullet && use_bullet && bulletAvailable()
                     ? (" + " + std::to_string(problem.bullet_sweep.size()) + " for Bullet").c_str()
                     : "");
    std::vector<std::pair<Config, std::function<std::unique_ptr<Engine>()>>> runs;
    for (const Config& config : problem.sweep)
      runs.emplace_back(config, [&problem, config]() -> std::unique_ptr<Engine> {
        return std::make_unique<PackageEngine>(problem.scene(config));
      });
    if (problem.bullet && use_bullet && bulletAvailable())
      for (const Config& config : problem.bullet_sweep)
        runs.emplace_back(config, [&problem, config] { return makeBulletRope(*problem.bullet, config); });
    const double problem_start = cpuSeconds();
    for (const auto& [config, make] : runs)
    {
      Measurement m = measure(problem, make, config);
      if (m.skipped)
        continue;
      for (std::size_t k = 0; k < problem.error_kinds.size(); ++k)
        csv << problem.name << "," << config.integrator << "," << problem.n_nodes << "," << formatDouble(config.dt) << ","
            << config.substeps << "," << config.iterations << "," << formatDouble(m.cost) << ","
            << formatDouble(m.errors[k]) << "," << problem.error_kinds[k] << ","
            << optionalDouble(config.bending_stiffness) << "\n";
      csv.flush();
      rows.push_back({ problem.name, problem.n_nodes, m });
    }
    std::fprintf(stderr, "[work_precision] %s, %d nodes: %.0f s CPU\n", problem.name.c_str(), problem.n_nodes,
                 cpuSeconds() - problem_start);
  }

  // Best cost per engine at each error level, and the table.
  std::ofstream best(out_dir + "/best_cost.csv");
  best << "problem,n_nodes,error_kind,error_level,engine,cpu_s_per_sim_s,dt,substeps,iterations,error,bending_kLST\n";
  const std::vector<double> levels = { 1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6 };
  std::printf("\nBest cost [CPU s per simulated s] reaching each error level (- = none does)\n");
  for (const Problem& problem : problems)
  {
    // The engines that ran it (a rod runs under implicit_euler only).
    std::vector<std::string> engines;
    for (const std::string& engine : integratorNames())
      if (std::any_of(problem.sweep.begin(), problem.sweep.end(), [&](const Config& c) { return c.integrator == engine; }))
        engines.push_back(engine);
    if (problem.bullet && use_bullet && bulletAvailable())
      engines.push_back("bullet");
    for (std::size_t kind = 0; kind < problem.error_kinds.size(); ++kind)
    {
      std::printf("\n%s, %d nodes, %s:\n  %-20s", problem.name.c_str(), problem.n_nodes, problem.error_kinds[kind].c_str(), "");
      for (double level : levels)
        std::printf(" %10s", ("<=" + formatDouble(level)).c_str());
      std::printf("\n");
      for (const std::string& engine : engines)
      {
        std::printf("  %-20s", engine.c_str());
        for (double level : levels)
        {
          const Row* row = cheapestAt(rows, problem, kind, engine, level);
          std::printf(" %10s", row ? formatDouble(row->m.cost).c_str() : "-");
          if (row)
            best << problem.name << "," << problem.n_nodes << "," << problem.error_kinds[kind] << "," << level << ","
                 << engine << "," << formatDouble(row->m.cost) << "," << formatDouble(row->m.config.dt) << ","
                 << row->m.config.substeps << "," << row->m.config.iterations << "," << formatDouble(row->m.errors[kind])
                 << "," << optionalDouble(row->m.config.bending_stiffness) << "\n";
        }
        std::printf("\n");
      }
    }
  }

  // The target: the hanging chain at max node error <= 1 mm, this package's best against Bullet's.
  std::ofstream ratios(out_dir + "/ratios.csv");
  ratios << "problem,n_nodes,package_engine,package_dt,package_substeps,package_iterations,package_cost,"
            "bullet_dt,bullet_iterations,bullet_cost,ratio,package_cost_interpolated,bullet_cost_interpolated,"
            "ratio_interpolated\n";
  if (std::any_of(problems.begin(), problems.end(), [](const Problem& p) { return p.name.rfind("hanging_chain", 0) == 0; }))
    std::printf("\nHanging chain, max node error <= 1 mm: this package's best against Bullet's best\n");
  for (const Problem& problem : problems)
  {
    if (problem.name.rfind("hanging_chain", 0) != 0)
      continue;
    const Row* ours = nullptr;
    std::string ours_engine;
    double ours_interpolated = kNaN;
    for (const std::string& engine : integratorNames())
    {
      const Row* row = cheapestAt(rows, problem, 0, engine, 1e-3);
      if (row && (!ours || row->m.cost < ours->m.cost))
      {
        ours = row;
        ours_engine = engine;
      }
      const double interpolated = interpolatedCostAt(rows, problem, 0, engine, 1e-3);
      if (std::isnan(ours_interpolated) || interpolated < ours_interpolated)
        ours_interpolated = interpolated;
    }
    const Row* theirs = cheapestAt(rows, problem, 0, "bullet", 1e-3);
    const double theirs_interpolated = interpolatedCostAt(rows, problem, 0, "bullet", 1e-3);
    const double ratio = ours && theirs ? ours->m.cost / theirs->m.cost : kNaN;
    const double ratio_interpolated = ours_interpolated / theirs_interpolated;
    std::printf("  %-28s %3d nodes: ours %s (%s dt %g x%d it %d) vs Bullet %s (dt %g, piterations %d): ratio %s"
                " (interpolated to 1 mm: %s vs %s, ratio %s)\n",
                problem.name.c_str(), problem.n_nodes, ours ? formatDouble(ours->m.cost).c_str() : "-", ours_engine.c_str(),
                ours ? ours->m.config.dt : kNaN, ours ? ours->m.config.substeps : 0, ours ? ours->m.config.iterations : 0,
                theirs ? formatDouble(theirs->m.cost).c_str() : "-", theirs ? theirs->m.config.dt : kNaN,
                theirs ? theirs->m.config.iterations : 0, formatDouble(ratio).c_str(),
                formatDouble(ours_interpolated).c_str(), formatDouble(theirs_interpolated).c_str(),
                formatDouble(ratio_interpolated).c_str());
    ratios << problem.name << "," << problem.n_nodes << "," << ours_engine << ","
           << (ours ? formatDouble(ours->m.config.dt) : "nan") << "," << (ours ? ours->m.config.substeps : 0) << ","
           << (ours ? ours->m.config.iterations : 0) << "," << (ours ? formatDouble(ours->m.cost) : "nan") << ","
           << (theirs ? formatDouble(theirs->m.config.dt) : "nan") << "," << (theirs ? theirs->m.config.iterations : 0)
           << "," << (theirs ? formatDouble(theirs->m.cost) : "nan") << "," << formatDouble(ratio) << ","
           << formatDouble(ours_interpolated) << "," << formatDouble(theirs_interpolated) << ","
           << formatDouble(ratio_interpolated) << "\n";
  }
  if (!demo.empty())
    measureDemo(demo, out_dir);
  std::printf("\nwork_precision: %zu configurations in %.0f s CPU; results in %s\n", rows.size(), cpuSeconds() - start,
              out_dir.c_str());
  return 0;
}
}  // namespace
}  // namespace soft_body_sim::bench

int main(int argc, char** argv) { return soft_body_sim::bench::run(argc, argv); }
