// The custom bodies' listed nodes, counted against kMaxSceneNodes from the parser's events, before
// yaml-cpp builds its tree of the document. That tree takes ~480 bytes a value (measured: 382 MB for the
// 800,000 values of 100,000 nodes written `- {position: [x, y, z], mass: m}`, a 5.4 MB file), so a file
// under kMaxSceneFileBytes listing more nodes than a scene may have would take gigabytes only to be
// refused; the scan holds only the path it is at and the length of each anchored list.
#pragma once

#include <string>
#include <vector>

#include <yaml-cpp/eventhandler.h>

#include "scene/yaml_reader.h"

namespace soft_body_sim::scene_yaml
{
/// Counts the items of every `bodies[i].nodes` list (a custom body's nodes; a rod's `nodes` is a number,
/// and a list under another type's is refused later anyway) and fails at the list that takes the count
/// over kMaxSceneNodes. The full check, with the generated bodies' nodes, is SceneSoFar::requireNodes
/// once the document is read.
class ListedNodesScan : public YAML::EventHandler
{
public:
  explicit ListedNodesScan(const Context& ctx) : ctx_(ctx) {}

  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& mark, YAML::anchor_t) override { value(mark, nullptr); }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t anchor) override;
  void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t, const std::string& text) override
  {
    value(mark, &text);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor,
                       YAML::EmitterStyle::value) override
  {
    value(mark, nullptr);
    levels_.emplace_back(false);
    levels_.back().anchor = anchor;
  }
  void OnSequenceEnd() override;
  void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override
  {
    value(mark, nullptr);
    levels_.emplace_back(true);
  }
  void OnMapEnd() override { levels_.pop_back(); }

private:
  /// An open mapping or sequence.
  struct Level
  {
    explicit Level(bool is_mapping) : mapping(is_mapping) {}

    bool mapping;
    bool at_key = true;  ///< a mapping's next value is a key
    std::string key;     ///< a mapping's last key, if it was a scalar
    YAML::Mark key_mark;
    long long items = 0;       ///< a sequence's items so far
    YAML::anchor_t anchor = 0;  ///< a sequence's anchor (`&name`), 0 without one
  };

  /// A value starts (a scalar's `text` given) inside the innermost open level.
  void value(const YAML::Mark& mark, const std::string* text);
  /// Whether the innermost open level is the list of nodes at bodies[i].nodes.
  bool inNodeList() const;
  /// Whether the next value is the one at bodies[i].nodes.
  bool atNodeListKey() const;
  /// Adds `count` nodes listed in bodies[i].nodes; fails if that takes the scene over kMaxSceneNodes.
  void addNodes(long long count, const YAML::Mark& mark);

  const Context& ctx_;
  std::vector<Level> levels_;
  long long nodes_ = 0;
  /// The item count of every anchored sequence, by anchor: `nodes: *name` lists as many nodes as the
  /// sequence `&name` holds (the tree shares it, yet the body copies it).
  std::vector<long long> anchored_items_;
};

}  // namespace soft_body_sim::scene_yaml
