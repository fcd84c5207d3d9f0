// `type: rope` (spring-string-tutorial.txt): a straight chain of equal-mass nodes from `from` to `to`.
#include "generated_body_keys.h"
#include "soft_body_sim/core/bodies/rope.h"

namespace soft_body_sim::scene_yaml
{
BodyDef readRopeBody(const Context& ctx, const Field& field, const SceneSoFar& scene)
{
  requireMap(ctx, field, withCommonBodyKeys({ "nodes", "from", "to", "mass", "stiffness", "damping", "bending",
                                              "bending_damping", "pinned" }));
  RopeDef rope;
  const Field nodes = requiredKey(ctx, field, "nodes");
  rope.nodes = readCount(ctx, nodes, 2);
  scene.requireNodes(ctx, nodes, rope.nodes);
  rope.from = readVec3(ctx, requiredKey(ctx, field, "from"));
  const Field to = requiredKey(ctx, field, "to");
  rope.to = readVec3(ctx, to);
  if (!((rope.to - rope.from).norm() > 0.0))
    ctx.fail(to, "must differ from 'from'; a rope needs a length");
  rope.mass = readPositive(ctx, requiredKey(ctx, field, "mass"));
  rope.stiffness = readPositive(ctx, requiredKey(ctx, field, "stiffness"));
  rope.damping = 0.0;
  if (const std::optional<Field> value = optionalKey(field, "damping"))
    rope.damping = readNonNegative(ctx, *value);
  rope.bending = 0.0;
  if (const std::optional<Field> value = optionalKey(field, "bending"))
    rope.bending = readNonNegative(ctx, *value);
  rope.bending_damping = 0.0;
  if (const std::optional<Field> value = optionalKey(field, "bending_damping"))
  {
    rope.bending_damping = readNonNegative(ctx, *value);
    if (!(rope.bending > 0.0))
      ctx.fail(*value, "has no effect without bending > 0 (there are no bending springs to damp)");
  }
  if (const std::optional<Field> value = optionalKey(field, "pinned"))
    rope.pinned = readPinned(ctx, *value, rope.nodes);
  return buildRope("rope", rope);
}

}  // namespace soft_body_sim::scene_yaml
