// libFuzzer harness for the scene parser: any bytes are parsed as a scene file; a scene that loads is
// built and stepped a little. Only SceneError (and buildWorld's std::invalid_argument) may come out;
// a crash, a sanitizer report or any other exception is a finding.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "soft_body_sim/scene/scene_loader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  using namespace soft_body_sim;
  const std::string text(reinterpret_cast<const char*>(data), size);
  // Counts of 100 and more (nx: 999, ny: 999) make legitimately large scenes of up to 10^6 nodes,
  // which test_hard_cases covers; here they would only spend the run on allocation. Such an integer is
  // a run of 3+ digits not followed by '.', 'e' or 'E' (a float such as 8000.0 passes).
  for (std::size_t i = 0, run = 0; i <= text.size(); ++i)
  {
    const bool digit = i < text.size() && text[i] >= '0' && text[i] <= '9';
    if (!digit && run >= 3 && (i == text.size() || (text[i] != '.' && text[i] != 'e' && text[i] != 'E')))
      return 0;
    run = digit ? run + 1 : 0;
  }
  SceneDef scene;
  try
  {
    scene = parseScene(text, "fuzz.yaml");
  }
  catch (const SceneError&)
  {
    return 0;
  }
  // Bound the work per input (a valid scene may ask for 10^6 nodes or 2^31 sub-steps).
  std::size_t nodes = 0;
  for (const BodyDef& body : scene.bodies)
    nodes += body.nodes.size();
  const double work = static_cast<double>(nodes) * scene.physics.step.substeps * scene.physics.step.iterations;
  if (work > 2e4)
    return 0;
  try
  {
    World world = buildWorld(scene);
    for (int n = 0; n < 5; ++n)
      world.step();
  }
  catch (const std::invalid_argument&)
  {
  }
  return 0;
}
