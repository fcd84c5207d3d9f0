// Every example scene under config/scenes/ loads and runs 10 simulated seconds without NaN.
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "soft_body_sim/scene/scene_loader.h"

namespace soft_body_sim
{
namespace
{
std::vector<std::string> exampleScenes()
{
  std::vector<std::string> paths;
  for (const auto& entry : std::filesystem::directory_iterator(std::string(SOURCE_DIR) + "/config/scenes"))
    if (entry.path().extension() == ".yaml")
      paths.push_back(entry.path().string());
  std::sort(paths.begin(), paths.end());
  return paths;
}

TEST(ExampleScenes, EachRunsTenSecondsWithoutNaN)
{
  const std::vector<std::string> paths = exampleScenes();
  ASSERT_FALSE(paths.empty());
  for (const std::string& path : paths)
  {
    SCOPED_TRACE(path);
    World world = buildWorld(loadSceneFile(path));
    const long steps = std::lround(10.0 / world.settings().dt);
    for (long n = 1; n <= steps; ++n)
    {
      world.step();
      if (n % 100 == 0 || n == steps)
      {
        ASSERT_TRUE(world.state().position.allFinite() && world.state().velocity.allFinite()) << "step " << n;
      }
    }
  }
}

}  // namespace
}  // namespace soft_body_sim
