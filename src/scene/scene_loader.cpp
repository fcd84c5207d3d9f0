#include "soft_body_sim/scene/scene_loader.h"

#include <algorithm>
#include <charconv>
#include <climits>
#include <cmath>
#include <fstream>
#include <iterator>
#include <map>
#include <optional>
#include <set>
#include <utility>

#include <yaml-cpp/yaml.h>

namespace soft_body_sim
{
namespace
{
using Keys = std::vector<std::string>;

const Keys kSceneKeys = { "frame_id", "physics", "bodies" };
const Keys kPhysicsKeys = { "integrator", "dt", "substeps", "iterations", "gravity", "drag" };
const Keys kBodyTypes = { "custom" };
const Keys kCustomBodyKeys = { "name", "type", "nodes", "springs", "constraints" };
const Keys kNodeKeys = { "position", "mass", "velocity", "pinned" };
const Keys kSpringKeys = { "nodes", "stiffness", "damping", "rest_length" };
const Keys kConstraintKeys = { "nodes", "compliance", "rest_length" };

std::string join(const Keys& words)
{
  std::string out;
  for (const std::string& word : words)
    out += (out.empty() ? "" : ", ") + word;
  return out;
}

/// User text made safe for a one-line message: control characters escaped, long text shortened.
std::string printable(const std::string& text)
{
  constexpr std::size_t kMaxLength = 60;
  std::string out;
  for (const char c : text.substr(0, kMaxLength))
  {
    if (c == '\n')
      out += "\\n";
    else if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
      out += '?';
    else
      out += c;
  }
  return text.size() > kMaxLength ? out + "..." : out;
}

std::string quoted(const std::string& text) { return "'" + printable(text) + "'"; }

/// yaml-cpp gives quoted scalars the tag "!" and plain ones "?"; a quoted "1.5" is a string in YAML.
bool isQuoted(const YAML::Node& node) { return node.Tag() == "!"; }

/// What a wrong value was, for "expected X, got <describe>".
std::string describe(const YAML::Node& node)
{
  switch (node.Type())
  {
    case YAML::NodeType::Null:
      return "an empty value (null)";
    case YAML::NodeType::Sequence:
      return "a list";
    case YAML::NodeType::Map:
      return "a mapping";
    case YAML::NodeType::Scalar:
      return (isQuoted(node) ? "the quoted string " : "") + quoted(node.Scalar());
    case YAML::NodeType::Undefined:
      break;
  }
  return "nothing";
}

/// A value and what an error about it points at: its key path and a line.
struct Field
{
  YAML::Node node;
  std::string path;  ///< e.g. "bodies[0].springs[1].nodes[1]"; empty for the document itself
  /// The key's mark for a mapping value: yaml-cpp marks an empty value at the token after it, which
  /// can be on a later line.
  YAML::Mark mark;
};

std::string childPath(const std::string& parent, const std::string& key)
{
  return parent.empty() ? key : parent + "." + key;
}

class Context
{
public:
  explicit Context(std::string source) : source_(std::move(source)) {}

  [[noreturn]] void fail(const YAML::Mark& mark, const std::string& path, const std::string& reason) const
  {
    // An empty document has no mark (line -1); it is still "line 1" to the reader.
    const int line = std::max(mark.line, 0) + 1;
    throw SceneError(source_ + ":" + std::to_string(line) + ": " + (path.empty() ? "(top level)" : path) +
                     ": " + reason);
  }

