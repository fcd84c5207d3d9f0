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
  if (const std::optional<Field> value = optionalKey(field, "segments"))
    tendrils.segments = readInt(ctx, *value);
  for (auto [key, target] : { std::pair{ "length", &tendrils.length }, std::pair{ "mass", &tendrils.mass },
                              std::pair{ "stiffness", &tendrils.stiffness }, std::pair{ "damping", &tendrils.damping } })
    if (const std::optional<Field> value = optionalKey(field, key))
      *target = readNumber(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "direction"))
    tendrils.direction = readVec3(ctx, *value);
  return tendrils;
}

}  // namespace

BodyDef readCreatureBody(const Context& ctx, const Field& field, const SceneSoFar& scene)
{
  requireMap(ctx, field, withCommonBodyKeys(kCreatureKeys));
  CreatureDef def;
  for (auto [key, target] : { std::pair{ "position", &def.position }, std::pair{ "heading", &def.heading },
                              std::pair{ "plane_normal", &def.plane_normal } })
    if (const std::optional<Field> value = optionalKey(field, key))
      *target = readVec3(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "target"))
    def.target = readVec3(ctx, *value);
  for (auto [key, target] : { std::pair{ "length", &def.length },
                              std::pair{ "width", &def.width },
                              std::pair{ "update_period", &def.update_period },
                              std::pair{ "stiffness", &def.stiffness },
                              std::pair{ "lead_retention", &def.lead_retention },
                              std::pair{ "anticipation", &def.anticipation },
                              std::pair{ "settle_tolerance", &def.settle_tolerance },
                              std::pair{ "parallel_retention", &def.parallel_retention },
                              std::pair{ "perpendicular_retention", &def.perpendicular_retention },
                              std::pair{ "side_retention", &def.side_retention },
                              std::pair{ "min_ratio", &def.min_ratio },
                              std::pair{ "max_ratio", &def.max_ratio },
                              std::pair{ "soft_strength", &def.soft_strength },
                              std::pair{ "hard_strength", &def.hard_strength } })
    if (const std::optional<Field> value = optionalKey(field, key))
      *target = readNumber(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "iterations"))
    def.iterations = readInt(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "tendrils"))
  {
    def.tendrils = readTendrils(ctx, *value);
    scene.requireNodes(ctx, firstPresent(*value, { "segments" }),
                       kCreatureBodyPoints + 2LL * std::max(0, def.tendrils->segments));
  }
  else
  {
    scene.requireNodes(ctx, field, kCreatureBodyPoints);
  }

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
