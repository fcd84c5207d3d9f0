#include "scene/listed_nodes_scan.h"

namespace soft_body_sim::scene_yaml
{
void ListedNodesScan::value(const YAML::Mark& mark, const std::string* text)
{
  if (levels_.empty())
    return;
  Level& parent = levels_.back();
  if (parent.mapping)
  {
    if (parent.at_key)
    {
      parent.key = text ? *text : std::string();
      parent.key_mark = mark;
    }
    parent.at_key = !parent.at_key;
    return;
  }
  ++parent.items;
  // An item of the list at bodies[i].nodes: the document's mapping, `bodies`, its list, a body's mapping,
  // `nodes`, its list.
  const bool listed_node = levels_.size() == 4 && levels_[0].mapping && levels_[0].key == "bodies" &&
                           !levels_[1].mapping && levels_[2].mapping && levels_[2].key == "nodes" &&
                           !levels_[3].mapping;
  if (listed_node && ++nodes_ > kMaxSceneNodes)
    ctx_.fail(levels_[2].key_mark, "bodies[" + std::to_string(levels_[1].items - 1) + "].nodes",
              "the scene would have more than " + std::to_string(kMaxSceneNodes) + " nodes (" +
                  std::to_string(nodes_) + " listed in its custom bodies up to line " + std::to_string(mark.line + 1) +
                  ")");
}

}  // namespace soft_body_sim::scene_yaml
