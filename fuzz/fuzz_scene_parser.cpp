// libFuzzer harness for the scene parser: any bytes are parsed as a scene file; a scene that loads is
// built and stepped a little, and a clone of it made mid-way, and a world built afresh and restored from the
// snapshot's bytes, must step on to the same bits. Only
// SceneError (and buildWorld's std::invalid_argument) may come out, and a SceneError must be one printable
// line that names the file; a crash, a sanitizer report, a slow input (-timeout), an input that takes too
// much memory (-rss_limit_mb), a clone that steps on differently or any other exception is a finding.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>

#include "soft_body_sim/scene/scene_loader.h"
#include "core/integrators/integrator_kit.h"

namespace
{
/// Meshing 850,000 tetrahedra (an 80 m box the fuzzer made of soft_box.yaml's at its resolution) takes
/// TetGen 38 s, past the 25 s timeout, and repeats what a small mesh covers: volumes of more than
/// 20,000 are refused here (about a second), as a finer resolution is refused past kMaxTetrahedra.
const soft_body_sim::SceneLimits kLimits{ 2.0e4 };
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  using namespace soft_body_sim;
  const std::string text(reinterpret_cast<const char*>(data), size);
  SceneDef scene;
  try
  {
    scene = parseScene(text, "fuzz.yaml", kLimits);
  }
  catch (const SceneError& e)
  {
    const std::string message = e.what();
    const bool control = std::any_of(message.begin(), message.end(), [](char c) {
      return static_cast<unsigned char>(c) < 0x20 || c == 0x7f;
    });
    if (message.rfind("fuzz.yaml:", 0) != 0 || control)
    {
      std::fprintf(stderr, "not one printable line naming the file: %s\n", message.c_str());
      std::abort();
    }
    return 0;
  }
  // Bound the stepping per input: a valid scene may ask for 10^6 nodes or 2^31 sub-steps, which would only
  // repeat what a small scene covers. A step updates every node, spring, constraint and cell once per
  // iteration of each sub-step. A tetrahedron counts five: its 12x12 block, its SVD and the fill of a
  // solid's factorisation cost more. Measured under the sanitizers, five steps take 2-3 ms per tetrahedron
  // (2.0 s for soft_box.yaml's 937, 4.3 s for soft_stack.yaml's 1,560, 40 s for a 12,600-tetrahedron bar
  // the fuzzer made, beyond its 25 s timeout): the largest solid that steps (2,000) stays near 6 s. A
  // solid's surface sample counts one (a distance to each collider near it per sub-step).
  // With soft solids, implicit_euler takes up to NewtonRule's most iterations, whatever `iterations` says.
  std::size_t elements = 0;
  bool solids = false;
  for (const BodyDef& body : scene.bodies)
  {
    elements += body.nodes.size() + body.springs.size() + body.constraints.size() + body.cells.size() +
                5 * body.tetrahedra.size() + body.surface_samples.size();
    solids = solids || !body.tetrahedra.empty();
  }
  const int iterations = solids ? std::max(scene.physics.step.iterations, NewtonRule::kMostIterations)
                                : scene.physics.step.iterations;
  const double work = static_cast<double>(elements) * scene.physics.step.substeps * iterations;
  if (work > 1e4)
    return 0;
  try
  {
    // Three steps, a clone and a world restored from the snapshot's bytes, two more steps of each: they
    // must end on the same bits (World's copy and its bytes carry everything the future depends on), NaN
    // or not.
    World world = buildWorld(scene);
    World fresh = buildWorld(scene);
    for (int n = 0; n < 3; ++n)
      world.step();
    World clone(world);
    try
    {
      fresh.restore(WorldSnapshot::fromBytes(world.snapshot().toBytes()));
    }
    catch (const std::invalid_argument& e)
    {
      std::fprintf(stderr, "a world refused its own snapshot's bytes: %s\n", e.what());
      std::abort();
    }
    for (int n = 0; n < 2; ++n)
    {
      world.step();
      clone.step();
      fresh.step();
    }
    const auto same = [](const auto& x, const auto& y) {  // bit for bit (an empty array's data is null)
      return x.size() == y.size() &&
             (x.size() == 0 || std::memcmp(x.data(), y.data(), sizeof(double) * static_cast<std::size_t>(x.size())) == 0);
    };
    const State& a = world.state();
    for (const World* other : { &clone, &fresh })
    {
      const State& b = other->state();
      if (!same(a.position, b.position) || !same(a.velocity, b.velocity) || !same(a.twist, b.twist))
      {
        std::fprintf(stderr, "a %s stepped on to other bits than its original\n",
                     other == &clone ? "clone" : "world restored from bytes");
        std::abort();
      }
    }
  }
  catch (const std::invalid_argument&)
  {
  }
  return 0;
}
