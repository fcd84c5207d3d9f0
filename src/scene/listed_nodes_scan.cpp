#include "scene/listed_nodes_scan.h"

namespace soft_body_sim::scene_yaml
{
// The path to a custom body's nodes: the document's mapping, its key `bodies`, that list, a body's
// mapping, its key `nodes`, that list.

bool ListedNodesScan::atNodeListKey() const
{
  return levels_.size() == 3 && levels_[0].mapping && levels_[0].key == "bodies" && !levels_[1].mapping &&
         levels_[2].mapping && !levels_[2].at_key && levels_[2].key == "nodes";
}

bool ListedNodesScan::inNodeList() const
{
  return levels_.size() == 4 && levels_[0].mapping && levels_[0].key == "bodies" && !levels_[1].mapping &&
         levels_[2].mapping && levels_[2].key == "nodes" && !levels_[3].mapping;
}

void ListedNodesScan::addNodes(long long count, const YAML::Mark& mark)
{
  nodes_ += count;
  if (nodes_ > kMaxSceneNodes)
    ctx_.fail(levels_[2].key_mark, "bodies[" + std::to_string(levels_[1].items - 1) + "].nodes",
              "the scene would have more than " + std::to_string(kMaxSceneNodes) + " nodes (" +
                  std::to_string(nodes_) + " listed in its custom bodies up to line " + std::to_string(mark.line + 1) +
                  ")");
}

void ListedNodesScan::OnAlias(const YAML::Mark& mark, YAML::anchor_t anchor)
{
  if (atNodeListKey() && anchor < anchored_items_.size())
    addNodes(anchored_items_[anchor], mark);
  value(mark, nullptr);
}

void ListedNodesScan::OnSequenceEnd()
{
  const Level& list = levels_.back();
  if (list.anchor != 0)
  {
    if (anchored_items_.size() <= list.anchor)
      anchored_items_.resize(list.anchor + 1, 0);
    anchored_items_[list.anchor] = list.items;
  }
  levels_.pop_back();
}

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
  if (inNodeList())
    addNodes(1, mark);
}

}  // namespace soft_body_sim::scene_yaml
