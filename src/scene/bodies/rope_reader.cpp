// `type: rope` (spring-string-tutorial.txt): a straight chain of equal-mass nodes from `from` to `to`.
#include "generated_body_keys.h"
#include "soft_body_sim/core/bodies/rope.h"

namespace soft_body_sim::scene_yaml
{
BodyDef readRopeBody(const Context& ctx, const Field& field, const SceneSoFar& scene)
{
  requireMap(ctx, field, withCommonBodyKeys({ "nodes", "from", "to", "mass", "stiffness", "damping", "bending",
                                              "bending_damping", "pinned", "radius", "self_collision" }));
  RopeDef rope;
  const Field nodes = requiredKey(ctx, field, "nodes");
  rope.nodes = readCount(ctx, nodes, 2);
  scene.requireNodes(ctx, nodes, rope.nodes);
  rope.from = readVec3(ctx, requiredKey(ctx, field, "from"));
  rope.to = readVec3(ctx, requiredKey(ctx, field, "to"));
  rope.mass = readNumber(ctx, requiredKey(ctx, field, "mass"));
  rope.stiffness = readNumber(ctx, requiredKey(ctx, field, "stiffness"));
  rope.damping = 0.0;
  if (const std::optional<Field> value = optionalKey(field, "damping"))
    rope.damping = readNumber(ctx, *value);
  rope.bending = 0.0;
  if (const std::optional<Field> value = optionalKey(field, "bending"))
    rope.bending = readNumber(ctx, *value);
  rope.bending_damping = 0.0;
  if (const std::optional<Field> value = optionalKey(field, "bending_damping"))
    rope.bending_damping = readNumber(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "pinned"))
    rope.pinned = readPinned(ctx, *value, rope.nodes);
  if (const std::optional<Field> value = optionalKey(field, "radius"))
    rope.radius = readNumber(ctx, *value);
  bool self_collision = false;
  if (const std::optional<Field> value = optionalKey(field, "self_collision"))
  {
    self_collision = readBool(ctx, *value);
    if (self_collision && !(rope.radius > 0.0))
      ctx.fail(*value, "needs radius > 0: links without thickness cannot keep apart");
  }
  BodyDef body = buildBody(ctx, field, rope, buildRope);
  body.self_collision = self_collision;
  return body;
}

}  // namespace soft_body_sim::scene_yaml
