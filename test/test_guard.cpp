// The divergence guard (guard.h): it catches a body that diverged, puts it back to the last saved good
// state, applies its policy, and leaves every other body alone. Truth: the discrete invariant of
// symplectic Euler, each scheme's exact discrete parabola, and the same body run alone.
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "scene_error.h"
#include "soft_body_sim/core/scene_def.h"
#include "test_util.h"

namespace soft_body_sim::test
{
namespace
{
constexpr double kOmega = 1000.0;  // [rad/s] of the stiff spring: 1e6 N/m on 1 kg
constexpr double kX0 = 1e-3;       // [m] its initial displacement from rest

/// A 1 kg node hanging from a pinned one on a 1e6 N/m spring of rest length 1 m, stretched kX0 past rest:
/// it oscillates along z only, about its static equilibrium 1 + g / w^2 below the pin.
BodyDef stiffSpring(const std::string& name, double y)
{
  BodyDef body;
  body.name = name;
  body.nodes = { { Vec3(0, y, 0), 1.0, Vec3::Zero(), true }, { Vec3(0, y, -1.0 - kX0), 1.0, Vec3::Zero(), false } };
  body.springs = { { 0, 1, kOmega * kOmega, 0.0, 1.0 } };
  return body;
}

/// One free node of 1 kg thrown at 1 m/s along y: it falls on each scheme's discrete parabola.
BodyDef ball(const std::string& name)
{
  BodyDef body;
  body.name = name;
  body.nodes = { { Vec3(0, 5, 10), 1.0, Vec3(0, 1, 0), false } };
  return body;
}

SceneDef scene(IntegratorType integrator, double dt, GuardPolicy policy, std::vector<BodyDef> bodies)
{
  SceneDef s;
  s.physics.integrator = integrator;
  s.physics.step.dt = dt;
  s.physics.guard.policy = policy;
  s.bodies = std::move(bodies);
  return s;
}

/// The stiff spring's displacement below its static equilibrium [m] and its velocity downwards [m/s].
std::pair<double, double> springMotion(const World& world, int node)
{
  const double g = -world.model().gravity.z();
  return { -world.state().position(2, node) - 1.0 - g / (kOmega * kOmega), -world.state().velocity(2, node) };
}

/// Symplectic Euler's invariant of an undamped oscillator: with v' = v - h w^2 x, x' = x + h v', the
/// quantity w^2 x^2 + v^2 - h w^2 x v is exactly conserved (the shadow energy, times 2 / m).
double shadowEnergy(const World& world, int node, double h)
{
  const auto [x, v] = springMotion(world, node);
  return kOmega * kOmega * (x * x - h * x * v) + v * v;
}

TEST(Guard, SwitchIntegratorRestoresTheBodyStepsItImplicitlyAndLeavesTheOthersAlone)
{
  expectGuardEvents();  // about divergence: the guard catches it
  // Symplectic Euler at w h = 50 multiplies the stiff spring's amplitude by ~2500 per step.
  const double dt = 0.05;
  World world = buildWorld(scene(IntegratorType::SemiImplicitEuler, dt, GuardPolicy::SwitchIntegrator,
                                 { stiffSpring("stiff", 0.0), ball("ball") }));
  World alone = buildWorld(scene(IntegratorType::SemiImplicitEuler, dt, GuardPolicy::SwitchIntegrator, { ball("ball") }));
  const double energy0 = 0.5 * kOmega * kOmega * kX0 * kX0;  // [J]
  bool caught = false;
  Vec3 saved = world.state().position.col(1);
  for (int n = 0; n < 200; ++n)
  {
    if (world.stepCount() % kGuardCheckpointSteps == 0)
      saved = world.state().position.col(1);  // what the guard keeps as the last good state
    world.step();
    alone.step();
    ASSERT_TRUE(allFinite(world.state())) << "step " << n;
    if (!caught && world.divergenceCount() == 1)
    {
      caught = true;
      // Restored to the last good state the guard saved, at most kGuardCheckpointSteps steps back.
      EXPECT_TRUE(expectNear(Vec3(world.state().position.col(1)), saved, 0.0)) << "step " << n;
      const std::vector<DivergenceEvent> events = world.takeDivergenceEvents();
      ASSERT_EQ(events.size(), 1u);
      EXPECT_EQ(events[0].body, "stiff");
      EXPECT_NE(events[0].reason.find("max_speed"), std::string::npos) << events[0].describe();
      EXPECT_EQ(events[0].action, "switched from semi_implicit_euler to implicit_euler");
    }
    // The ball shares the world but not the stiff spring's fate: the same steps as alone, to the bit.
    ASSERT_TRUE(expectNear(Vec3(world.state().position.col(2)), Vec3(alone.state().position.col(0)), 0.0))
        << "step " << n;
  }
  ASSERT_TRUE(caught);
  EXPECT_EQ(world.divergenceCount(), 1);
  EXPECT_EQ(world.divergenceCount(0), 1);
  EXPECT_EQ(world.divergenceCount(1), 0);
  EXPECT_EQ(world.bodyIntegrator(0), IntegratorType::ImplicitEuler);
  EXPECT_EQ(world.bodyIntegrator(1), IntegratorType::SemiImplicitEuler);
  EXPECT_EQ(world.integrator(), IntegratorType::SemiImplicitEuler);
  EXPECT_FALSE(world.isFrozen(0));
  // Implicit Euler only loses energy from wherever the restore left it, which the guard bounded; after
  // 150-odd steps at w h = 50 (each step divides the amplitude by about w h) nothing is left.
  const auto [x, v] = springMotion(world, 1);
  EXPECT_LT(0.5 * kOmega * kOmega * x * x + 0.5 * v * v, 1e-12 * energy0);
}

TEST(Guard, HalveStepRunsTheSpringAtHalfTheSubStepWhereSymplecticEulerIsStable)
{
  expectGuardEvents();  // about divergence: the guard catches it
  // w h = 2.5 is past symplectic Euler's limit 2 (amplitude x ~4 per step); w h / 2 = 1.25 is within.
  const double dt = 2.5e-3;
  SceneDef spring = scene(IntegratorType::SemiImplicitEuler, dt, GuardPolicy::HalveStep, { stiffSpring("stiff", 0.0) });
  // Caught while the swing (1 m/s at first) is still far shorter than the spring: the motion stays linear.
  spring.physics.guard.max_speed = 10.0;
  World world = buildWorld(spring);
  int n = 0;
  while (world.divergenceCount() == 0 && n++ < 100)
    world.step();
  ASSERT_EQ(world.divergenceCount(), 1) << "not caught in 100 steps";
  EXPECT_EQ(world.settings().substeps, 2);
  EXPECT_EQ(world.settings().dt, dt);  // the step and the publishing rate stay
  EXPECT_EQ(world.takeDivergenceEvents().at(0).action, "sub-step halved to 0.00125 s (2 per step, every body)");
  // From here the discrete invariant at h = dt / 2 holds to round-off: the sub-step is really halved.
  const double q0 = shadowEnergy(world, 1, dt / 2);
  for (int k = 0; k < 10000; ++k)
  {
    world.step();
    ASSERT_NEAR(shadowEnergy(world, 1, dt / 2), q0, 1e-9 * q0) << "step " << k;
  }
  EXPECT_EQ(world.divergenceCount(), 1);
}

TEST(Guard, HalveStepFreezesABodyThatDivergesAtEveryStep)
{
  expectGuardEvents();  // about divergence: the guard catches it
  // Explicit Euler on an undamped spring gains 1 + (w h)^2 in energy per step at any h: halving cannot help.
  World world = buildWorld(scene(IntegratorType::ExplicitEuler, 1e-3, GuardPolicy::HalveStep, { stiffSpring("stiff", 0.0) }));
  for (int n = 0; n < 20000 && !world.isFrozen(0); ++n)
    world.step();
  ASSERT_TRUE(world.isFrozen(0));
  EXPECT_EQ(world.settings().substeps, kGuardMaxSubsteps);
  EXPECT_EQ(world.divergenceCount(), 11);  // ten halvings, then the freeze
  const std::vector<DivergenceEvent> events = world.takeDivergenceEvents();
  ASSERT_EQ(events.size(), 11u);
  EXPECT_EQ(events.back().action, "already at 1024 sub-steps per step: frozen (its free nodes pinned at rest)");
}

/// Drives its node away ever faster: its position doubles every step (a controller gone wrong).
class RunawayController final : public Controller
{
public:
  std::unique_ptr<Controller> clone() const override { return std::make_unique<RunawayController>(*this); }
  void carry(StateArchive& /*archive*/) override {}  // no state of its own: it doubles what it finds
  explicit RunawayController(int node) : node_(node) {}
  void step(double dt, State& state) override
  {
    const Vec3 next = 2.0 * Vec3(state.position.col(node_));
    state.velocity.col(node_) = (next - state.position.col(node_)) / dt;
    state.position.col(node_) = next;
  }

private:
  int node_;
};

TEST(Guard, AFrozenBodysControllerStopsToo)
{
  // A free node hangs on a spring from a node that a runaway controller drives: the free node is dragged
  // past max_speed, the guard freezes the body, and from then on the driven node stands still too. Left
  // running, the controller would reach infinity (2^1024) within about a thousand steps.
  expectGuardEvents();  // about the guard's freeze
  BodyDef body;
  body.name = "runaway";
  body.nodes = { { Vec3(1, 0, 0), 1.0, Vec3::Zero(), true }, { Vec3(1, 0, -1), 1.0, Vec3::Zero(), false } };
  body.springs = { { 0, 1, 100.0, 0.0, 1.0 } };
  body.controller = [](int first_node) { return std::make_unique<RunawayController>(first_node); };
  World world = buildWorld(scene(IntegratorType::ImplicitEuler, 0.01, GuardPolicy::Freeze, { body }));
  int steps_to_freeze = 0;
  while (!world.isFrozen(0) && steps_to_freeze < 100)
  {
    world.step();
    ++steps_to_freeze;
  }
  ASSERT_TRUE(world.isFrozen(0));
  const Vec3 driven = world.state().position.col(0);
  for (int n = 0; n < 2000; ++n)
  {
    world.step();
    ASSERT_TRUE(allFinite(world.state())) << "step " << n;
    ASSERT_TRUE(expectNear(Vec3(world.state().position.col(0)), driven, 0.0)) << "step " << n;
    ASSERT_TRUE(expectNear(Vec3(world.state().velocity.col(0)), Vec3::Zero(), 0.0)) << "step " << n;
  }
  EXPECT_EQ(world.divergenceCount(), 1);
}

TEST(Guard, FreezeStopsTheBodyWhileAnotherFallsOnItsExactParabola)
{
  expectGuardEvents();  // about divergence: the guard catches it
  const double dt = 0.01;
  World world = buildWorld(scene(IntegratorType::ExplicitEuler, dt, GuardPolicy::Freeze,
                                 { stiffSpring("stiff", 0.0), ball("ball") }));
  const Vec3 x0 = world.state().position.col(2);
  const Vec3 v0 = world.state().velocity.col(2);
  const Vec3 g = world.model().gravity;
  Vec3 frozen_at = Vec3::Zero();
  for (int n = 1; n <= 300; ++n)
  {
    world.step();
    ASSERT_TRUE(allFinite(world.state()));
    if (world.isFrozen(0))
    {
      if (frozen_at.isZero())
        frozen_at = world.state().position.col(1);
      // Frozen: pinned at rest, never checked or moved again.
      ASSERT_TRUE(expectNear(Vec3(world.state().position.col(1)), frozen_at, 0.0)) << "step " << n;
      ASSERT_TRUE(expectNear(Vec3(world.state().velocity.col(1)), Vec3::Zero(), 0.0));
    }
    // Explicit Euler's exact discrete free fall: x_n = x0 + n h v0 + h^2 g n (n - 1) / 2.
    const Vec3 expected = x0 + n * dt * v0 + dt * dt * g * (n * (n - 1) / 2.0);
    ASSERT_TRUE(expectNear(Vec3(world.state().position.col(2)), expected, 1e-12 * (1.0 + n * n))) << "step " << n;
  }
  EXPECT_TRUE(world.isFrozen(0));
  EXPECT_FALSE(world.isFrozen(1));
  EXPECT_EQ(world.divergenceCount(), 1);
  EXPECT_EQ(world.model().inverse_mass[1], 0.0);
}

TEST(Guard, ANonFiniteOrRunawayNodeSetFromOutsideIsPutBackToTheLastSavedGoodState)
{
  expectGuardEvents();  // about divergence: the guard catches it
  World world = buildWorld(scene(IntegratorType::ImplicitEuler, 0.01, GuardPolicy::SwitchIntegrator,
                                 { ball("a"), ball("b") }));
  const State good = world.state();  // saved at step 0; the next save is at step kGuardCheckpointSteps
  world.step();
  world.setNode(0, Vec3(std::numeric_limits<double>::quiet_NaN(), 0, 0), Vec3::Zero());
  world.step();
  ASSERT_TRUE(allFinite(world.state()));
  EXPECT_TRUE(expectNear(Vec3(world.state().position.col(0)), Vec3(good.position.col(0)), 0.0));
  EXPECT_TRUE(expectNear(Vec3(world.state().velocity.col(0)), Vec3::Zero(), 0.0));  // frozen: at rest
  EXPECT_FALSE(expectNear(Vec3(world.state().position.col(1)), Vec3(good.position.col(1)), 1e-6));  // b fell on
  std::vector<DivergenceEvent> events = world.takeDivergenceEvents();
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].reason, "node 0 is not finite");
  // Already on implicit_euler: nothing stabler to switch to, so the body is frozen.
  EXPECT_EQ(events[0].action, "already on implicit_euler: frozen (its free nodes pinned at rest)");
  EXPECT_TRUE(world.isFrozen(0));
  EXPECT_EQ(events[0].describe(), "body 'a' diverged at t = 0.020 s (node 0 is not finite): restored to its last "
                                  "good state, already on implicit_euler: frozen (its free nodes pinned at rest)");

