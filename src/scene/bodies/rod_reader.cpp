// `type: rod`: a cable, hose or wire by its material (bodies/rod.h), straight from `from` to `to`.
#include "scene/bodies/generated_body_keys.h"
#include "soft_body_sim/core/bodies/rod.h"

namespace soft_body_sim::scene_yaml
{
BodyDef readRodBody(const Context& ctx, const Field& field, const SceneSoFar& scene)
{
  requireMap(ctx, field, withCommonBodyKeys({ "nodes", "from", "to", "radius", "youngs_modulus", "shear_modulus",
                                              "density", "damping", "clamped", "end_moment", "self_collision", "self_friction" }));
  RodDef rod;
  const Field nodes = requiredKey(ctx, field, "nodes");
  rod.nodes = readCount(ctx, nodes, 2);
  scene.requireNodes(ctx, nodes, rod.nodes);
  rod.from = readVec3(ctx, requiredKey(ctx, field, "from"));
  rod.to = readVec3(ctx, requiredKey(ctx, field, "to"));
  rod.radius = readNumber(ctx, requiredKey(ctx, field, "radius"));
  rod.youngs_modulus = readNumber(ctx, requiredKey(ctx, field, "youngs_modulus"));
  readOptional(ctx, field, "shear_modulus", rod.shear_modulus, readNumber);
  rod.density = readNumber(ctx, requiredKey(ctx, field, "density"));
  readOptional(ctx, field, "damping", rod.damping, readNumber);
  if (const std::optional<Field> value = optionalKey(field, "clamped"))
    rod.clamped = readPinned(ctx, *value, rod.nodes);
  readOptional(ctx, field, "end_moment", rod.end_moment, readVec3);
  readSelfContact(ctx, field, rod);
  return buildBody(ctx, field, rod, buildRod);
}

}  // namespace soft_body_sim::scene_yaml
