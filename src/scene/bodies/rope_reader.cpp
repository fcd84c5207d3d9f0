// `type: rope` (spring-string-tutorial.txt): a chain of equal-mass nodes, straight from `from` to `to`
// or along a `path`.
#include "scene/bodies/generated_body_keys.h"
#include "soft_body_sim/core/bodies/rope.h"

namespace soft_body_sim::scene_yaml
{
BodyDef readRopeBody(const Context& ctx, const Field& field, const SceneSoFar& scene)
{
  requireMap(ctx, field, withCommonBodyKeys({ "nodes", "from", "to", "path", "mass", "stiffness", "damping", "bending",
                                              "bending_damping", "pinned", "radius", "self_collision",
                                              "self_friction" }));
  RopeDef rope;
  const Field nodes = requiredKey(ctx, field, "nodes");
  rope.nodes = readCount(ctx, nodes, 2);
  scene.requireNodes(ctx, nodes, rope.nodes);
  if (const std::optional<Field> path = optionalKey(field, "path"))
  {
    for (const char* key : { "from", "to" })
      if (const std::optional<Field> value = optionalKey(field, key))
        ctx.fail(*value, "give either from and to, or path, not both");
    const std::vector<Field> points = requireList(ctx, *path, "a list of at least 2 points [x, y, z]");
    if (points.size() < 2)
      ctx.fail(*path, "needs at least 2 points [x, y, z]");
    for (const Field& point : points)
      rope.path.push_back(readVec3(ctx, point));
  }
  else
  {
    rope.from = readVec3(ctx, requiredKey(ctx, field, "from"));
    rope.to = readVec3(ctx, requiredKey(ctx, field, "to"));
  }
  rope.mass = readNumber(ctx, requiredKey(ctx, field, "mass"));
  rope.stiffness = readNumber(ctx, requiredKey(ctx, field, "stiffness"));
  rope.damping = 0.0;
  readOptional(ctx, field, "damping", rope.damping, readNumber);
  rope.bending = 0.0;
  readOptional(ctx, field, "bending", rope.bending, readNumber);
  rope.bending_damping = 0.0;
  readOptional(ctx, field, "bending_damping", rope.bending_damping, readNumber);
  if (const std::optional<Field> value = optionalKey(field, "pinned"))
    rope.pinned = readPinned(ctx, *value, rope.nodes);
  readOptional(ctx, field, "radius", rope.radius, readNumber);
  readSelfContact(ctx, field, rope);
  return buildBody(ctx, field, rope, buildRope);
}

}  // namespace soft_body_sim::scene_yaml