  // Faster than max_speed: caught as well (body b, still free).
  GuardSettings guard;
  guard.max_speed = 100.0;
  world.setGuard(guard);
  world.setNode(1, world.state().position.col(1), Vec3(0, 0, -101.0));
  world.step();
  events = world.takeDivergenceEvents();
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].body, "b");
  EXPECT_EQ(events[0].reason, "node 0 moves at 101 m/s > max_speed 100 m/s");
  EXPECT_TRUE(world.takeDivergenceEvents().empty());
}

TEST(Guard, AnXpbdBodyIsSwitchedToImplicitEuler)
{
  expectGuardEvents();  // about divergence: the guard catches it
  World world = buildWorld(scene(IntegratorType::Xpbd, 0.01, GuardPolicy::SwitchIntegrator, { ball("a") }));
  world.setNode(0, world.state().position.col(0), Vec3(std::numeric_limits<double>::infinity(), 0, 0));
  world.step();
  const std::vector<DivergenceEvent> events = world.takeDivergenceEvents();
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].action, "switched from xpbd to implicit_euler");
  EXPECT_EQ(world.bodyIntegrator(0), IntegratorType::ImplicitEuler);
  EXPECT_FALSE(world.isFrozen(0));
}

TEST(Guard, RejectsANonPositiveOrNonFiniteMaxSpeed)
{
  World world = buildWorld(scene(IntegratorType::Xpbd, 0.01, GuardPolicy::Freeze, { ball("a") }));
  for (double speed : { 0.0, -1.0, std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN() })
  {
    GuardSettings guard;
    guard.max_speed = speed;
    EXPECT_THROW(world.setGuard(guard), std::invalid_argument) << speed;
  }
  EXPECT_EQ(world.guard().policy, GuardPolicy::Freeze);
}

TEST(GuardScene, ReadsThePolicyAndMaxSpeedAndRejectsBadValues)
{
  const std::string head = "physics:\n  guard:\n";
  const std::string body = "bodies:\n  - name: a\n    type: custom\n    nodes:\n      - {position: [0, 0, 0], mass: 1}\n";
  const SceneDef s = parseScene(head + "    policy: halve_step\n    max_speed: 20.0\n" + body, "guard.yaml");
  EXPECT_EQ(s.physics.guard.policy, GuardPolicy::HalveStep);
  EXPECT_EQ(s.physics.guard.max_speed, 20.0);
  EXPECT_EQ(parseScene(body, "guard.yaml").physics.guard.policy, GuardPolicy::SwitchIntegrator);
  expectSceneError(head + "    policy: explode\n" + body, "bad.yaml:3: physics.guard.policy",
                   { "unknown policy", "halve_step", "switch_integrator", "freeze" });
  expectSceneError(head + "    max_speed: 0\n" + body, "bad.yaml:3: physics.guard.max_speed", { "> 0" });
  expectSceneError(head + "    speed: 1\n" + body, "bad.yaml:3: physics.guard.speed", { "unknown key" });
}

}  // namespace
}  // namespace soft_body_sim::test