  [[noreturn]] void fail(const Field& field, const std::string& reason) const
  {
    fail(field.mark, field.path, reason);
  }

private:
  std::string source_;
};

// --- structure ---------------------------------------------------------------------------------

void requireMapping(const Context& ctx, const Field& field)
{
  if (!field.node.IsMap())
    ctx.fail(field, "expected a mapping, got " + describe(field.node));
}

/// A mapping whose keys are unique strings from `allowed`. Duplicates are rejected because yaml-cpp
/// keeps both and lookups would silently use the first.
void requireMap(const Context& ctx, const Field& field, const Keys& allowed)
{
  requireMapping(ctx, field);
  std::set<std::string> seen;
  for (const auto& entry : field.node)
  {
    const YAML::Node& key = entry.first;
    if (!key.IsScalar())
      ctx.fail(key.Mark(), field.path, "keys must be strings, got " + describe(key));
    const std::string path = childPath(field.path, printable(key.Scalar()));
    if (std::find(allowed.begin(), allowed.end(), key.Scalar()) == allowed.end())
      ctx.fail(key.Mark(), path, "unknown key " + quoted(key.Scalar()) + "; allowed keys: " + join(allowed));
    if (!seen.insert(key.Scalar()).second)
      ctx.fail(key.Mark(), path, "duplicate key");
  }
}

/// The value under `key` of a mapping checked by requireMap; nullopt if absent.
std::optional<Field> optionalKey(const Field& map, const std::string& key)
{
  for (const auto& entry : map.node)
    if (entry.first.Scalar() == key)
      return Field{ entry.second, childPath(map.path, key), entry.first.Mark() };
  return std::nullopt;
}

Field requiredKey(const Context& ctx, const Field& map, const std::string& key)
{
  if (std::optional<Field> field = optionalKey(map, key))
    return *field;
  ctx.fail(map.mark, childPath(map.path, key), "missing required key");
}

std::vector<Field> requireList(const Context& ctx, const Field& field, const std::string& expected = "a list")
{
  if (!field.node.IsSequence())
    ctx.fail(field, "expected " + expected + ", got " + describe(field.node));
  std::vector<Field> items;
  for (const YAML::Node& item : field.node)
    items.push_back({ item, field.path + "[" + std::to_string(items.size()) + "]", item.Mark() });
  return items;
}

std::vector<Field> requireListOfSize(const Context& ctx, const Field& field, std::size_t size,
                                     const std::string& what)
{
  const std::string expected = "a list of " + std::to_string(size) + " " + what;
  std::vector<Field> items = requireList(ctx, field, expected);
  if (items.size() != size)
    ctx.fail(field, "expected " + expected + ", got " + std::to_string(items.size()) + " item(s)");
  return items;
}

// --- scalars -----------------------------------------------------------------------------------

double readNumber(const Context& ctx, const Field& field)
{
  double value = 0.0;
  if (!field.node.IsScalar() || isQuoted(field.node) || !YAML::convert<double>::decode(field.node, value))
    ctx.fail(field, "expected a number, got " + describe(field.node));
  if (!std::isfinite(value))
    ctx.fail(field, "must be a finite number, got " + quoted(field.node.Scalar()));
  return value;
}

double readPositive(const Context& ctx, const Field& field)
{
  const double value = readNumber(ctx, field);
  if (!(value > 0.0))
    ctx.fail(field, "must be > 0, got " + field.node.Scalar());
  return value;
}

double readNonNegative(const Context& ctx, const Field& field)
{
  const double value = readNumber(ctx, field);
  if (value < 0.0)
    ctx.fail(field, "must be >= 0, got " + field.node.Scalar());
  return value;
}

/// A plain decimal integer as YAML 1.2 writes one ([-+]?[0-9]+). Parsed here rather than by
/// yaml-cpp, which also takes 0x1F and reads 010 as octal 8.
long long readInteger(const Context& ctx, const Field& field)
{
  if (!field.node.IsScalar() || isQuoted(field.node))
    ctx.fail(field, "expected an integer, got " + describe(field.node));
  const std::string& text = field.node.Scalar();
  const char* first = text.data();
  const char* last = text.data() + text.size();
  if (first != last && *first == '+' && first + 1 != last && first[1] != '-')
    ++first;  // from_chars takes a '-' but not a '+'
  long long value = 0;
  const auto [end, error] = std::from_chars(first, last, value);
  if (error == std::errc::result_out_of_range)
    ctx.fail(field, "integer out of range: " + quoted(text));
  if (error != std::errc() || end != last)
  {
    double number = 0.0;
    const bool is_number = YAML::convert<double>::decode(field.node, number);
    ctx.fail(field, is_number ? "must be an integer, got " + quoted(text) : "expected an integer, got " + quoted(text));
  }
  return value;
}

int readAtLeastOne(const Context& ctx, const Field& field)
{
  const long long value = readInteger(ctx, field);
  if (value < 1 || value > INT_MAX)
    ctx.fail(field, "must be an integer in [1, " + std::to_string(INT_MAX) + "], got " + field.node.Scalar());
  return static_cast<int>(value);
}

/// YAML 1.2 booleans only: yaml-cpp would also take yes/no/on/off/y/n, which YAML 1.2 reads as strings.
bool readBool(const Context& ctx, const Field& field)
{
  static const Keys kTrue = { "true", "True", "TRUE" };
  static const Keys kFalse = { "false", "False", "FALSE" };
  const std::string text = field.node.IsScalar() && !isQuoted(field.node) ? field.node.Scalar() : "";
  if (std::find(kTrue.begin(), kTrue.end(), text) != kTrue.end())
    return true;
  if (std::find(kFalse.begin(), kFalse.end(), text) != kFalse.end())
    return false;
  ctx.fail(field, "expected true or false, got " + describe(field.node));
}

std::string readNonEmptyString(const Context& ctx, const Field& field)
{
  if (!field.node.IsScalar())
    ctx.fail(field, "expected a string, got " + describe(field.node));
  if (field.node.Scalar().empty())
    ctx.fail(field, "must not be empty");
  return field.node.Scalar();
}

Vec3 readVec3(const Context& ctx, const Field& field)
{
  const std::vector<Field> items = requireListOfSize(ctx, field, 3, "numbers");
  return Vec3(readNumber(ctx, items[0]), readNumber(ctx, items[1]), readNumber(ctx, items[2]));
}

// --- scene parts -------------------------------------------------------------------------------

IntegratorType readIntegrator(const Context& ctx, const Field& field)
{
  const std::string name = readNonEmptyString(ctx, field);
  IntegratorType type{};
  if (!integratorFromName(name, type))
    ctx.fail(field, "unknown integrator " + quoted(name) + "; valid integrators: " + join(integratorNames()));
  return type;
}

PhysicsDef readPhysics(const Context& ctx, const Field& field)
{
  requireMap(ctx, field, kPhysicsKeys);
  PhysicsDef physics;
  if (const std::optional<Field> value = optionalKey(field, "integrator"))
    physics.integrator = readIntegrator(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "dt"))
    physics.step.dt = readPositive(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "substeps"))
    physics.step.substeps = readAtLeastOne(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "iterations"))
    physics.step.iterations = readAtLeastOne(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "gravity"))
    physics.gravity = readVec3(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "drag"))
    physics.drag = readNonNegative(ctx, *value);
  return physics;
}

