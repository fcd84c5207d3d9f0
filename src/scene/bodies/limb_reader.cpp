// `type: limb`: one 3-particle Verlet limb of verlet-bezier-limbs.txt (see core/bodies/limb.h), and the
// limb-motion keys it shares with `humanoid`.

#include "../body_readers.h"
#include "soft_body_sim/core/bodies/limb.h"

namespace soft_body_sim::scene_yaml
{
namespace
{
const Keys kLimbKeys = { "root", "direction", "upper_length", "lower_length" };

Keys limbKeys()
{
  Keys keys = kLimbKeys;
  keys.insert(keys.end(), limbMotionKeys().begin(), limbMotionKeys().end());
  return keys;
}
}  // namespace

const Keys& limbMotionKeys()
{
  static const Keys keys = { "gravity",    "frame_period", "max_frames_per_step", "iterations",
                             "tension",    "retention",    "curve_samples" };
  return keys;
}

void readLimbMotion(const Context& ctx, const Field& body, LimbMotion& motion)
{
  if (const std::optional<Field> value = optionalKey(body, "gravity"))
    motion.gravity = readVec3(ctx, *value);
  if (const std::optional<Field> value = optionalKey(body, "frame_period"))
    motion.frame_period = readPositive(ctx, *value);
  if (const std::optional<Field> value = optionalKey(body, "max_frames_per_step"))
  {
    motion.max_frames_per_step = readPositive(ctx, *value);
    if (motion.max_frames_per_step > kMaxUpdatesPerStep)
      ctx.fail(*value, "must be in (0, " + std::to_string(kMaxUpdatesPerStep) + "], got " + value->node.Scalar());
  }
  if (const std::optional<Field> value = optionalKey(body, "iterations"))
    motion.iterations = readRelaxationPasses(ctx, *value);
  if (const std::optional<Field> value = optionalKey(body, "tension"))
  {
    motion.tension = readPositive(ctx, *value);
    if (!(motion.tension < 1.0))
      ctx.fail(*value, "must be in (0, 1) (a free link's error changes by 1 - 2 tension per pass), got " +
                           value->node.Scalar());
  }
  if (const std::optional<Field> value = optionalKey(body, "retention"))
  {
    motion.retention = readNonNegative(ctx, *value);
    if (motion.retention > 1.0)
      ctx.fail(*value, "must be in [0, 1], got " + value->node.Scalar());
  }
  if (const std::optional<Field> value = optionalKey(body, "curve_samples"))
  {
    const long long samples = readInteger(ctx, *value);
    // Every published marker carries the curve: a few dozen points draw it smoothly.
    constexpr long long kMaxCurveSamples = 10000;
    if (samples < 2 || samples > kMaxCurveSamples)
      ctx.fail(*value,
               "must be an integer in [2, " + std::to_string(kMaxCurveSamples) + "], got " + value->node.Scalar());
    motion.curve_samples = static_cast<int>(samples);
  }
}

BodyDef readLimbBody(const Context& ctx, const Field& field, const SceneSoFar& scene)
{
  requireMap(ctx, field, withCommonBodyKeys(limbKeys()));
  scene.requireNodes(ctx, field, kLimbLeaf + 1);
  LimbDef def;
  if (const std::optional<Field> value = optionalKey(field, "root"))
    def.root = readVec3(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "direction"))
  {
    def.direction = readVec3(ctx, *value);
    if (!(def.direction.norm() > 1e-12))
      ctx.fail(*value, "must not be the zero vector");
  }
  if (const std::optional<Field> value = optionalKey(field, "upper_length"))
    def.upper_length = readPositive(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "lower_length"))
    def.lower_length = readPositive(ctx, *value);
  readLimbMotion(ctx, field, def.motion);

  return buildProceduralBody(ctx, field, def, buildLimb);
}

}  // namespace soft_body_sim::scene_yaml
