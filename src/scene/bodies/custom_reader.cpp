// `type: custom`: nodes, springs and constraints listed one by one.
#include "scene/body_readers.h"

namespace soft_body_sim::scene_yaml
{
namespace
{
const Keys kNodeKeys = { "position", "mass", "velocity", "pinned" };
const Keys kSpringKeys = { "nodes", "stiffness", "damping", "rest_length" };
const Keys kConstraintKeys = { "nodes", "compliance", "rest_length" };

NodeDef readNode(const Context& ctx, const Field& field)
{
  requireMap(ctx, field, kNodeKeys);
  NodeDef node;
  node.position = readVec3(ctx, requiredKey(ctx, field, "position"));
  node.mass = readPositive(ctx, requiredKey(ctx, field, "mass"));
  readOptional(ctx, field, "velocity", node.velocity, readVec3);
  readOptional(ctx, field, "pinned", node.pinned, readBool);
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
  readOptional(ctx, field, "rest_length", link.rest_length, readNonNegative);
}

SpringDef readSpring(const Context& ctx, const Field& field, std::size_t node_count)
{
  requireMap(ctx, field, kSpringKeys);
  SpringDef spring;
  readLinkEnds(ctx, field, node_count, spring);
  spring.stiffness = readPositive(ctx, requiredKey(ctx, field, "stiffness"));
  readOptional(ctx, field, "damping", spring.damping, readNonNegative);
  return spring;
}

ConstraintDef readConstraint(const Context& ctx, const Field& field, std::size_t node_count)
{
  requireMap(ctx, field, kConstraintKeys);
  ConstraintDef constraint;
  readLinkEnds(ctx, field, node_count, constraint);
  readOptional(ctx, field, "compliance", constraint.compliance, readNonNegative);
  return constraint;
}

}  // namespace

BodyDef readCustomBody(const Context& ctx, const Field& field, const SceneSoFar& scene)
{
  requireMap(ctx, field, withCommonBodyKeys({ "nodes", "springs", "constraints", "radius" }));
  BodyDef body;  // a custom body is its own definition: BodyDef's type is "custom"
  body.name = readNonEmptyString(ctx, requiredKey(ctx, field, "name"));
  const Field nodes = requiredKey(ctx, field, "nodes");
  const std::vector<Field> items = requireList(ctx, nodes);
  scene.requireNodes(ctx, nodes, static_cast<long long>(items.size()));
  for (const Field& item : items)
    body.nodes.push_back(readNode(ctx, item));
  if (body.nodes.empty())
    ctx.fail(nodes, "must not be empty; a body needs at least one node");
  if (const std::optional<Field> springs = optionalKey(field, "springs"))
    for (const Field& item : requireList(ctx, *springs))
      body.springs.push_back(readSpring(ctx, item, body.nodes.size()));
  if (const std::optional<Field> constraints = optionalKey(field, "constraints"))
    for (const Field& item : requireList(ctx, *constraints))
      body.constraints.push_back(readConstraint(ctx, item, body.nodes.size()));
  readOptional(ctx, field, "radius", body.contact_radius, readNonNegative);
  return body;
}

}  // namespace soft_body_sim::scene_yaml