NodeDef readNode(const Context& ctx, const Field& field)
{
  requireMap(ctx, field, kNodeKeys);
  NodeDef node;
  node.position = readVec3(ctx, requiredKey(ctx, field, "position"));
  node.mass = readPositive(ctx, requiredKey(ctx, field, "mass"));
  if (const std::optional<Field> value = optionalKey(field, "velocity"))
    node.velocity = readVec3(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "pinned"))
    node.pinned = readBool(ctx, *value);
  return node;
}

int readNodeIndex(const Context& ctx, const Field& field, std::size_t node_count)
{
  const long long index = readInteger(ctx, field);
  if (index < 0 || static_cast<unsigned long long>(index) >= node_count)
    ctx.fail(field, "node index " + std::to_string(index) + " out of range; the body has " +
                        std::to_string(node_count) + " nodes (0.." + std::to_string(node_count - 1) + ")");
  return static_cast<int>(index);
}

/// The `nodes` and `rest_length` keys that springs and constraints share.
template <typename LinkDef>
void readLinkEnds(const Context& ctx, const Field& field, std::size_t node_count, LinkDef& link)
{
  const Field ends = requiredKey(ctx, field, "nodes");
  const std::vector<Field> items = requireListOfSize(ctx, ends, 2, "node indices");
  link.a = readNodeIndex(ctx, items[0], node_count);
  link.b = readNodeIndex(ctx, items[1], node_count);
  if (link.a == link.b)
    ctx.fail(ends, "connects node " + std::to_string(link.a) + " to itself");
  if (const std::optional<Field> value = optionalKey(field, "rest_length"))
    link.rest_length = readNonNegative(ctx, *value);
}

SpringDef readSpring(const Context& ctx, const Field& field, std::size_t node_count)
{
  requireMap(ctx, field, kSpringKeys);
  SpringDef spring;
  readLinkEnds(ctx, field, node_count, spring);
  spring.stiffness = readPositive(ctx, requiredKey(ctx, field, "stiffness"));
  if (const std::optional<Field> value = optionalKey(field, "damping"))
    spring.damping = readNonNegative(ctx, *value);
  return spring;
}

ConstraintDef readConstraint(const Context& ctx, const Field& field, std::size_t node_count)
{
  requireMap(ctx, field, kConstraintKeys);
  ConstraintDef constraint;
  readLinkEnds(ctx, field, node_count, constraint);
  if (const std::optional<Field> value = optionalKey(field, "compliance"))
    constraint.compliance = readNonNegative(ctx, *value);
  return constraint;
}

