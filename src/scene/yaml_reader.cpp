#include "scene/yaml_reader.h"

#include <algorithm>
#include <charconv>
#include <climits>
#include <cmath>
#include <optional>
#include <set>
#include <istream>
#include <streambuf>

#include <yaml-cpp/eventhandler.h>

namespace soft_body_sim::scene_yaml
{
namespace
{
/// yaml-cpp gives quoted scalars the tag "!" and plain ones "?"; a quoted "1.5" is a string in YAML.
bool isQuoted(const YAML::Node& node) { return node.Tag() == "!"; }

/// Where the last document of a stream started and the mark of its root node unless that is null,
/// from the parser's events, without building the document. The first document's events also go to
/// `first`.
class DocumentOutline : public YAML::EventHandler
{
public:
  YAML::Mark start;
  std::optional<YAML::Mark> root;

  explicit DocumentOutline(YAML::EventHandler& first) : first_(&first) {}

  void OnDocumentStart(const YAML::Mark& mark) override
  {
    start = mark;
    root.reset();
    if (first_)
      first_->OnDocumentStart(mark);
  }
  void OnDocumentEnd() override
  {
    if (first_)
      first_->OnDocumentEnd();
    first_ = nullptr;
  }
  void OnNull(const YAML::Mark& mark, YAML::anchor_t anchor) override
  {
    if (first_)
      first_->OnNull(mark, anchor);
  }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t anchor) override
  {
    node(mark);
    if (first_)
      first_->OnAlias(mark, anchor);
  }
  void OnScalar(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t anchor,
                const std::string& value) override
  {
    node(mark);
    if (first_)
      first_->OnScalar(mark, tag, anchor, value);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t anchor,
                       YAML::EmitterStyle::value style) override
  {
    node(mark);
    if (first_)
      first_->OnSequenceStart(mark, tag, anchor, style);
  }
  void OnSequenceEnd() override
  {
    if (first_)
      first_->OnSequenceEnd();
  }
  void OnMapStart(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t anchor,
                  YAML::EmitterStyle::value style) override
  {
    node(mark);
    if (first_)
      first_->OnMapStart(mark, tag, anchor, style);
  }
  void OnMapEnd() override
  {
    if (first_)
      first_->OnMapEnd();
  }

private:
  /// The first node of a document is its root; the others are inside it.
  void node(const YAML::Mark& mark)
  {
    if (!root)
      root = mark;
  }

  YAML::EventHandler* first_;  ///< until the first document ends
};

/// `text` as an input stream without the copy std::istringstream makes of it (a scene file may be
/// kMaxSceneFileBytes). The parser only reads it.
class TextStream : private std::streambuf, public std::istream
{
public:
  explicit TextStream(const std::string& text) : std::istream(static_cast<std::streambuf*>(this))
  {
    char* const begin = const_cast<char*>(text.data());
    setg(begin, begin, begin + text.size());
  }
};

/// `reason` may quote the input (yaml-cpp's "unknown escape character: <the character>").
[[noreturn]] void failInvalid(const Context& ctx, const YAML::Mark& mark, const std::string& reason)
{
  throw SceneError(escapeControlCharacters(ctx.source() + ":" + std::to_string(mark.line + 1) + ":" +
                                           std::to_string(mark.column + 1) + ": invalid YAML: " + reason));
}
}  // namespace

// --- the document ------------------------------------------------------------------------------

