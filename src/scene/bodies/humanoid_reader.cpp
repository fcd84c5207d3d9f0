// `type: humanoid`: a torso following a target with four Bezier limbs (see core/bodies/humanoid.h).
#include <iterator>

#include <Eigen/Geometry>  // cross products

#include "scene/body_readers.h"
#include "soft_body_sim/core/bodies/humanoid.h"

namespace soft_body_sim::scene_yaml
{
namespace
{
const Keys kHumanoidKeys = { "position",       "target",     "up",          "facing",
                             "torso_length",   "head_height", "shoulder_width", "hip_width",
                             "arm_length",     "leg_length",  "torso_stiffness", "torso_retention" };

Keys humanoidKeys()
{
  Keys keys = kHumanoidKeys;
  keys.insert(keys.end(), limbMotionKeys().begin(), limbMotionKeys().end());
  return keys;
}
}  // namespace

BodyDef readHumanoidBody(const Context& ctx, const Field& field, const SceneSoFar& scene)
{
  requireMap(ctx, field, withCommonBodyKeys(humanoidKeys()));
  scene.requireNodes(ctx, field, kHumanoidNodes);
  HumanoidDef def;
  if (const std::optional<Field> value = optionalKey(field, "position"))
    def.position = readVec3(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "target"))
    def.target = readVec3(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "up"))
    def.up = readVec3(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "facing"))
    def.facing = readVec3(ctx, *value);
  double* const lengths[] = { &def.torso_length, &def.head_height, &def.shoulder_width,
                              &def.hip_width,    &def.arm_length,  &def.leg_length };
  const char* const length_keys[] = { "torso_length", "head_height", "shoulder_width",
                                      "hip_width",    "arm_length",  "leg_length" };
  for (std::size_t k = 0; k < std::size(lengths); ++k)
    if (const std::optional<Field> value = optionalKey(field, length_keys[k]))
      *lengths[k] = readNumber(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "torso_stiffness"))
    def.torso_stiffness = readNumber(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "torso_retention"))
    def.torso_retention = readNumber(ctx, *value);
  readLimbMotion(ctx, field, def.limbs);

  return buildBody(ctx, field, def, buildHumanoid);
}

}  // namespace soft_body_sim::scene_yaml
