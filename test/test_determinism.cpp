// Today's results, pinned bit for bit (as Box2D's test/test_determinism.c pins a state hash): every
// example scene and every hard-case scene, with each integrator that its step keeps stable, runs a fixed
// number of steps while its anchors follow a small circle and its targets jump once; then a hash of the
// exact bits of every position and velocity must equal the value pinned below. A refactor keeps every
// value. A change that alters results on purpose updates the table in the same commit and says why:
// SOFT_BODY_SIM_PRINT_HASHES=1 prints the table as the build computes it. The hashes hold for this
// compiler and flags (g++ 12, the Release build's -O3, x86-64 without -march): the sanitizer build does not
// run this test.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/elements/wide_columns.h"
#include "soft_body_sim/scene/scene_loader.h"
#include "test_util.h"

namespace soft_body_sim::test
{
namespace
{
constexpr int kSteps = 240;
/// Node-steps per run at most: the 100,000-node cloth runs 2 steps (implicit_euler takes ~5 s a step
/// there), every other scene all kSteps.
constexpr double kNodeSteps = 3.0e5;

struct Pinned
{
  const char* scene;       ///< path from the package root
  const char* integrator;  ///< scene-file name
  std::uint64_t hash;
};

// clang-format off
const std::vector<Pinned> kPinned = {
  { "config/scenes/cable.yaml", "implicit_euler", 0x34dc8a964211ee9cULL },
  { "config/scenes/cloth.yaml", "rk4", 0xaae8ec7e9dac4f47ULL },
  { "config/scenes/cloth.yaml", "implicit_euler", 0xe52e5eaae058a859ULL },
  { "config/scenes/cloth.yaml", "xpbd", 0x4bb109f3abb4c01dULL },
  { "config/scenes/creature.yaml", "semi_implicit_euler", 0x765423a5b0770241ULL },
  { "config/scenes/creature.yaml", "verlet", 0x62655c068c372151ULL },
  { "config/scenes/creature.yaml", "velocity_verlet", 0x58aa07c0834867eeULL },
  { "config/scenes/creature.yaml", "rk4", 0xd697d53e481029b5ULL },
  { "config/scenes/creature.yaml", "implicit_euler", 0xe7adc476ec781decULL },
  { "config/scenes/creature.yaml", "xpbd", 0x4cc3d2920fde0bf4ULL },
  { "config/scenes/demo.yaml", "implicit_euler", 0xe542504378f0797eULL },
  { "config/scenes/demo.yaml", "xpbd", 0x2d9558da5e4ba8dcULL },
  { "config/scenes/hanging_chain.yaml", "implicit_euler", 0x114803029f29833cULL },
  { "config/scenes/hanging_chain.yaml", "xpbd", 0xa88ae03d24c4615eULL },
  { "config/scenes/humanoid.yaml", "explicit_euler", 0xc3ca3b1f594e318bULL },
  { "config/scenes/humanoid.yaml", "semi_implicit_euler", 0xc3ca3b1f594e318bULL },
  { "config/scenes/humanoid.yaml", "verlet", 0xc3ca3b1f594e318bULL },
  { "config/scenes/humanoid.yaml", "velocity_verlet", 0xc3ca3b1f594e318bULL },
  { "config/scenes/humanoid.yaml", "rk4", 0xc3ca3b1f594e318bULL },
  { "config/scenes/humanoid.yaml", "implicit_euler", 0xc3ca3b1f594e318bULL },
  { "config/scenes/humanoid.yaml", "xpbd", 0xc3ca3b1f594e318bULL },
  { "config/scenes/jelly.yaml", "semi_implicit_euler", 0xc10f1115e07da9f8ULL },
  { "config/scenes/jelly.yaml", "verlet", 0x8cf215e66bec8f11ULL },
  { "config/scenes/jelly.yaml", "velocity_verlet", 0xc2d2733d01f420f8ULL },
  { "config/scenes/jelly.yaml", "rk4", 0x629f001732ccabccULL },
  { "config/scenes/jelly.yaml", "implicit_euler", 0x7d3de18ab20d23e3ULL },
  { "config/scenes/jelly.yaml", "xpbd", 0x7bd18af25b51c7ddULL },
  { "config/scenes/knot.yaml", "implicit_euler", 0xeed9b80ea3608ed9ULL },
  { "config/scenes/knot.yaml", "xpbd", 0x29cc2d619c3c06b8ULL },
  { "config/scenes/limb.yaml", "explicit_euler", 0x209a46a387d07860ULL },
  { "config/scenes/limb.yaml", "semi_implicit_euler", 0x209a46a387d07860ULL },
  { "config/scenes/limb.yaml", "verlet", 0x209a46a387d07860ULL },
  { "config/scenes/limb.yaml", "velocity_verlet", 0x209a46a387d07860ULL },
  { "config/scenes/limb.yaml", "rk4", 0x209a46a387d07860ULL },
  { "config/scenes/limb.yaml", "implicit_euler", 0x209a46a387d07860ULL },
  { "config/scenes/limb.yaml", "xpbd", 0x209a46a387d07860ULL },
  { "config/scenes/rope.yaml", "semi_implicit_euler", 0xd0e18f98212dc93dULL },
  { "config/scenes/rope.yaml", "verlet", 0xdef19852ec0a1290ULL },
  { "config/scenes/rope.yaml", "velocity_verlet", 0x95f5685e92122fbfULL },
  { "config/scenes/rope.yaml", "rk4", 0xf3ea88e83ab68d8fULL },
  { "config/scenes/rope.yaml", "implicit_euler", 0x3ca46eacb2eaa183ULL },
  { "config/scenes/rope.yaml", "xpbd", 0x9aa8a132b502c6aULL },
  { "config/scenes/soft_box.yaml", "implicit_euler", 0xbc0fd9fcd0ea96faULL },
  { "config/scenes/soft_stack.yaml", "implicit_euler", 0xee77605412f0563fULL },
  { "config/scenes/string.yaml", "semi_implicit_euler", 0xfe674c76035a8a3cULL },
  { "config/scenes/string.yaml", "verlet", 0xb724baf639b4775ULL },
  { "config/scenes/string.yaml", "velocity_verlet", 0x1fe875d77f4947b2ULL },
  { "config/scenes/string.yaml", "rk4", 0x317fc9b54da00c86ULL },
  { "config/scenes/string.yaml", "implicit_euler", 0x3190564623b8ce2fULL },
  { "config/scenes/string.yaml", "xpbd", 0x5f6992a083643df9ULL },
  { "config/scenes/tum_exercise_1.yaml", "semi_implicit_euler", 0xe6e191431315ea4eULL },
  { "config/scenes/tum_exercise_1.yaml", "verlet", 0xa12e00ac9fbda9c6ULL },
  { "config/scenes/tum_exercise_1.yaml", "velocity_verlet", 0x76688a4128002a9ULL },
  { "config/scenes/tum_exercise_1.yaml", "rk4", 0xdfcc71626d5a44c3ULL },
  { "config/scenes/tum_exercise_1.yaml", "implicit_euler", 0x1dfcc6eb3003c2faULL },
  { "config/scenes/tum_exercise_1.yaml", "xpbd", 0x5e2320c1b686eba7ULL },
  { "test/hard_cases/anchor_teleport.yaml", "semi_implicit_euler", 0xba54e2b8c8c4d246ULL },
  { "test/hard_cases/anchor_teleport.yaml", "verlet", 0xd5a664d40ecb238dULL },
  { "test/hard_cases/anchor_teleport.yaml", "velocity_verlet", 0x58698a3724eb024aULL },
  { "test/hard_cases/anchor_teleport.yaml", "rk4", 0xe57174c09f0aab4dULL },
  { "test/hard_cases/anchor_teleport.yaml", "implicit_euler", 0x7d88076d5ffd4ef3ULL },
  { "test/hard_cases/anchor_teleport.yaml", "xpbd", 0x95f85a7705aa2ce4ULL },
  { "test/hard_cases/cloth_folds_on_ball.yaml", "implicit_euler", 0xd65f548b18865e33ULL },
  { "test/hard_cases/cloth_folds_on_ball.yaml", "xpbd", 0x5eabdb7b98f68eabULL },
  { "test/hard_cases/damping_threshold.yaml", "implicit_euler", 0x82b2bfb8e1b93444ULL },
  { "test/hard_cases/damping_threshold.yaml", "xpbd", 0x4c9296c1d78a2d48ULL },
  { "test/hard_cases/heavy_end_chain.yaml", "implicit_euler", 0x2ca19ae4703e8c0bULL },
  { "test/hard_cases/heavy_end_chain.yaml", "xpbd", 0xb2409e6510370dbaULL },
  { "test/hard_cases/jelly_drop_5m.yaml", "semi_implicit_euler", 0xf253f67967e8f176ULL },
  { "test/hard_cases/jelly_drop_5m.yaml", "verlet", 0xf80adb69511d694cULL },
  { "test/hard_cases/jelly_drop_5m.yaml", "velocity_verlet", 0x8f0839856f3af7ceULL },
  { "test/hard_cases/jelly_drop_5m.yaml", "rk4", 0xc641388d56946a5bULL },
  { "test/hard_cases/jelly_drop_5m.yaml", "implicit_euler", 0x5010d899b6f2a9e3ULL },
  { "test/hard_cases/jelly_drop_5m.yaml", "xpbd", 0x605ef59fb8b471c0ULL },
  { "test/hard_cases/large_cloth.yaml", "implicit_euler", 0x8fdda4dbc4301afaULL },
  { "test/hard_cases/large_cloth.yaml", "xpbd", 0x226234149caf26e3ULL },
  { "test/hard_cases/mass_extremes.yaml", "implicit_euler", 0x32db4a26ec1aeabaULL },
  { "test/hard_cases/mass_extremes.yaml", "xpbd", 0x9746c213dbd22bafULL },
  { "test/hard_cases/single_node.yaml", "explicit_euler", 0xd4e5626257b9ea0dULL },
  { "test/hard_cases/single_node.yaml", "semi_implicit_euler", 0x47cb06fa2724ff8aULL },
  { "test/hard_cases/single_node.yaml", "verlet", 0x6a45dcac8ea4439dULL },
  { "test/hard_cases/single_node.yaml", "velocity_verlet", 0xc39148cf5b936566ULL },
  { "test/hard_cases/single_node.yaml", "rk4", 0x1e2eda21cd7b87a1ULL },
  { "test/hard_cases/single_node.yaml", "implicit_euler", 0x47cb06fa2724ff8aULL },
  { "test/hard_cases/single_node.yaml", "xpbd", 0x56cf232357ebaa46ULL },
  { "test/hard_cases/stiff_spring.yaml", "semi_implicit_euler", 0x214a306fc4b712ebULL },
  { "test/hard_cases/stiff_spring.yaml", "verlet", 0x3f7414d88df53eb6ULL },
  { "test/hard_cases/stiff_spring.yaml", "velocity_verlet", 0x94898561474cfb28ULL },
  { "test/hard_cases/stiff_spring.yaml", "rk4", 0x80c8936279830c0dULL },
  { "test/hard_cases/stiff_spring.yaml", "implicit_euler", 0x3df4116ef5a35fa0ULL },
  { "test/hard_cases/stiff_spring.yaml", "xpbd", 0xc6ced583348c4f18ULL },
  { "test/hard_cases/zero_rest_length.yaml", "explicit_euler", 0x27816e2345ffbdb2ULL },
  { "test/hard_cases/zero_rest_length.yaml", "semi_implicit_euler", 0xc6629954a62a5a5aULL },
  { "test/hard_cases/zero_rest_length.yaml", "verlet", 0x9cb2126e34f22d25ULL },
  { "test/hard_cases/zero_rest_length.yaml", "velocity_verlet", 0x3e3ba5e6f76951eeULL },
  { "test/hard_cases/zero_rest_length.yaml", "rk4", 0xe5a7dd213522024cULL },
  { "test/hard_cases/zero_rest_length.yaml", "implicit_euler", 0x5d3591a293b7578bULL },
  { "test/hard_cases/zero_rest_length.yaml", "xpbd", 0xc9dd1899635e2f63ULL },
};
// clang-format on

/// FNV-1a over the bytes of the doubles of `array`, chained from `hash`.
std::uint64_t fnv1a(const NodeArray& array, std::uint64_t hash)
{
  const auto* bytes = reinterpret_cast<const unsigned char*>(array.data());
  const std::size_t size = static_cast<std::size_t>(array.size()) * sizeof(double);
  for (std::size_t k = 0; k < size; ++k)
  {
    hash ^= bytes[k];
    hash *= 1099511628211ULL;
  }
  return hash;
}

std::vector<std::string> scenes()
{
  std::vector<std::string> paths;
  for (const char* folder : { "config/scenes", "test/hard_cases" })
    for (const auto& entry : std::filesystem::directory_iterator(std::string(SOURCE_DIR) + "/" + folder))
      if (entry.path().extension() == ".yaml")
        paths.push_back(std::string(folder) + "/" + entry.path().filename().string());
  std::sort(paths.begin(), paths.end());
  return paths;
}

/// The hash of the exact bits of every position and velocity.
std::uint64_t hashOf(const World& world)
{
  return fnv1a(world.state().velocity, fnv1a(world.state().position, 14695981039346656037ULL));
}

/// A run of `scene` with `integrator`: kSteps steps (fewer for a large scene, see kNodeSteps) in which
/// anchors circle (radius 5 cm, one turn in 2 s, from where they start) for the first half and every body
/// that takes a target is sent 0.3 m along x at step 60.
class Rollout
{
public:
  Rollout(const SceneDef& scene, IntegratorType integrator) : world(build(scene, integrator))
  {
    steps = std::min(kSteps, static_cast<int>(kNodeSteps / world.model().nodeCount()));
    for (const Anchor& anchor : world.model().anchors)
      anchor_start.push_back(world.state().position.col(anchor.node));
  }

