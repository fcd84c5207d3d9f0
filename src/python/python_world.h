// The World behind Python's sim.World: a world loaded from a scene file as `simulate` loads it, with a lock,
// because its step() runs without Python's GIL while other Python threads may call in.
#pragma once

#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "soft_body_sim/core/world.h"

namespace soft_body_sim::python
{
class PythonWorld
{
public:
  /// Loads `scene` as `simulate` does (loadSceneFile, buildWorld: `dt: auto`, package:// meshes). Throws
  /// SceneError for a file the loader refuses, std::invalid_argument for a scene buildWorld refuses.
  explicit PythonWorld(const std::string& scene);
  /// Parses `yaml_text` as if it were the file `source` (parseScene: meshes by a relative path are found
  /// from source's folder, and the loader's messages name source), then builds it as above. The file need
  /// not exist: a sweep's run is its base scene with some values changed, never written to disk.
  PythonWorld(const std::string& yaml_text, const std::string& source);
  /// A clone (World's copy) with `other`'s scene path and last catches.
  PythonWorld(const PythonWorld& other);
  PythonWorld& operator=(const PythonWorld&) = delete;

  /// Takes `steps` (>= 0) steps; lastEvents() are then the divergence guard's catches in them.
  void step(std::int64_t steps);
  /// Back to `snapshot` (World::restore; std::invalid_argument for another scene's); no catches since.
  void restore(const WorldSnapshot& snapshot);

  /// f(const World&) under the lock.
  template <typename F>
  decltype(auto) read(F&& f) const
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    return std::forward<F>(f)(static_cast<const World&>(world_));
  }
  /// f(World&) under the lock.
  template <typename F>
  decltype(auto) change(F&& f)
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    return std::forward<F>(f)(world_);
  }

  /// The scene file's path as it was given (for a world of text, the source it was parsed as).
  const std::string& scene() const { return scene_; }
  /// The YAML text the world was parsed from; none for a world loaded from its file.
  const std::optional<std::string>& yamlText() const { return yaml_text_; }
  /// The divergence guard's catches in the last step() call, oldest first.
  std::vector<DivergenceEvent> lastEvents() const;

private:
  mutable std::mutex mutex_;
  std::string scene_;
  std::optional<std::string> yaml_text_;
  World world_;
  std::vector<DivergenceEvent> events_;
};

}  // namespace soft_body_sim::python