BodyDef readCustomBody(const Context& ctx, const Field& field)
{
  requireMap(ctx, field, kCustomBodyKeys);
  BodyDef body;
  body.name = readNonEmptyString(ctx, requiredKey(ctx, field, "name"));
  body.type = "custom";
  const Field nodes = requiredKey(ctx, field, "nodes");
  for (const Field& item : requireList(ctx, nodes))
    body.nodes.push_back(readNode(ctx, item));
  if (body.nodes.empty())
    ctx.fail(nodes, "must not be empty; a body needs at least one node");
  if (const std::optional<Field> springs = optionalKey(field, "springs"))
    for (const Field& item : requireList(ctx, *springs))
      body.springs.push_back(readSpring(ctx, item, body.nodes.size()));
  if (const std::optional<Field> constraints = optionalKey(field, "constraints"))
    for (const Field& item : requireList(ctx, *constraints))
      body.constraints.push_back(readConstraint(ctx, item, body.nodes.size()));
  return body;
}

BodyDef readBody(const Context& ctx, const Field& field)
{
  requireMapping(ctx, field);
  // The type decides which other keys are allowed, so it is checked before them.
  const Field type = requiredKey(ctx, field, "type");
  const std::string name = readNonEmptyString(ctx, type);
  if (name != "custom")
    ctx.fail(type, "unknown body type " + quoted(name) + "; valid types: " + join(kBodyTypes));
  return readCustomBody(ctx, field);
}

SceneDef readScene(const Context& ctx, const Field& root)
{
  if (!root.node.IsMap())
    ctx.fail(root, "a scene must be a YAML mapping with the keys " + join(kSceneKeys) + "; got " +
                       (root.node.IsNull() ? "an empty document" : describe(root.node)));
  requireMap(ctx, root, kSceneKeys);
  SceneDef scene;
  if (const std::optional<Field> value = optionalKey(root, "frame_id"))
    scene.frame_id = readNonEmptyString(ctx, *value);
  if (const std::optional<Field> value = optionalKey(root, "physics"))
    scene.physics = readPhysics(ctx, *value);

  const Field bodies = requiredKey(ctx, root, "bodies");
  std::map<std::string, std::string> path_by_name;  // to name the first body in a duplicate error
  for (const Field& item : requireList(ctx, bodies))
  {
    scene.bodies.push_back(readBody(ctx, item));
    const std::string& name = scene.bodies.back().name;
    const auto [first, inserted] = path_by_name.emplace(name, item.path);
    if (!inserted)
      ctx.fail(requiredKey(ctx, item, "name"), "duplicate body name " + quoted(name) + " (first used by " +
                                                   first->second + ")");
  }
  if (scene.bodies.empty())
    ctx.fail(bodies, "must not be empty; a scene needs at least one body");
  return scene;
}

}  // namespace

SceneDef loadSceneFile(const std::string& path)
{
  std::ifstream file(path);
  std::string text;
  try
  {
    if (file)
      text.assign(std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
  }
  catch (const std::ios_base::failure&)  // e.g. a directory: it opens, but reading it throws
  {
    file.setstate(std::ios_base::badbit);
  }
  if (!file || file.bad())
    throw SceneError(path + ": cannot open scene file");
  return parseScene(text, path);
}

SceneDef parseScene(const std::string& yaml_text, const std::string& source)
{
  const Context ctx(source);
  std::vector<YAML::Node> documents;
  try
  {
    // All documents, not just the first: a second one would otherwise be silently ignored.
    documents = YAML::LoadAll(yaml_text);
  }
  catch (const YAML::ParserException& e)
  {
    throw SceneError(source + ":" + std::to_string(e.mark.line + 1) + ":" + std::to_string(e.mark.column + 1) +
                     ": invalid YAML: " + e.msg);
  }
  // A trailing "---" (an empty document) holds nothing that could be ignored; any other one would be.
  for (std::size_t i = 1; i < documents.size(); ++i)
    if (!documents[i].IsNull())
      ctx.fail(documents[i].Mark(), "", "found a second YAML document; a scene file holds exactly one");
  const YAML::Node root = documents.empty() ? YAML::Node() : documents.front();
  return readScene(ctx, Field{ root, "", root.Mark() });
}

}  // namespace soft_body_sim