/// YAML::LoadAll is not used: yaml-cpp 0.7 never returns from it on a token that cannot start a node,
/// such as a stray ',' at the top level (jbeder/yaml-cpp#1040; fixed by #1319 in 2024, after 0.8.0). Its
/// parser then reports an empty document without consuming the token, again and again, and LoadAll
/// collects them until memory runs out. So the stream is first walked document by document, stopping at
/// the first document that starts where the one before started; the first document is then built alone.
YAML::Node loadSingleDocument(const Context& ctx, const std::string& text, YAML::EventHandler& scan)
{
  try
  {
    TextStream stream(text);
    YAML::Parser parser(stream);
    DocumentOutline outline(scan);
    std::optional<YAML::Mark> previous_start;
    for (; parser.HandleNextDocument(outline); previous_start = outline.start)
    {
      if (previous_start && outline.start.pos == previous_start->pos)
      {
        const std::size_t at = static_cast<std::size_t>(std::max(outline.start.pos, 0));
        const bool printable_ascii = at < text.size() && text[at] > ' ' && text[at] < 0x7f;
        failInvalid(ctx, outline.start,
                    printable_ascii ? "unexpected " + quoted(text.substr(at, 1)) : "unexpected token");
      }
      // A trailing "---" (an empty document) holds nothing that could be ignored; any other one would be.
      if (previous_start && outline.root)
        ctx.fail(*outline.root, "", "found a second YAML document; a scene file holds exactly one");
    }
    TextStream document(text);
    return YAML::Load(document);
  }
  catch (const YAML::ParserException& e)
  {
    failInvalid(ctx, e.mark, e.msg);
  }
}

std::string join(const Keys& words)
{
  std::string out;
  for (const std::string& word : words)
    out += (out.empty() ? "" : ", ") + word;
  return out;
}

std::string escapeControlCharacters(const std::string& text)
{
  std::string out;
  for (const char c : text)
  {
    if (c == '\n')
      out += "\\n";
    else if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
      out += '?';
    else
      out += c;
  }
  return out;
}

/// User text made safe for a one-line message: control characters escaped, long text shortened.
std::string printable(const std::string& text)
{
  constexpr std::size_t kMaxLength = 60;
  const std::string out = escapeControlCharacters(text.substr(0, kMaxLength));
  return text.size() > kMaxLength ? out + "..." : out;
}

std::string quoted(const std::string& text) { return "'" + printable(text) + "'"; }

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

std::string childPath(const std::string& parent, const std::string& key)
{
  return parent.empty() ? key : parent + "." + key;
}

// --- structure ---------------------------------------------------------------------------------

void requireMapping(const Context& ctx, const Field& field)
{
  if (!field.node.IsMap())
    ctx.fail(field, "expected a mapping, got " + describe(field.node));
  // yaml-cpp reads a merge key as a key named "<<": without this, `{<<: *rope, name: b}` would fail on
  // a missing `type` or an unknown key '<<', neither of which says what is wrong.
  for (const auto& entry : field.node)
    if (entry.first.IsScalar() && !isQuoted(entry.first) && entry.first.Scalar() == "<<")
      ctx.fail(entry.first.Mark(), childPath(field.path, "<<"),
               "YAML merge keys are not supported; write the keys out (an alias *name may stand for a whole value)");
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

std::vector<Field> requireList(const Context& ctx, const Field& field, const std::string& expected)
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

int readInt(const Context& ctx, const Field& field)
{
  const long long value = readInteger(ctx, field);
  if (value < INT_MIN || value > INT_MAX)
    ctx.fail(field, "integer out of range: " + quoted(field.node.Scalar()));
  return static_cast<int>(value);
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

Vec3 readColor(const Context& ctx, const Field& field)
{
  const Vec3 color = readVec3(ctx, field);
  if (!((color.array() >= 0.0).all() && (color.array() <= 1.0).all()))
    ctx.fail(field, "a color is [r, g, b], each from 0 to 1");
  return color;
}

int readNodeIndex(const Context& ctx, const Field& field, std::size_t node_count)
{
  const long long index = readInteger(ctx, field);
  if (index < 0 || static_cast<unsigned long long>(index) >= node_count)
    ctx.fail(field, "node index " + std::to_string(index) + " out of range; the body has " +
                        std::to_string(node_count) + " nodes (0.." + std::to_string(node_count - 1) + ")");
  return static_cast<int>(index);
}

}  // namespace soft_body_sim::scene_yaml
