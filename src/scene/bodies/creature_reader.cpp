// `type: creature`: the codeling of fuzzy-physics-constraints.txt (see core/bodies/creature.h).
#include <sstream>

#include "scene/body_readers.h"
#include "soft_body_sim/core/bodies/creature.h"

namespace soft_body_sim::scene_yaml
{
namespace
{
const Keys kCreatureKeys = { "position",      "heading",        "plane_normal",       "target",
                             "length",        "width",          "update_period",      "stiffness",
                             "lead_retention", "anticipation",  "parallel_retention", "perpendicular_retention",
                             "side_retention", "min_ratio",     "max_ratio",          "soft_strength",
                             "hard_strength",  "iterations",    "tendrils",           "settle_tolerance" };
const Keys kTendrilKeys = { "segments", "length", "mass", "stiffness", "damping", "direction" };

TendrilDef readTendrils(const Context& ctx, const Field& field)
{
  requireMap(ctx, field, kTendrilKeys);
  TendrilDef tendrils;
  readOptional(ctx, field, "segments", tendrils.segments, readInt);
  readOptional(ctx, field, "length", tendrils.length, readNumber);
  readOptional(ctx, field, "mass", tendrils.mass, readNumber);
  readOptional(ctx, field, "stiffness", tendrils.stiffness, readNumber);
  readOptional(ctx, field, "damping", tendrils.damping, readNumber);
  readOptional(ctx, field, "direction", tendrils.direction, readVec3);
  return tendrils;
}

}  // namespace

BodyDef readCreatureBody(const Context& ctx, const Field& field, const SceneSoFar& scene)
{
  requireMap(ctx, field, withCommonBodyKeys(kCreatureKeys));
  CreatureDef def;
  readOptional(ctx, field, "position", def.position, readVec3);
  readOptional(ctx, field, "heading", def.heading, readVec3);
  readOptional(ctx, field, "plane_normal", def.plane_normal, readVec3);
  readOptional(ctx, field, "target", def.target, readVec3);
  readOptional(ctx, field, "length", def.length, readNumber);
  readOptional(ctx, field, "width", def.width, readNumber);
  readOptional(ctx, field, "update_period", def.update_period, readNumber);
  readOptional(ctx, field, "stiffness", def.stiffness, readNumber);
  readOptional(ctx, field, "lead_retention", def.lead_retention, readNumber);
  readOptional(ctx, field, "anticipation", def.anticipation, readNumber);
  readOptional(ctx, field, "settle_tolerance", def.settle_tolerance, readNumber);
  readOptional(ctx, field, "parallel_retention", def.parallel_retention, readNumber);
  readOptional(ctx, field, "perpendicular_retention", def.perpendicular_retention, readNumber);
  readOptional(ctx, field, "side_retention", def.side_retention, readNumber);
  readOptional(ctx, field, "min_ratio", def.min_ratio, readNumber);
  readOptional(ctx, field, "max_ratio", def.max_ratio, readNumber);
  readOptional(ctx, field, "soft_strength", def.soft_strength, readNumber);
  readOptional(ctx, field, "hard_strength", def.hard_strength, readNumber);
  readOptional(ctx, field, "iterations", def.iterations, readInt);
  readOptional(ctx, field, "tendrils", def.tendrils, readTendrils);
  // Without tendrils, the count is the body's alone and an error points at the body.
  scene.requireNodes(ctx, firstPresent(field, { "tendrils.segments", "tendrils" }),
                     kCreatureBodyPoints + (def.tendrils ? 2LL * std::max(0, def.tendrils->segments) : 0LL));

  // The creature makes every update due in a step, however many (a `dt: auto` step is only known when the
  // world is built, so only a given dt is checked): a check of the body against the scene's physics.
  const double updates_per_step = scene.physics.step.dt / def.update_period;
  if (!scene.physics.auto_dt && def.update_period > 0.0 && updates_per_step > kMaxUpdatesPerStep)
  {
    std::ostringstream updates;  // 6 significant digits, an exponent for large values
    updates << updates_per_step;
    ctx.fail(firstPresent(field, { "update_period" }), "physics.dt / update_period = " + updates.str() +
                                                           " updates per physics step, more than " +
                                                           std::to_string(kMaxUpdatesPerStep));
  }
  return buildBody(ctx, field, def, buildCreature);
}

}  // namespace soft_body_sim::scene_yaml
