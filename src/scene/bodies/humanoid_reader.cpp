// `type: humanoid`: a torso following a target with four Bezier limbs (see core/bodies/humanoid.h).
#include <iterator>

#include <Eigen/Geometry>  // cross products

#include "../body_readers.h"
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

Vec3 readNonZeroVec3(const Context& ctx, const Field& field)
{
  const Vec3 value = readVec3(ctx, field);
  if (!(value.norm() > 1e-12))
    ctx.fail(field, "must not be the zero vector");
  return value;
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
    def.up = readNonZeroVec3(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "facing"))
  {
    def.facing = readNonZeroVec3(ctx, *value);
    if (!(def.up.normalized().cross(def.facing.normalized()).norm() > 1e-9))
      ctx.fail(*value, "must not be parallel to up");
  }
  double* const lengths[] = { &def.torso_length, &def.head_height, &def.shoulder_width,
                              &def.hip_width,    &def.arm_length,  &def.leg_length };
  const char* const length_keys[] = { "torso_length", "head_height", "shoulder_width",
                                      "hip_width",    "arm_length",  "leg_length" };
  for (std::size_t k = 0; k < std::size(lengths); ++k)
    if (const std::optional<Field> value = optionalKey(field, length_keys[k]))
      *lengths[k] = readPositive(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "torso_stiffness"))
    def.torso_stiffness = readNonNegative(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "torso_retention"))
  {
    def.torso_retention = readNonNegative(ctx, *value);
    if (def.torso_retention > 1.0)
      ctx.fail(*value, "must be in [0, 1], got " + value->node.Scalar());
  }
  readLimbMotion(ctx, field, def.limbs);

  const double k_t2 = def.torso_stiffness * def.limbs.frame_period * def.limbs.frame_period;
  if (!(k_t2 < 2.0 * (1.0 + def.torso_retention)))
  {
    Field at = field;
    for (const char* key : { "torso_stiffness", "frame_period", "torso_retention" })
      if (const std::optional<Field> value = optionalKey(field, key))
      {
        at = *value;
        break;
      }
    ctx.fail(at, "torso_stiffness * frame_period^2 = " + std::to_string(k_t2) +
                     " must be < 2 (1 + torso_retention) for the torso's recurrence to be stable");
  }

  return buildProceduralBody(ctx, field, def, buildHumanoid);
}

}  // namespace soft_body_sim::scene_yaml
