// Cost of one physics step (Google Benchmark). "Model only what a scene needs": a plain rope must cost
// the same inside the full engine (planes, pressure, anchors, controllers all compiled in but absent
// from the scene) as in a minimal loop that knows only springs and gravity. Compare, in one run,
//   BM_RopeStepEngine/semi_implicit_euler  against  BM_RopeStepMinimalLoop
// (same rope, same scheme, same arithmetic); their ratio is the price of the unused features.
#include <benchmark/benchmark.h>

#include "soft_body_sim/core/bodies/rope.h"
#include "soft_body_sim/core/forces.h"

namespace soft_body_sim
{
namespace
{
constexpr double kDt = 1e-4;

SceneDef ropeScene(int nodes, IntegratorType integrator)
{
  RopeDef rope;
  rope.nodes = nodes;
  rope.mass = 0.1;
  rope.stiffness = 1000.0;
  rope.damping = 0.01;
  rope.pinned = { 0 };
  SceneDef scene;
  scene.physics.integrator = integrator;
  scene.physics.step.dt = kDt;
  scene.bodies.push_back(buildRope("rope", rope));
  return scene;
}

void BM_RopeStepEngine(benchmark::State& bench, IntegratorType integrator)
{
  World world = buildWorld(ropeScene(static_cast<int>(bench.range(0)), integrator));
  for (auto _ : bench)
  {
    world.step();
    benchmark::DoNotOptimize(world.state().position.data());
  }
  bench.SetItemsProcessed(bench.iterations() * static_cast<int64_t>(world.model().springs.size()));
}

/// Symplectic Euler written out for springs + gravity only: the lower bound for the engine's step.
void BM_RopeStepMinimalLoop(benchmark::State& bench)
{
  const World world = buildWorld(ropeScene(static_cast<int>(bench.range(0)), IntegratorType::SemiImplicitEuler));
  const Model& model = world.model();
  State state = world.state();
  NodeArray force(3, model.nodeCount());
  for (auto _ : bench)
  {
    force.setZero();
    accumulateSpringForces(model, state.position, state.velocity, force);
    for (int i = 0; i < model.nodeCount(); ++i)
    {
      if (model.inverse_mass[i] == 0.0)
        continue;
      state.velocity.col(i) += kDt * (model.gravity + model.inverse_mass[i] * force.col(i));
      state.position.col(i) += kDt * state.velocity.col(i);
    }
    benchmark::DoNotOptimize(state.position.data());
  }
  bench.SetItemsProcessed(bench.iterations() * static_cast<int64_t>(model.springs.size()));
}

BENCHMARK(BM_RopeStepMinimalLoop)->Arg(100)->Arg(1000);
BENCHMARK_CAPTURE(BM_RopeStepEngine, semi_implicit_euler, IntegratorType::SemiImplicitEuler)->Arg(100)->Arg(1000);
BENCHMARK_CAPTURE(BM_RopeStepEngine, explicit_euler, IntegratorType::ExplicitEuler)->Arg(100)->Arg(1000);
BENCHMARK_CAPTURE(BM_RopeStepEngine, verlet, IntegratorType::Verlet)->Arg(100)->Arg(1000);
BENCHMARK_CAPTURE(BM_RopeStepEngine, velocity_verlet, IntegratorType::VelocityVerlet)->Arg(100)->Arg(1000);
BENCHMARK_CAPTURE(BM_RopeStepEngine, rk4, IntegratorType::Rk4)->Arg(100)->Arg(1000);
BENCHMARK_CAPTURE(BM_RopeStepEngine, implicit_euler, IntegratorType::ImplicitEuler)->Arg(100)->Arg(1000);
BENCHMARK_CAPTURE(BM_RopeStepEngine, xpbd, IntegratorType::Xpbd)->Arg(100)->Arg(1000);

}  // namespace
}  // namespace soft_body_sim

BENCHMARK_MAIN();
