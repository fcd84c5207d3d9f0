#include "python/names.h"

#include <algorithm>

namespace soft_body_sim::python
{
std::string listed(const std::vector<std::string>& names)
{
  if (names.empty())
    return "none";
  std::string text;
  for (const std::string& name : names)
    text += (text.empty() ? "'" : ", '") + name + "'";
  return text;
}

std::size_t findBody(const Model& model, const std::string& body)
{
  std::vector<std::string> known;
  for (std::size_t b = 0; b < model.bodies.size(); ++b)
  {
    if (model.bodies[b].name == body)
      return b;
    known.push_back(model.bodies[b].name);
  }
  throw UnknownName("unknown body '" + body + "'; the scene's bodies: " + listed(known));
}

int findAnchor(const World& world, const std::string& body, const std::string& anchor)
{
  findBody(world.model(), body);
  if (const std::optional<int> k = world.findAnchor(body, anchor))
    return *k;
  std::vector<std::string> known;
  for (const Anchor& a : world.model().anchors)
    if (a.body == body)
      known.push_back(a.name);
  throw UnknownName("body '" + body + "' has no anchor '" + anchor + "'; its anchors: " + listed(known));
}

std::size_t findGrasp(const World& world, const std::string& frame)
{
  std::vector<std::string> known;
  for (std::size_t k = 0; k < world.grasps().size(); ++k)
  {
    if (world.grasps()[k].name == frame)
      return k;
    known.push_back(world.grasps()[k].name);
  }
  throw UnknownName("no grasp of frame '" + frame + "'; the grasps now: " + listed(known));
}

std::vector<std::string> movableColliders(const Model& model)
{
  std::vector<std::string> names;
  for (const ColliderPlacement* at : placements(model.colliders))
    if (!at->name.empty())
      names.push_back(at->name);
  return names;
}

}  // namespace soft_body_sim::python
