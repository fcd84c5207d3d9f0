#include "soft_body_sim/scene/scene_loader.h"

#include <algorithm>
#include <fstream>
#include <iterator>
#include <map>
#include <optional>
#include <set>
#include <utility>

#include "yaml_reader.h"

namespace soft_body_sim
{
namespace
{
using namespace scene_yaml;

const Keys kSceneKeys = { "frame_id", "physics", "bodies" };
const Keys kPhysicsKeys = { "integrator", "dt", "substeps", "iterations", "gravity", "drag" };
const Keys kBodyTypes = { "custom" };
const Keys kCustomBodyKeys = { "name", "type", "nodes", "springs", "constraints" };
const Keys kNodeKeys = { "position", "mass", "velocity", "pinned" };
const Keys kSpringKeys = { "nodes", "stiffness", "damping", "rest_length" };
const Keys kConstraintKeys = { "nodes", "compliance", "rest_length" };

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
