#include "wp_problems.h"

#include <cmath>
#include <cstdio>
#include <limits>

#include "catenary.h"  // test/catenary.h: the exact discrete catenary, shared with the tests
#include "elastica.h"  // test/elastica.h: the cantilever's elastica by shooting, shared with test_rod
#include "soft_body_sim/core/bodies/cloth.h"
#include "soft_body_sim/core/bodies/jelly.h"
#include "soft_body_sim/core/bodies/rod.h"
#include "soft_body_sim/core/elements/forces.h"

namespace soft_body_sim::bench
{
namespace
{
constexpr double kGravity = test::kGravity;  // [m/s^2] along -z, as the catenary assumes
constexpr double kInf = std::numeric_limits<double>::infinity();

IntegratorType typeOf(const std::string& name)
{
  IntegratorType type = IntegratorType::SemiImplicitEuler;
  integratorFromName(name, type);
  return type;
}

SceneDef sceneWith(const Config& config)
{
  SceneDef scene;
  scene.physics.integrator = typeOf(config.integrator);
  scene.physics.step.dt = config.dt;
  scene.physics.step.substeps = config.substeps;
  scene.physics.step.iterations = config.iterations;
  return scene;
}

/// dt0 / 2^k for k in [k_first, k_last].
std::vector<double> halvings(double dt0, int k_first, int k_last)
{
  std::vector<double> dts;
  for (int k = k_first; k <= k_last; ++k)
    dts.push_back(dt0 / std::pow(2.0, k));
  return dts;
}

const std::vector<std::string> kExplicitSchemes = { "explicit_euler", "semi_implicit_euler", "verlet",
                                                    "velocity_verlet", "rk4" };

/// The sweep of one problem: each explicit scheme over `explicit_dts` (with each of
/// `constraint_iterations` when the model has constraints), implicit_euler over `implicit_dts` with 1
/// and 2 Newton iterations, xpbd at dt = `xpbd_dt` with 1, 2, 4, ... `max_substeps` sub-steps of one
/// sweep, and with `xpbd_iterations` sweeps at every fourth of those.
struct SweepPlan
{
  std::vector<double> explicit_dts;
  std::vector<int> constraint_iterations = { 1 };
  std::vector<double> implicit_dts;
  double xpbd_dt = 0.01;
  int max_substeps = 64;
  std::vector<int> xpbd_iterations = { 4 };
};

std::vector<Config> sweepOf(const SweepPlan& plan)
{
  std::vector<Config> configs;
  for (const std::string& scheme : kExplicitSchemes)
    for (double dt : plan.explicit_dts)
      for (int iterations : plan.constraint_iterations)
        configs.push_back({ scheme, dt, 1, iterations });
  for (double dt : plan.implicit_dts)
    for (int iterations : { 1, 2 })
      configs.push_back({ "implicit_euler", dt, 1, iterations });
  for (int substeps = 1; substeps <= plan.max_substeps; substeps *= 2)
  {
    configs.push_back({ "xpbd", plan.xpbd_dt, substeps, 1 });
    if ((substeps == 1 || substeps % 4 == 0))
      for (int iterations : plan.xpbd_iterations)
        configs.push_back({ "xpbd", plan.xpbd_dt, substeps, iterations });
  }
  return configs;
}

/// Segment strains |x_{j+1} - x_j| / rest - 1 of a chain.
Eigen::VectorXd chainStrains(const Eigen::Matrix3Xd& x, double rest)
{
  Eigen::VectorXd strain(x.cols() - 1);
  for (Eigen::Index j = 0; j + 1 < x.cols(); ++j)
    strain[j] = (x.col(j + 1) - x.col(j)).norm() / rest - 1.0;
  return strain;
}

bool finiteAndBounded(const Eigen::Matrix3Xd& x) { return x.allFinite() && x.cwiseAbs().maxCoeff() < 1e3; }

// --- 1. harmonic oscillator ----------------------------------------------------------------------------
// Node 0 pinned at the origin, node 1 (1 kg) on a spring of k = 4 pi^2 N/m (period 1 s), rest 1 m,
// released 0.1 m stretched: x(t) = 0.1 cos(2 pi t). Error: |x(T) - x_exact(T)| after T = 10 s.
Problem oscillator(const ProblemOptions& options)
{
  Problem p;
  p.name = "harmonic_oscillator";
  p.n_nodes = 2;
  p.duration = 10.0;
  p.error_kinds = { "final_position" };
  p.truth = "analytic x(t) = 0.1 cos(2 pi t)";
  p.scene = [](const Config& config) {
    SceneDef scene = sceneWith(config);
    scene.physics.gravity = Vec3::Zero();
    BodyDef body;
    body.name = "oscillator";
    body.nodes = { NodeDef{ Vec3::Zero(), 1.0, Vec3::Zero(), true }, NodeDef{ Vec3(1.1, 0, 0), 1.0, Vec3::Zero(), false } };
    body.springs = { SpringDef{ 0, 1, 4.0 * M_PI * M_PI, 0.0, 1.0 } };
    scene.bodies.push_back(body);
    return scene;
  };
  struct OscillatorMeter : Meter
  {
    double duration;
    explicit OscillatorMeter(double d) : duration(d) {}
    void sample(int, Engine&) override {}
    std::vector<double> finish(Engine& engine) override
    {
      const Eigen::Matrix3Xd& x = engine.positions();
      if (!finiteAndBounded(x))
        return { kInf };
      const double exact = 0.1 * std::cos(2.0 * M_PI * duration);
      return { (Vec3(x.col(1)) - Vec3(1.0 + exact, 0, 0)).norm() };
    }
  };
  const double duration = p.duration;
  p.meter = [duration] { return std::make_unique<OscillatorMeter>(duration); };
  SweepPlan plan;
  plan.explicit_dts = halvings(0.1, 0, options.quick ? 6 : 12);
  plan.implicit_dts = halvings(0.1, 0, options.quick ? 6 : 12);
  plan.xpbd_dt = 0.1;
  plan.max_substeps = options.quick ? 64 : 4096;
  plan.xpbd_iterations = {};
  p.sweep = sweepOf(plan);
  return p;
}

// --- 2. hanging chain ----------------------------------------------------------------------------------
// 1 m, 0.1 kg (equal node masses 0.1 / N), pinned at both ends 0.8 m apart, released from a V of two
// straight arms at rest (0.3 m deep) and settled by air drag 8 1/s for `settle` seconds. Stiff: springs
// of extensional stiffness EA = k rest = 1e4 N (a thin cord; strain ~7e-5), no dashpot. Inextensible:
// distance constraints of compliance 0. Truth: the discrete catenary of the same chain (elastic with
// k, or with k = infinity), solved by bisection on the horizontal tension to machine precision.
// Errors: the largest node distance to it, and the largest |strain - strain of the truth|.
constexpr double kChainLength = 1.0, kChainMass = 0.1, kChainSpan = 0.8, kChainEA = 1e4, kChainDrag = 8.0;

Eigen::Matrix3Xd chainStart(int nodes)
{
  const double rest = kChainLength / (nodes - 1);
  const int middle = (nodes - 1) / 2;
  Eigen::Matrix3Xd x(3, nodes);
  for (int j = 0; j < nodes; ++j)
  {
    const double along = std::abs(j - middle) * rest;  // from the V's tip along one arm
    x.col(j) = Vec3(kChainSpan / 2 + (j < middle ? -1 : 1) * along * 0.8, 0.0, -0.3 + along * 0.6);
  }
  return x;
}

Problem hangingChain(int nodes, bool inextensible, const ProblemOptions& options)
{
  Problem p;
  p.name = inextensible ? "hanging_chain_inextensible" : "hanging_chain_stiff";
  p.n_nodes = nodes;
  p.duration = 3.0;
  p.error_kinds = { "max_node_distance", "max_strain" };
  const double rest = kChainLength / (nodes - 1);
  const double node_mass = kChainMass / nodes;
  const double stiffness = kChainEA / rest;
  const Eigen::Matrix3Xd start = chainStart(nodes);
  p.scene = [=](const Config& config) {
    SceneDef scene = sceneWith(config);
    scene.physics.gravity = Vec3(0, 0, -kGravity);
    scene.physics.drag = kChainDrag;
    BodyDef body;
    body.name = "chain";
    for (int j = 0; j < nodes; ++j)
      body.nodes.push_back(NodeDef{ start.col(j), node_mass, Vec3::Zero(), j == 0 || j == nodes - 1 });
    for (int j = 1; j < nodes; ++j)
      if (inextensible)
        body.constraints.push_back(ConstraintDef{ j - 1, j, 0.0, rest });
      else
        body.springs.push_back(SpringDef{ j - 1, j, stiffness, 0.0, rest });
    scene.bodies.push_back(body);
    return scene;
  };
  const Eigen::Matrix3Xd truth =
      test::discreteCatenary(nodes, node_mass, inextensible ? kInf : stiffness, rest, kChainSpan);
  const Eigen::VectorXd truth_strain = chainStrains(truth, rest);
  char text[200];
  std::snprintf(text, sizeof text, "discrete catenary (%s), sag %.6f m, end of span %.1e m", inextensible ? "k = inf" : "EA = 1e4 N",
                -truth.row(2).minCoeff(), std::abs(truth(0, nodes - 1) - kChainSpan));
  p.truth = text;
  struct ChainMeter : Meter
  {
    Eigen::Matrix3Xd truth;
    Eigen::VectorXd truth_strain;
    double rest;
    void sample(int, Engine&) override {}
    std::vector<double> finish(Engine& engine) override
    {
      const Eigen::Matrix3Xd& x = engine.positions();
      if (!finiteAndBounded(x))
        return { kInf, kInf };
      return { (x - truth).colwise().norm().maxCoeff(), (chainStrains(x, rest) - truth_strain).cwiseAbs().maxCoeff() };
    }
  };
  p.meter = [=] {
    auto meter = std::make_unique<ChainMeter>();
    meter->truth = truth;
    meter->truth_strain = truth_strain;
    meter->rest = rest;
    return meter;
  };
  SweepPlan plan;
  if (inextensible)
  {
    plan.explicit_dts = halvings(0.01, 0, options.quick ? 3 : 7);
    plan.constraint_iterations = { 1, 8 };
  }
  else
  {
    // The explicit schemes are stable below w_max dt ~ 2: dt < 6e-5 s (51 nodes), 1.6e-5 s (201).
    plan.explicit_dts = halvings(0.01, nodes > 100 ? 9 : 7, nodes > 100 ? 10 : 8);
  }
  // Backward Euler's rest state is exactly f(x) = 0 at any step, so its large steps are worth trying.
  plan.implicit_dts = halvings(0.16, 0, options.quick ? 3 : 7);
  plan.max_substeps = options.quick ? 16 : (nodes > 100 ? 256 : 128);
  plan.xpbd_iterations = { 4, 16 };
  p.sweep = sweepOf(plan);

  BulletRope rope;
  rope.nodes = nodes;
  rope.length = kChainLength;
  rope.node_mass = node_mass;
  rope.pinned = { 0, nodes - 1 };
  rope.start = start;
  rope.gravity = kGravity;
  rope.drag = kChainDrag;
  p.bullet = rope;
  for (double dt : halvings(0.01, 0, options.quick ? 3 : 8))
    for (int iterations : { 1, 2, 4, 16 })
      p.bullet_sweep.push_back({ "bullet", dt, 1, iterations });
  return p;
}

// --- 3. swinging rope ----------------------------------------------------------------------------------
// 1 m, 0.1 kg, 51 nodes, pinned at node 0, released horizontal at rest; no drag. Stiff: EA = 1e4 N
// with a light dashpot (0.01 N s/m); inextensible: distance constraints. Truth: a reference run of
// the same model at a tiny step (stiff: rk4 at dt = 0.01 / 4096 s; inextensible: xpbd, one sweep per
// sub-step of h = 0.01 / 4096 s), its own error estimated against half as many steps. Errors over
// the first second, sampled
// every 10 ms: the largest distance of the free end from the reference's, and the largest
// |strain - reference strain| of any segment.
constexpr double kSampleNodes = 51;

struct RopeTrack
{
  std::vector<Vec3> end;               ///< per sample: the free end [m]
  std::vector<Eigen::VectorXd> strain;  ///< per sample: segment strains
};

class TrackMeter : public Meter
{
public:
  TrackMeter(std::shared_ptr<const RopeTrack> reference, double rest) : reference_(std::move(reference)), rest_(rest) {}
  void sample(int k, Engine& engine) override
  {
    const Eigen::Matrix3Xd& x = engine.positions();
    if (!finiteAndBounded(x))
    {
      end_error_ = strain_error_ = kInf;
      return;
    }
    const Eigen::VectorXd strain = chainStrains(x, rest_);
    track_.end.push_back(x.col(x.cols() - 1));
    track_.strain.push_back(strain);
    if (reference_ && static_cast<std::size_t>(k) <= reference_->end.size())
    {
      const std::size_t r = static_cast<std::size_t>(k) - 1;
      end_error_ = std::max(end_error_, (Vec3(x.col(x.cols() - 1)) - reference_->end[r]).norm());
      strain_error_ = std::max(strain_error_, (strain - reference_->strain[r]).cwiseAbs().maxCoeff());
    }
  }
  std::vector<double> finish(Engine&) override { return { end_error_, strain_error_ }; }
  const RopeTrack& track() const { return track_; }

private:
  std::shared_ptr<const RopeTrack> reference_;
  double rest_;
  RopeTrack track_;
  double end_error_ = 0.0, strain_error_ = 0.0;
};

/// Runs `problem` with `config` by World, sampling every sample_period; returns what the meter saw.
template <typename MeterType>
void runReference(const Problem& problem, const Config& config, MeterType& meter)
{
  PackageEngine engine(problem.scene(config));
  const long steps = std::lround(problem.duration / config.dt);
  const long per_sample = std::lround(problem.sample_period / config.dt);
  for (long s = 1; s <= steps; ++s)
  {
    engine.step();
    if (s % per_sample == 0)
      meter.sample(static_cast<int>(s / per_sample), engine);
  }
}

Problem swingingRope(bool inextensible, const ProblemOptions& options)
{
  Problem p;
  const int nodes = static_cast<int>(kSampleNodes);
  p.name = inextensible ? "swinging_rope_inextensible" : "swinging_rope_stiff";
  p.n_nodes = nodes;
  p.duration = 1.0;
  p.sample_period = 0.01;
  p.error_kinds = { "end_point_distance", "max_strain" };
  const double rest = kChainLength / (nodes - 1);
  const double node_mass = kChainMass / nodes;
  const double stiffness = kChainEA / rest;
  Eigen::Matrix3Xd start(3, nodes);
  for (int j = 0; j < nodes; ++j)
    start.col(j) = Vec3(j * rest, 0.0, 0.0);
  p.scene = [=](const Config& config) {
    SceneDef scene = sceneWith(config);
    scene.physics.gravity = Vec3(0, 0, -kGravity);
    BodyDef body;
    body.name = "rope";
    for (int j = 0; j < nodes; ++j)
      body.nodes.push_back(NodeDef{ start.col(j), node_mass, Vec3::Zero(), j == 0 });
    for (int j = 1; j < nodes; ++j)
      if (inextensible)
        body.constraints.push_back(ConstraintDef{ j - 1, j, 0.0, rest });
      else
        body.springs.push_back(SpringDef{ j - 1, j, stiffness, 0.01, rest });
    scene.bodies.push_back(body);
    return scene;
  };

  // The reference and, at half its steps, an estimate of its own error.
  const int fine = options.quick ? 256 : 4096;
  Config reference = inextensible ? Config{ "xpbd", 0.01, fine / 8, 1 } : Config{ "rk4", 0.01 / fine, 1, 1 };
  Config coarser = reference;
  if (inextensible)
    coarser.substeps /= 2;
  else
    coarser.dt *= 2.0;
  if (inextensible)
    reference.dt = coarser.dt = 0.01 / 8;  // 8 steps per sample, fine / 8 sub-steps each: h = 0.01 / fine
  TrackMeter reference_meter(nullptr, rest), coarser_meter(nullptr, rest);
  const double t0 = cpuSeconds();
  runReference(p, reference, reference_meter);
  runReference(p, coarser, coarser_meter);
  auto track = std::make_shared<RopeTrack>(reference_meter.track());
  double self_end = 0.0, self_strain = 0.0;
  for (std::size_t k = 0; k < track->end.size() && k < coarser_meter.track().end.size(); ++k)
  {
    self_end = std::max(self_end, (coarser_meter.track().end[k] - track->end[k]).norm());
    self_strain = std::max(self_strain, (coarser_meter.track().strain[k] - track->strain[k]).cwiseAbs().maxCoeff());
  }
  char text[300];
  std::snprintf(text, sizeof text,
                "reference run %s dt %.3g s x %d sub-steps (h = %.3g s); against half its steps it differs by "
                "%.1e m (end point), %.1e (strain); %.1f s CPU",
                reference.integrator.c_str(), reference.dt, reference.substeps, reference.dt / reference.substeps,
                self_end, self_strain, cpuSeconds() - t0);
  p.truth = text;
  p.meter = [track, rest] { return std::make_unique<TrackMeter>(track, rest); };

  SweepPlan plan;
  if (inextensible)
  {
    plan.explicit_dts = halvings(0.01, 0, options.quick ? 3 : 8);
    plan.constraint_iterations = { 1, 8 };
  }
  else
  {
    plan.explicit_dts = halvings(0.01, 5, options.quick ? 7 : 10);
  }
  plan.implicit_dts = halvings(0.01, 0, options.quick ? 3 : 8);
  plan.max_substeps = options.quick ? 16 : 512;
  plan.xpbd_iterations = { 4 };
  p.sweep = sweepOf(plan);

  BulletRope rope;
  rope.nodes = nodes;
  rope.length = kChainLength;
  rope.node_mass = node_mass;
  rope.pinned = { 0 };
  rope.start = start;
  rope.gravity = kGravity;
  p.bullet = rope;
  for (double dt : halvings(0.01, 0, options.quick ? 3 : 8))
    for (int iterations : { 1, 4, 16, 64 })
      p.bullet_sweep.push_back({ "bullet", dt, 1, iterations });
  return p;
}

// --- 4. cloth ------------------------------------------------------------------------------------------
// 32 x 32 nodes, 1 m x 1 m, 0.3 kg, pinned at the two top corners, released flat and horizontal; the
// springs of config/scenes/cloth.yaml scaled to the finer grid (same k * rest): structural 2214 N/m,
// shear 443 N/m, bending 44 N/m; no dashpots and no drag, so the exact energy is constant. Errors over
// the first second, sampled every 10 ms: |max structural strain - the reference run's max| (rk4 at
// dt = 0.01 / 256 s), and the energy drift max |E(t) - E(0)| / (M g 1 m).
struct ClothTrack
{
  std::vector<double> max_strain;  ///< per sample
};

Problem cloth(const ProblemOptions& options)
{
  Problem p;
  const int n = 32;
  p.name = "cloth";
  p.n_nodes = n * n;
  p.duration = 1.0;
  p.sample_period = 0.01;
  p.error_kinds = { "max_strain", "energy_drift" };
  const double mass = 0.3;
  p.scene = [=](const Config& config) {
    SceneDef scene = sceneWith(config);
    scene.physics.gravity = Vec3(0, 0, -kGravity);
    ClothDef def;
    def.nx = def.ny = n;
    def.corners = GridCorners{ Vec3(0, 0, 1), Vec3(1, 0, 1), Vec3(0, 1, 1) };
    def.mass = mass;
    def.structural = SpringParameters{ 1000.0 * 31 / 14, 0.0 };
    def.shear = SpringParameters{ 200.0 * 31 / 14, 0.0 };
    def.bending = SpringParameters{ 20.0 * 31 / 14, 0.0 };
    def.pinned = { 0, n - 1 };
    scene.bodies.push_back(buildCloth("cloth", def));
    return scene;
  };
  // Structural springs are the first 2 n (n - 1) of the body's springs (see buildCloth).
  const std::size_t structural = static_cast<std::size_t>(2 * n * (n - 1));
  struct ClothMeter : Meter
  {
    std::shared_ptr<const ClothTrack> reference;
    std::size_t structural = 0;
    std::vector<Spring> springs;
    double energy_scale = 1.0;
    double initial_energy = std::numeric_limits<double>::quiet_NaN();
    double strain_error = 0.0, drift = 0.0, peak = 0.0;
    ClothTrack track;
    void sample(int k, Engine& engine) override
    {
      const Eigen::Matrix3Xd& x = engine.positions();
      if (!finiteAndBounded(x))
      {
        strain_error = drift = kInf;
        return;
      }
      double strain = 0.0;
      for (std::size_t s = 0; s < structural; ++s)
        strain = std::max(strain, std::abs((x.col(springs[s].a) - x.col(springs[s].b)).norm() / springs[s].rest_length - 1.0));
      track.max_strain.push_back(strain);
      peak = std::max(peak, strain);
      if (reference && static_cast<std::size_t>(k) <= reference->max_strain.size())
        strain_error = std::max(strain_error, std::abs(strain - reference->max_strain[static_cast<std::size_t>(k) - 1]));
      drift = std::max(drift, std::abs(engine.energy() - initial_energy) / energy_scale);
    }
    std::vector<double> finish(Engine&) override { return { strain_error, drift }; }
  };
  const Model model = buildWorld(p.scene(Config{ "rk4", 0.01, 1, 1 })).model();
  const double energy_scale = mass * kGravity * 1.0;
  auto make_meter = [model, structural, energy_scale](std::shared_ptr<const ClothTrack> reference) {
    auto meter = std::make_unique<ClothMeter>();
    meter->reference = std::move(reference);
    meter->structural = structural;
    meter->springs = model.springs;
    meter->energy_scale = energy_scale;
    return meter;
  };
  // E(0): flat and at rest, springs at rest.
  const double initial_energy = buildWorld(p.scene(Config{ "rk4", 0.01, 1, 1 })).energy();
  const double t0 = cpuSeconds();
  auto reference_meter = make_meter(nullptr);
  reference_meter->initial_energy = initial_energy;
  const Config reference{ "rk4", 0.01 / (options.quick ? 32 : 256), 1, 1 };
  runReference(p, reference, *reference_meter);
  auto track = std::make_shared<ClothTrack>(reference_meter->track);
  char text[300];
  std::snprintf(text, sizeof text,
                "reference run rk4 dt %.3g s: peak structural strain %.4f, its own energy drift %.1e; %.1f s CPU",
                reference.dt, reference_meter->peak, reference_meter->drift, cpuSeconds() - t0);
  p.truth = text;
  p.meter = [make_meter, track, initial_energy] {
    auto meter = make_meter(track);
    meter->initial_energy = initial_energy;
    return meter;
  };
  // omega_max ~ 8600 1/s: the explicit schemes need dt < ~2.3e-4 s.
  SweepPlan plan;
  plan.explicit_dts = halvings(0.01, 5, options.quick ? 7 : 9);
  plan.implicit_dts = halvings(0.01, 0, options.quick ? 2 : 5);
  plan.max_substeps = options.quick ? 8 : 64;
  plan.xpbd_iterations = { 4 };
  p.sweep = sweepOf(plan);
  return p;
}

// --- 5. jelly ------------------------------------------------------------------------------------------
// config/scenes/jelly.yaml: 6 x 6 gas cells, 0.4 m, 1 kg, dropped from 2 m (tilted 15 degrees) onto a
// floor (restitution 0, friction 0.5), drag 0.1 1/s; 1.5 s (it lands at ~0.6 s). Errors, sampled
// every 10 ms: the total cell area against a reference run (rk4 at dt = 0.01 / 1024 s),
// max |sum A - sum A_ref| / sum A0, and the penetration: the deepest a node gets behind the floor
// inside a sub-step, before the contact pass puts it back (after a step it is always 0).
struct AreaTrack
{
  std::vector<double> area;
};

Problem jelly(const ProblemOptions& options)
{
  Problem p;
  p.name = "jelly";
  p.n_nodes = 49;
  p.duration = 1.5;
  p.sample_period = 0.01;
  p.error_kinds = { "cell_area", "penetration" };
  p.scene = [](const Config& config) {
    SceneDef scene = sceneWith(config);
    scene.physics.gravity = Vec3(0, 0, -kGravity);
    scene.physics.drag = 0.1;
    scene.colliders.planes = { Plane{ Vec3::Zero(), Vec3::UnitZ(), 0.0, 0.5 } };
    JellyDef def;
    def.corners = GridCorners{ Vec3(-0.1414, 0.0, 2.4899), Vec3(0.2449, 0.0, 2.3864), Vec3(-0.2449, 0.0, 2.1035) };
    scene.bodies.push_back(buildJelly("jelly", def));
    return scene;
  };
  const Model model = buildWorld(p.scene(Config{ "rk4", 0.01, 1, 1 })).model();
  double rest_area = 0.0;
  for (const PressureCell& cell : model.cells)
    rest_area += cell.rest_area;
  struct JellyMeter : Meter
  {
    std::shared_ptr<const AreaTrack> reference;
    std::vector<PressureCell> cells;
    double rest_area = 1.0;
    double area_error = 0.0;
    AreaTrack track;
    void sample(int k, Engine& engine) override
    {
      const Eigen::Matrix3Xd& x = engine.positions();
      if (!finiteAndBounded(x))
      {
        area_error = kInf;
        return;
      }
      double area = 0.0;
      for (const PressureCell& cell : cells)
        area += cellArea(cell, x);
      track.area.push_back(area);
      if (reference && static_cast<std::size_t>(k) <= reference->area.size())
        area_error = std::max(area_error, std::abs(area - reference->area[static_cast<std::size_t>(k) - 1]) / rest_area);
    }
    std::vector<double> finish(Engine& engine) override { return { area_error, engine.penetration() }; }
  };
  auto make_meter = [model, rest_area](std::shared_ptr<const AreaTrack> reference) {
    auto meter = std::make_unique<JellyMeter>();
    meter->reference = std::move(reference);
    meter->cells = model.cells;
    meter->rest_area = rest_area;
    return meter;
  };
  const double t0 = cpuSeconds();
  const int fine = options.quick ? 128 : 1024;
  auto reference_meter = make_meter(nullptr), coarser_meter = make_meter(nullptr);
  runReference(p, Config{ "rk4", 0.01 / fine, 1, 1 }, *reference_meter);
  runReference(p, Config{ "rk4", 0.02 / fine, 1, 1 }, *coarser_meter);
  auto track = std::make_shared<AreaTrack>(reference_meter->track);
  double self_error = 0.0;
  for (std::size_t k = 0; k < track->area.size(); ++k)
    self_error = std::max(self_error, std::abs(coarser_meter->track.area[k] - track->area[k]) / rest_area);
  char text[300];
  std::snprintf(text, sizeof text,
                "reference run rk4 dt %.3g s; against half its steps it differs by %.1e (area); penetration observed "
                "inside World::step; %.1f s CPU",
                0.01 / fine, self_error, cpuSeconds() - t0);
  p.truth = text;
  p.meter = [make_meter, track] { return make_meter(track); };
  SweepPlan plan;
  plan.explicit_dts = halvings(0.01, 2, options.quick ? 4 : 7);
  plan.implicit_dts = halvings(0.01, 0, options.quick ? 2 : 5);
  plan.max_substeps = options.quick ? 8 : 64;
  plan.xpbd_iterations = { 4 };
  p.sweep = sweepOf(plan);
  return p;
}


// --- 6. rod cantilever ---------------------------------------------------------------------------------
// A rod (type: rod) 1 m long, radius 5 mm, E = 0.6 GPa, 1000 kg/m^3 (E I = 0.29 N m^2, 0.079 kg/m),
// clamped horizontal at node 0 (position and direction held), of 11, 21, 41 and 81 nodes; released
// straight at rest and settled for 5 s by air drag 10 1/s. Its first mode (1.08 Hz small, omega = 6.8
// 1/s) is then 0.73 of critically damped and decays like exp(-5 t): by 5 s the motion left is ~1e-11 of
// its 0.3 m amplitude, far below the shape's error, so what is measured is the rest shape. Truth: the
// elastica E I theta'' = -w (L - s) cos theta by shooting (test/elastica.h; the rod's stretching, strain
// ~2e-5, and shear, (r / L)^2 E / G ~ 1e-4 of the bending, are not in it). Error: the largest distance of
// a node from the elastica at the same arc length, at the end of the run.
// Bullet's counterpart is a rope whose node i is also linked to node i + 2 (generateBendingConstraints(2)),
// clamped by its first two nodes pinned. Such a link of rest length 2 l resists bending only through its
// length, which a turn phi at the middle node shortens by l phi^2 / 4: no force to first order in phi, so
// no material E I; it is swept over the links' kLST, its iterations and its step.
constexpr double kRodLength = 1.0, kRodRadius = 0.005, kRodYoungs = 6.0e8, kRodDensity = 1000.0, kRodDrag = 10.0,
                 kRodSettle = 5.0;

RodDef rodCantilever(int nodes)
{
  RodDef def;
  def.nodes = nodes;
  def.from = Vec3(0.0, 0.0, 1.0);
  def.to = Vec3(kRodLength, 0.0, 1.0);
  def.radius = kRodRadius;
  def.youngs_modulus = kRodYoungs;
  def.density = kRodDensity;
  def.clamped = { 0 };
  return def;
}

Problem rodCantileverProblem(int nodes, const ProblemOptions& options)
{
  Problem p;
  p.name = "rod_cantilever";
  p.n_nodes = nodes;
  p.duration = kRodSettle;
  p.error_kinds = { "max_node_distance" };
  const RodDef def = rodCantilever(nodes);
  const BodyDef body = buildRod("rod", def);
  p.scene = [body](const Config& config) {
    SceneDef scene = sceneWith(config);
    scene.physics.gravity = Vec3(0, 0, -kGravity);
    scene.physics.drag = kRodDrag;
    scene.bodies.push_back(body);
    return scene;
  };
  const double area = M_PI * kRodRadius * kRodRadius;
  const double bending_stiffness = kRodYoungs * 0.25 * M_PI * std::pow(kRodRadius, 4);
  std::vector<double> at;
  for (int i = 0; i < nodes; ++i)
    at.push_back(kRodLength * i / (nodes - 1));
  const std::vector<Eigen::Vector2d> shape = test::elastica(bending_stiffness, kRodDensity * area * kGravity, kRodLength, at);
  Eigen::Matrix3Xd truth(3, nodes);
  for (int i = 0; i < nodes; ++i)
    truth.col(i) = def.from + Vec3(shape[static_cast<std::size_t>(i)].x(), 0.0, shape[static_cast<std::size_t>(i)].y());
  char text[200];
  std::snprintf(text, sizeof text, "elastica by shooting (test/elastica.h): tip at x = %.4f m, %.4f m below the clamp",
                truth(0, nodes - 1), def.from.z() - truth(2, nodes - 1));
  p.truth = text;
  struct RodMeter : Meter
  {
    Eigen::Matrix3Xd truth;
    void sample(int, Engine&) override {}
    std::vector<double> finish(Engine& engine) override
    {
      const Eigen::Matrix3Xd& x = engine.positions();
      if (!finiteAndBounded(x))
        return { kInf };
      return { (x - truth).colwise().norm().maxCoeff() };
    }
  };
  p.meter = [truth] {
    auto meter = std::make_unique<RodMeter>();
    meter->truth = truth;
    return meter;
  };
  // A ROS node's steps, 1/240 to 1/30 s, and a few larger: backward Euler's rest state is the discrete
  // rod's equilibrium at any step. Rods run only under implicit_euler.
  std::vector<double> dts = { 1.0 / 240, 1.0 / 120, 1.0 / 60, 1.0 / 30 };
  if (!options.quick)
    for (double dt : { 1.0 / 15, 1.0 / 8, 1.0 / 4 })
      dts.push_back(dt);
  for (double dt : dts)
    for (int iterations : { 1, 2 })
      p.sweep.push_back({ "implicit_euler", dt, 1, iterations });

  BulletRope rope;
  rope.nodes = nodes;
  rope.length = kRodLength;
  for (const NodeDef& node : body.nodes)
    rope.masses.push_back(node.mass);
  rope.pinned = { 0, 1 };
  rope.start.resize(3, nodes);
  for (int i = 0; i < nodes; ++i)
    rope.start.col(i) = body.nodes[static_cast<std::size_t>(i)].position;
  rope.gravity = kGravity;
  rope.drag = kRodDrag;
  rope.bending_distance = 2;
  p.bullet = rope;
  // Its links stiffen the rope by iterating: the rope holds up more the more sweeps per step (and the
  // shorter the step), straight in the limit; its rest shape depends on piterations / dt^2 alone
  // (measured: 64 at 1/240 s, 256 at 1/120 s and 1024 at 1/60 s leave the same 0.52 m at 11 nodes). So
  // the sweep goes to thousands of iterations, where at 11 nodes it passes the elastica's tip (runs over
  // kMaxRunSeconds are skipped). A kLST below 0.3 (0.01, 0.1
  // measured) only softens the rope further: worse at every setting short of that.
  for (double dt : { 1.0 / 240, 1.0 / 120, 1.0 / 60, 1.0 / 30 })
    for (int iterations : options.quick ? std::vector<int>{ 1, 16, 256 } : std::vector<int>{ 1, 4, 16, 64, 256, 1024, 4096 })
      for (double stiffness : { 0.3, 1.0 })
        p.bullet_sweep.push_back({ "bullet", dt, 1, iterations, stiffness });
  return p;
}

}  // namespace

std::vector<Problem> makeProblems(const ProblemOptions& options)
{
  std::vector<Problem> problems;
  // Only the problems asked for are made: a truth can be a long reference run.
  auto add = [&problems, &options](const std::string& name, const std::function<Problem()>& make) {
    if (!options.only.empty() && name.find(options.only) == std::string::npos)
      return;
    Problem p = make();
    std::fprintf(stderr, "[work_precision] %s (%d nodes): truth = %s\n", p.name.c_str(), p.n_nodes, p.truth.c_str());
    problems.push_back(std::move(p));
  };
  add("harmonic_oscillator", [&] { return oscillator(options); });
  for (int nodes : { 51, 201 })
    for (bool inextensible : { false, true })
      add(inextensible ? "hanging_chain_inextensible" : "hanging_chain_stiff",
          [&] { return hangingChain(nodes, inextensible, options); });
  add("swinging_rope_stiff", [&] { return swingingRope(false, options); });
  add("swinging_rope_inextensible", [&] { return swingingRope(true, options); });
  add("cloth", [&] { return cloth(options); });
  add("jelly", [&] { return jelly(options); });
  for (int nodes : { 11, 21, 41, 81 })
    add("rod_cantilever", [&] { return rodCantileverProblem(nodes, options); });
  return problems;
}

}  // namespace soft_body_sim::bench