  /// Steps `w` (this run's world or a copy of it) from step `from` to step `to` with the run's inputs.
  void stepInputs(World& w, int from, int to) const
  {
    for (int n = from; n < to; ++n)
    {
      if (n < steps / 2)
        for (std::size_t k = 0; k < anchor_start.size(); ++k)
        {
          const double angle = M_PI * w.time();
          w.moveAnchor(static_cast<int>(k), anchor_start[k] + 0.05 * Vec3(std::cos(angle) - 1.0, 0.0, std::sin(angle)));
        }
      if (n == 60)
        for (const BodyRange& body : w.model().bodies)
          w.setTarget(body.name, Vec3(w.state().position.col(body.first)) + Vec3(0.3, 0.0, 0.0));
      w.step();
    }
  }

  World world;
  int steps = 0;
  std::vector<Vec3> anchor_start;

private:
  static World build(SceneDef scene, IntegratorType integrator)
  {
    scene.physics.integrator = integrator;
    return buildWorld(scene);
  }
};

/// The hash after a whole run.
std::uint64_t run(const SceneDef& scene, IntegratorType integrator)
{
  Rollout rollout(scene, integrator);
  rollout.stepInputs(rollout.world, 0, rollout.steps);
  return hashOf(rollout.world);
}

/// The pinned hash of `path` with `integrator`, or nullptr.
const Pinned* pinnedHash(const std::string& path, const std::string& integrator)
{
  const auto pinned = std::find_if(kPinned.begin(), kPinned.end(), [&](const Pinned& p) {
    return path == p.scene && integrator == p.integrator;
  });
  return pinned == kPinned.end() ? nullptr : &*pinned;
}

/// check(scene, integrator, what, pinned) for every pinned run (each scene with each integrator that keeps
/// it stable; `what` names them), then that every pinned run was one.
template <class Check>
void forEachPinnedRun(Check check)
{
  std::size_t checked = 0;
  for (const std::string& path : scenes())
  {
    const SceneDef scene = loadSceneFile(std::string(SOURCE_DIR) + "/" + path);
    for (const IntegratorType integrator : stableIntegrators(scene))
    {
      const std::string name = integratorName(integrator);
      const Pinned* pinned = pinnedHash(path, name);
      ASSERT_NE(pinned, nullptr) << path << " with " << name << " has no pinned hash";
      check(scene, integrator, path + " with " + name, *pinned);
      ++checked;
    }
  }
  EXPECT_EQ(checked, kPinned.size()) << "a pinned scene or integrator no longer runs";
}

TEST(Determinism, EveryExampleAndHardCaseSceneGivesItsPinnedBits)
{
  const bool print = std::getenv("SOFT_BODY_SIM_PRINT_HASHES") != nullptr;
  std::size_t checked = 0;
  for (const std::string& path : scenes())
  {
    const SceneDef scene = loadSceneFile(std::string(SOURCE_DIR) + "/" + path);
    for (const IntegratorType integrator : stableIntegrators(scene))
    {
      const std::string name = integratorName(integrator);
      const std::uint64_t hash = run(scene, integrator);
      if (print)
      {
        std::cout << "  { \"" << path << "\", \"" << name << "\", 0x" << std::hex << hash << std::dec << "ULL },\n";
        continue;
      }
      const Pinned* pinned = pinnedHash(path, name);
      ASSERT_NE(pinned, nullptr) << path << " with " << name << " has no pinned hash";
      EXPECT_EQ(hash, pinned->hash) << path << " with " << name;
      ++checked;
    }
  }
  if (!print)
  {
    EXPECT_EQ(checked, kPinned.size()) << "a pinned scene or integrator no longer runs";
  }
}

TEST(Determinism, TheTwoLaneKernelsOfAProcessorWithoutAvx2GiveThePinnedBits)
{
  // The spring forces and xpbd's sweep take four springs or rows at a time where the processor has AVX2,
  // two (SSE2) where it has not, each lane with the scalar operations (wide_columns.h): every run of the
  // first test with two lanes, on the same pinned bits.
  if (!hasWideLanes())
    GTEST_SKIP() << "no AVX2 here: the first test ran the two lanes";
  useWideLanes(false);
  forEachPinnedRun([](const SceneDef& scene, IntegratorType integrator, const std::string& what, const Pinned& pinned) {
    EXPECT_EQ(run(scene, integrator), pinned.hash) << what << ", two lanes";
  });
  useWideLanes(true);
  EXPECT_TRUE(hasWideLanes());
}

TEST(Determinism, AWorldClonedOrRestoredMidRunStepsOnToTheSameBits)
{
  // Every run of the first test, interrupted a third of the way (after the anchors began circling, before
  // the targets jump): a clone (World's copy) stepped on with the same inputs, the world itself stepped
  // on, restored to a snapshot of that moment and stepped on again, and a world built afresh from the
  // scene, restored from that snapshot's bytes, each end on the run's pinned bits.
  forEachPinnedRun([](const SceneDef& scene, IntegratorType integrator, const std::string& what, const Pinned& pinned) {
    Rollout rollout(scene, integrator);
    const int split = rollout.steps / 3;
    rollout.stepInputs(rollout.world, 0, split);
    World clone(rollout.world);
    const WorldSnapshot moment = rollout.world.snapshot();
    const std::string bytes = moment.toBytes();
    rollout.stepInputs(rollout.world, split, rollout.steps);
    EXPECT_EQ(hashOf(rollout.world), pinned.hash) << what;
    rollout.stepInputs(clone, split, rollout.steps);
    EXPECT_EQ(hashOf(clone), pinned.hash) << what << ": the clone";
    rollout.world.restore(moment);
    EXPECT_EQ(rollout.world.stepCount(), split);
    rollout.stepInputs(rollout.world, split, rollout.steps);
    EXPECT_EQ(hashOf(rollout.world), pinned.hash) << what << ": restored";
    Rollout fresh(scene, integrator);
    fresh.world.restore(WorldSnapshot::fromBytes(bytes));
    EXPECT_EQ(fresh.world.stepCount(), split);
    fresh.stepInputs(fresh.world, split, rollout.steps);
    EXPECT_EQ(hashOf(fresh.world), pinned.hash) << what << ": from bytes";
  });
}

TEST(Determinism, BytesOfAnotherMaterialScalingStepOnWithTheirSprings)
{
  // A force-based scheme keeps its own copy of the springs (SpringArrays); a world that has stepped with
  // the scene's springs, restored from the bytes of one whose springs were stiffened, steps on as that one.
  SceneDef scene = loadSceneFile(std::string(SOURCE_DIR) + "/config/scenes/rope.yaml");
  scene.physics.integrator = IntegratorType::SemiImplicitEuler;
  World stiffened = buildWorld(scene);
  BodyScaling twice;
  twice.stiffness = 2.0;
  ASSERT_TRUE(stiffened.setBodyScaling(scene.bodies.front().name, twice));
  World plain = buildWorld(scene);
  for (int n = 0; n < 10; ++n)
  {
    stiffened.step();
    plain.step();
  }
  plain.restore(WorldSnapshot::fromBytes(stiffened.snapshot().toBytes()));
  for (int n = 0; n < 50; ++n)
  {
    stiffened.step();
    plain.step();
  }
  EXPECT_EQ(hashOf(plain), hashOf(stiffened));
}

TEST(Determinism, AWorldRestoredFromAScaledOnesBytesKeepsTheScenesMaterial)
{
  // A world keeps no copy of its springs as built while its factors are 1 (MaterialScaling): restored from
  // the bytes of a world whose springs were stiffened, it takes that world's springs and factor, and a
  // factor of 1 then gives back the scene's springs, whose fingerprint every world of the scene shares.
  const SceneDef scene = loadSceneFile(std::string(SOURCE_DIR) + "/config/scenes/rope.yaml");
  const std::string body = scene.bodies.front().name;
  const World fresh = buildWorld(scene);
  World stiffened = buildWorld(scene);
  BodyScaling twice;
  twice.stiffness = 2.0;
  ASSERT_TRUE(stiffened.setBodyScaling(body, twice));
  EXPECT_EQ(stiffened.fingerprint(), fresh.fingerprint());
  World plain = buildWorld(scene);
  plain.restore(WorldSnapshot::fromBytes(stiffened.snapshot().toBytes()));
  EXPECT_EQ(plain.bodyScaling(body).stiffness, 2.0);
  EXPECT_EQ(plain.fingerprint(), fresh.fingerprint());
  ASSERT_EQ(plain.model().springs.size(), fresh.model().springs.size());
  for (std::size_t k = 0; k < fresh.model().springs.size(); ++k)
    EXPECT_EQ(plain.model().springs[k].stiffness, 2.0 * fresh.model().springs[k].stiffness) << k;
  ASSERT_TRUE(plain.setBodyScaling(body, BodyScaling{}));
  for (std::size_t k = 0; k < fresh.model().springs.size(); ++k)
    EXPECT_EQ(plain.model().springs[k].stiffness, fresh.model().springs[k].stiffness) << k;
  EXPECT_EQ(plain.fingerprint(), fresh.fingerprint());
}

TEST(Determinism, ASnapshotOfAnotherSceneIsRefusedNamingBoth)
{
  World rope = buildWorld(loadSceneFile(std::string(SOURCE_DIR) + "/config/scenes/rope.yaml"));
  World cloth = buildWorld(loadSceneFile(std::string(SOURCE_DIR) + "/config/scenes/cloth.yaml"));
  const WorldSnapshot moment = cloth.snapshot();
  rope.step();
  const State before = rope.state();
  try
  {
    rope.restore(moment);
    FAIL() << "restored a cloth's snapshot into a rope";
  }
  catch (const std::invalid_argument& e)
  {
    const std::string message = e.what();
    EXPECT_NE(message.find("cloth ("), std::string::npos) << message;
    EXPECT_NE(message.find("rope ("), std::string::npos) << message;
  }
  EXPECT_EQ(rope.state().position, before.position);  // untouched
  EXPECT_EQ(rope.stepCount(), 1);
}

/// The message of the std::invalid_argument that `f` throws, or "" if it throws none.
template <typename F>
std::string refusal(F f)
{
  try
  {
    f();
  }
  catch (const std::invalid_argument& e)
  {
    return e.what();
  }
  return "";
}

TEST(Determinism, SnapshotBytesOfAnotherSceneOrDamagedAreRefusedAndChangeNothing)
{
  World rope = buildWorld(loadSceneFile(std::string(SOURCE_DIR) + "/config/scenes/rope.yaml"));
  World cloth = buildWorld(loadSceneFile(std::string(SOURCE_DIR) + "/config/scenes/cloth.yaml"));
  cloth.step();
  rope.step();
  const std::string cloth_bytes = cloth.snapshot().toBytes();
  std::string rope_bytes = rope.snapshot().toBytes();
  rope.step();
  const State before = rope.state();

  const std::string other = refusal([&] { rope.restore(WorldSnapshot::fromBytes(cloth_bytes)); });
  EXPECT_NE(other.find("cloth ("), std::string::npos) << other;
  EXPECT_NE(other.find("rope ("), std::string::npos) << other;
  // The same scene with another stiffness is another scene: its fingerprint differs.
  std::ifstream file(std::string(SOURCE_DIR) + "/config/scenes/rope.yaml");
  std::string text((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  ASSERT_NE(text.find("stiffness: 200.0"), std::string::npos);
  text.replace(text.find("stiffness: 200.0"), 16, "stiffness: 400.0");
  World stiff = buildWorld(parseScene(text, "<a stiffer rope>"));
  EXPECT_NE(stiff.fingerprint(), rope.fingerprint());
  EXPECT_NE(refusal([&] { stiff.restore(WorldSnapshot::fromBytes(rope_bytes)); }).find("another scene"),
            std::string::npos);

  EXPECT_NE(refusal([&] { WorldSnapshot::fromBytes(rope_bytes.substr(0, rope_bytes.size() - 1)); }).find("damaged"),
            std::string::npos);
  EXPECT_NE(refusal([&] { WorldSnapshot::fromBytes(rope_bytes.substr(0, 20)); }).find("end early"), std::string::npos);
  EXPECT_NE(refusal([&] { WorldSnapshot::fromBytes("not a snapshot at all"); }).find("not a soft_body_sim snapshot"),
            std::string::npos);
  std::string flipped = rope_bytes;
  flipped[flipped.size() / 2] = static_cast<char>(flipped[flipped.size() / 2] ^ 1);
  EXPECT_NE(refusal([&] { WorldSnapshot::fromBytes(flipped); }).find("damaged"), std::string::npos);
  std::string renamed = rope_bytes;
  renamed[32] = static_cast<char>(renamed[32] ^ 1);  // the header's scene summary: the checksum covers it too
  EXPECT_NE(refusal([&] { WorldSnapshot::fromBytes(renamed); }).find("damaged"), std::string::npos);
  std::string newer = rope_bytes;
  newer[12] = static_cast<char>(newer[12] + 1);  // the version, after the magic and the byte-order marker
  EXPECT_NE(refusal([&] { WorldSnapshot::fromBytes(newer); }).find("format version"), std::string::npos);

  EXPECT_EQ(rope.state().position, before.position);  // untouched by every refusal
  EXPECT_EQ(rope.stepCount(), 2);
  rope.restore(WorldSnapshot::fromBytes(rope_bytes));
  EXPECT_EQ(rope.stepCount(), 1);
  EXPECT_DOUBLE_EQ(WorldSnapshot::fromBytes(rope_bytes).time(), rope.time());
}

}  // namespace
}  // namespace soft_body_sim::test
