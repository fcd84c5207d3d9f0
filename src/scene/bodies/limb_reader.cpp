// `type: limb`: one 3-particle Verlet limb of verlet-bezier-limbs.txt (see core/bodies/limb.h), and the
// limb-motion keys it shares with `humanoid`.

#include "scene/body_readers.h"
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
  for (auto [key, target] : { std::pair{ "frame_period", &motion.frame_period },
                              std::pair{ "max_frames_per_step", &motion.max_frames_per_step },
                              std::pair{ "tension", &motion.tension }, std::pair{ "retention", &motion.retention } })
    if (const std::optional<Field> value = optionalKey(body, key))
      *target = readNumber(ctx, *value);
  for (auto [key, target] : { std::pair{ "iterations", &motion.iterations },
                              std::pair{ "curve_samples", &motion.curve_samples } })
    if (const std::optional<Field> value = optionalKey(body, key))
      *target = readInt(ctx, *value);
}

BodyDef readLimbBody(const Context& ctx, const Field& field, const SceneSoFar& scene)
{
  requireMap(ctx, field, withCommonBodyKeys(limbKeys()));
  scene.requireNodes(ctx, field, kLimbLeaf + 1);
  LimbDef def;
  if (const std::optional<Field> value = optionalKey(field, "root"))
    def.root = readVec3(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "direction"))
    def.direction = readVec3(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "upper_length"))
    def.upper_length = readNumber(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "lower_length"))
    def.lower_length = readNumber(ctx, *value);
  readLimbMotion(ctx, field, def.motion);

  return buildBody(ctx, field, def, buildLimb);
}

}  // namespace soft_body_sim::scene_yaml
