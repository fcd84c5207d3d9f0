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
  readOptional(ctx, body, "gravity", motion.gravity, readVec3);
  readOptional(ctx, body, "frame_period", motion.frame_period, readNumber);
  readOptional(ctx, body, "max_frames_per_step", motion.max_frames_per_step, readNumber);
  readOptional(ctx, body, "tension", motion.tension, readNumber);
  readOptional(ctx, body, "retention", motion.retention, readNumber);
  readOptional(ctx, body, "iterations", motion.iterations, readInt);
  readOptional(ctx, body, "curve_samples", motion.curve_samples, readInt);
}

BodyDef readLimbBody(const Context& ctx, const Field& field, const SceneSoFar& scene)
{
  requireMap(ctx, field, withCommonBodyKeys(limbKeys()));
  scene.requireNodes(ctx, field, kLimbLeaf + 1);
  LimbDef def;
  readOptional(ctx, field, "root", def.root, readVec3);
  readOptional(ctx, field, "direction", def.direction, readVec3);
  readOptional(ctx, field, "upper_length", def.upper_length, readNumber);
  readOptional(ctx, field, "lower_length", def.lower_length, readNumber);
  readLimbMotion(ctx, field, def.motion);

  return buildBody(ctx, field, def, buildLimb);
}

}  // namespace soft_body_sim::scene_yaml
