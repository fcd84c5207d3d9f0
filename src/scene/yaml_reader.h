// Strict YAML readers shared by the scene loader and the readers of each body type: every value is
// checked for type and range, and every error is one line "<source>:<line>: <key path>: <reason>".
// Private to the scene library (yaml-cpp stays out of the public headers).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include "soft_body_sim/core/model.h"
#include "soft_body_sim/scene/scene_loader.h"

namespace soft_body_sim::scene_yaml
{
using Keys = std::vector<std::string>;

std::string join(const Keys& words);
/// `text` on one printable line: a newline becomes "\n", any other control character '?'.
std::string escapeControlCharacters(const std::string& text);
/// User text made safe for a one-line message: control characters escaped, long text shortened.
std::string printable(const std::string& text);
std::string quoted(const std::string& text);
/// What a wrong value was, for "expected X, got <describe>".
std::string describe(const YAML::Node& node);

/// A value and what an error about it points at: its key path and a line.
struct Field
{
  YAML::Node node;
  std::string path;  ///< e.g. "bodies[0].springs[1].nodes[1]"; empty for the document itself
  /// The key's mark for a mapping value: yaml-cpp marks an empty value at the token after it, which
  /// can be on a later line.
  YAML::Mark mark;
};

std::string childPath(const std::string& parent, const std::string& key);

class Context
{
public:
  explicit Context(std::string source) : source_(std::move(source)) {}

  const std::string& source() const { return source_; }

  /// The message is escaped as a whole: a reason may quote a value as the file wrote it ("got 0.0\r").
  [[noreturn]] void fail(const YAML::Mark& mark, const std::string& path, const std::string& reason) const
  {
    // An empty document has no mark (line -1); it is still "line 1" to the reader.
    const int line = std::max(mark.line, 0) + 1;
    throw SceneError(escapeControlCharacters(source_ + ":" + std::to_string(line) + ": " +
                                             (path.empty() ? "(top level)" : path) + ": " + reason));
  }

  [[noreturn]] void fail(const Field& field, const std::string& reason) const
  {
    fail(field.mark, field.path, reason);
  }

private:
  std::string source_;
};

/// The first document of `text`, its one document that may hold anything (a trailing empty one may
/// follow). Invalid YAML fails as "<source>:<line>:<column>: invalid YAML: <reason>". `scan` is told
/// every event of the first document before yaml-cpp builds it, so that it can refuse the document (with
/// a SceneError) before the tree takes its memory.
YAML::Node loadSingleDocument(const Context& ctx, const std::string& text, YAML::EventHandler& scan);

/// A mapping (any keys).
void requireMapping(const Context& ctx, const Field& field);
/// A mapping whose keys are unique strings from `allowed`.
void requireMap(const Context& ctx, const Field& field, const Keys& allowed);
/// The value under `key` of a mapping checked by requireMap; nullopt if absent.
std::optional<Field> optionalKey(const Field& map, const std::string& key);
Field requiredKey(const Context& ctx, const Field& map, const std::string& key);
/// An optional key: the value under `key` of a mapping checked by requireMap, read into `target` by `read`
/// (readNumber, readVec3, ... any `T read(const Context&, const Field&)`), whose errors name the key's path
/// and line; an absent key leaves `target` as it was, the definition's default.
template <typename T, typename Read>
void readOptional(const Context& ctx, const Field& map, const std::string& key, T& target, Read read)
{
  if (const std::optional<Field> value = optionalKey(map, key))
    target = read(ctx, *value);
}
std::vector<Field> requireList(const Context& ctx, const Field& field, const std::string& expected = "a list");
std::vector<Field> requireListOfSize(const Context& ctx, const Field& field, std::size_t size,
                                     const std::string& what);

/// A finite number (a quoted string is not a number).
double readNumber(const Context& ctx, const Field& field);
double readPositive(const Context& ctx, const Field& field);
double readNonNegative(const Context& ctx, const Field& field);
/// A plain decimal integer ([-+]?[0-9]+).
long long readInteger(const Context& ctx, const Field& field);
/// An integer in [INT_MIN, INT_MAX].
int readInt(const Context& ctx, const Field& field);
/// An integer in [1, INT_MAX].
int readAtLeastOne(const Context& ctx, const Field& field);
/// YAML 1.2 booleans only (true/True/TRUE, false/False/FALSE).
bool readBool(const Context& ctx, const Field& field);
std::string readNonEmptyString(const Context& ctx, const Field& field);
/// A list of exactly 3 finite numbers.
Vec3 readVec3(const Context& ctx, const Field& field);
/// [r, g, b], each in [0, 1].
Vec3 readColor(const Context& ctx, const Field& field);
/// An index into a body of `node_count` nodes.
int readNodeIndex(const Context& ctx, const Field& field, std::size_t node_count);

}  // namespace soft_body_sim::scene_yaml
