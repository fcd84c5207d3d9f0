// `type: creature`: the codeling of fuzzy-physics-constraints.txt (see core/bodies/creature.h).
#include <sstream>

#include "../body_readers.h"
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

/// A number in [0, 1].
double readFraction(const Context& ctx, const Field& field)
{
  const double value = readNonNegative(ctx, field);
  if (value > 1.0)
    ctx.fail(field, "must be in [0, 1], got " + field.node.Scalar());
  return value;
}

/// A number in (0, 1].
double readStrength(const Context& ctx, const Field& field)
{
  const double value = readPositive(ctx, field);
  if (value > 1.0)
    ctx.fail(field, "must be in (0, 1], got " + field.node.Scalar());
  return value;
}

Vec3 readNonZeroVec3(const Context& ctx, const Field& field)
{
  const Vec3 value = readVec3(ctx, field);
  if (!(value.norm() > 1e-12))
    ctx.fail(field, "must not be the zero vector");
  return value;
}

TendrilDef readTendrils(const Context& ctx, const Field& field)
{
  requireMap(ctx, field, kTendrilKeys);
  TendrilDef tendrils;
  if (const std::optional<Field> value = optionalKey(field, "segments"))
  {
    const long long segments = readInteger(ctx, *value);
    if (segments < 1 || segments > kMaxSceneNodes / 2)  // two tendrils
      ctx.fail(*value, "must be an integer in [1, " + std::to_string(kMaxSceneNodes / 2) + "], got " +
                           value->node.Scalar());
    tendrils.segments = static_cast<int>(segments);
  }
  if (const std::optional<Field> value = optionalKey(field, "length"))
    tendrils.length = readPositive(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "mass"))
    tendrils.mass = readPositive(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "stiffness"))
    tendrils.stiffness = readPositive(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "damping"))
    tendrils.damping = readNonNegative(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "direction"))
    tendrils.direction = readNonZeroVec3(ctx, *value);
  return tendrils;
}

/// The field an error about several keys points at: the first of `keys` present, else the body.
Field firstPresent(const Field& body, const Keys& keys)
{
  for (const std::string& key : keys)
    if (const std::optional<Field> value = optionalKey(body, key))
      return *value;
  return body;
}

}  // namespace

BodyDef readCreatureBody(const Context& ctx, const Field& field, const SceneSoFar& scene)
{
  requireMap(ctx, field, withCommonBodyKeys(kCreatureKeys));
  CreatureDef def;
  if (const std::optional<Field> value = optionalKey(field, "position"))
    def.position = readVec3(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "heading"))
    def.heading = readNonZeroVec3(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "plane_normal"))
    def.plane_normal = readNonZeroVec3(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "target"))
    def.target = readVec3(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "length"))
    def.length = readPositive(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "width"))
    def.width = readPositive(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "update_period"))
    def.update_period = readPositive(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "stiffness"))
    def.stiffness = readNonNegative(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "lead_retention"))
    def.lead_retention = readFraction(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "anticipation"))
    def.anticipation = readNonNegative(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "settle_tolerance"))
    def.settle_tolerance = readPositive(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "parallel_retention"))
    def.parallel_retention = readFraction(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "perpendicular_retention"))
    def.perpendicular_retention = readFraction(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "side_retention"))
    def.side_retention = readFraction(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "min_ratio"))
    def.min_ratio = readStrength(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "max_ratio"))
  {
    def.max_ratio = readNumber(ctx, *value);
    if (def.max_ratio < 1.0)
      ctx.fail(*value, "must be >= 1, got " + value->node.Scalar());
  }
  if (const std::optional<Field> value = optionalKey(field, "soft_strength"))
    def.soft_strength = readStrength(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "hard_strength"))
    def.hard_strength = readStrength(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "iterations"))
    def.iterations = readRelaxationPasses(ctx, *value);
  if (const std::optional<Field> value = optionalKey(field, "tendrils"))
  {
    def.tendrils = readTendrils(ctx, *value);
    scene.requireNodes(ctx, firstPresent(*value, { "segments" }), kCreatureBodyPoints + 2LL * def.tendrils->segments);
  }
  else
  {
    scene.requireNodes(ctx, field, kCreatureBodyPoints);
  }

  // Checks across keys, pointed at the first of the keys involved that the file sets.
  const double k_t2 = def.stiffness * def.update_period * def.update_period;
  if (!(k_t2 < 2.0 * (1.0 + def.lead_retention)))
    ctx.fail(firstPresent(field, { "stiffness", "update_period", "lead_retention" }),
             "stiffness * update_period^2 = " + std::to_string(k_t2) + " must be < 2 (1 + lead_retention) = " +
                 std::to_string(2.0 * (1.0 + def.lead_retention)) + " for the lead's recurrence to be stable");
  // The creature makes every update due in a step, however many (a `dt: auto` step is only known when the
  // world is built, so only a given dt is checked).
  const double updates_per_step = scene.physics.step.dt / def.update_period;
  if (!scene.physics.auto_dt && updates_per_step > kMaxUpdatesPerStep)
  {
    std::ostringstream updates;  // 6 significant digits, an exponent for large values
    updates << updates_per_step;
    ctx.fail(firstPresent(field, { "update_period" }), "physics.dt / update_period = " + updates.str() +
                                                           " updates per physics step, more than " +
                                                           std::to_string(kMaxUpdatesPerStep));
  }
  const Vec3 normal = def.plane_normal.normalized();
  if (!((def.heading - normal * normal.dot(def.heading)).norm() > 1e-9 * def.heading.norm()))
    ctx.fail(firstPresent(field, { "heading", "plane_normal" }),
             "heading must not be parallel to plane_normal (the spine lies in the swimming plane)");

  return buildProceduralBody(ctx, field, def, buildCreature);
}

}  // namespace soft_body_sim::scene_yaml
