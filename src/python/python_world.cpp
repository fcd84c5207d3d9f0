#include "python/python_world.h"

#include "soft_body_sim/scene/scene_loader.h"

namespace soft_body_sim::python
{
PythonWorld::PythonWorld(const std::string& scene) : scene_(scene), world_(buildWorld(loadSceneFile(scene))) {}

PythonWorld::PythonWorld(const std::string& yaml_text, const std::string& source)
  : scene_(source), yaml_text_(yaml_text), world_(buildWorld(parseScene(yaml_text, source)))
{
}

PythonWorld::PythonWorld(const PythonWorld& other)
  : scene_(other.scene_), yaml_text_(other.yaml_text_), world_(other.read([](const World& world) { return world; })), events_(other.lastEvents())
{
}

void PythonWorld::step(std::int64_t steps)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  for (std::int64_t n = 0; n < steps; ++n)
    world_.step();
  events_ = world_.takeDivergenceEvents();
}

void PythonWorld::restore(const WorldSnapshot& snapshot)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  world_.restore(snapshot);
  events_.clear();
}

std::vector<DivergenceEvent> PythonWorld::lastEvents() const
{
  const std::lock_guard<std::mutex> lock(mutex_);
  return events_;
}

}  // namespace soft_body_sim::python
