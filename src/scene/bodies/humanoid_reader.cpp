// `type: humanoid`: a torso following a target with four Bezier limbs (see core/bodies/humanoid.h).
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
  readOptional(ctx, field, "position", def.position, readVec3);
  readOptional(ctx, field, "target", def.target, readVec3);
  readOptional(ctx, field, "up", def.up, readVec3);
  readOptional(ctx, field, "facing", def.facing, readVec3);
  readOptional(ctx, field, "torso_length", def.torso_length, readNumber);
  readOptional(ctx, field, "head_height", def.head_height, readNumber);
  readOptional(ctx, field, "shoulder_width", def.shoulder_width, readNumber);
  readOptional(ctx, field, "hip_width", def.hip_width, readNumber);
  readOptional(ctx, field, "arm_length", def.arm_length, readNumber);
  readOptional(ctx, field, "leg_length", def.leg_length, readNumber);
  readOptional(ctx, field, "torso_stiffness", def.torso_stiffness, readNumber);
  readOptional(ctx, field, "torso_retention", def.torso_retention, readNumber);
  readLimbMotion(ctx, field, def.limbs);

  return buildBody(ctx, field, def, buildHumanoid);
}

}  // namespace soft_body_sim::scene_yaml
