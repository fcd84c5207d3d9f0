// The readers of each body type. A reader gets a body mapping whose `type` it owns, checks the keys
// (its own plus the common ones: name, type, anchors) and returns the body expanded into nodes,
// springs and constraints (plus a controller for procedural bodies). The loader then fills in the
// name and type and reads the anchors, whose node indices refer to the expanded body.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "soft_body_sim/core/controller.h"
#include "soft_body_sim/core/scene_def.h"
#include "yaml_reader.h"

namespace soft_body_sim
{
struct LimbMotion;
}

namespace soft_body_sim::scene_yaml
{
/// A node index of a body of `node_count` nodes, a negative one counting from the end (-1 is the last
/// node), made non-negative (resolveNodeIndex); one outside the body fails at the field.
inline int readNodeIndex(const Context& ctx, const Field& field, int node_count)
{
  const long long index = readInteger(ctx, field);
  const long long n = node_count;
  if (index < -n || index >= n)
    ctx.fail(field, "node index " + std::to_string(index) + " out of range; the body has " + std::to_string(n) +
                        " nodes (" + std::to_string(-n) + ".." + std::to_string(n - 1) + ")");
  return resolveNodeIndex(index, node_count);
}

/// The most nodes a scene may have, in all its bodies: a typo such as `nx: 100000` or
/// `segments: 1e9` fails with a message rather than exhausting memory.
constexpr long long kMaxSceneNodes = 1000000;

/// The most relaxation passes per update of a procedurally animated body. With the most updates per
/// physics step (kMaxUpdatesPerStep, controller.h) it multiplies the work of every step (the seeds make
/// 1 to 4 updates of 1 to 8 passes), so that a typo such as `update_period: 1e-9` or
/// `iterations: 1000000` fails with a message rather than stalling the simulation.
constexpr long long kMaxRelaxationPasses = 100;

/// `iterations` of a procedurally animated body: an integer in [1, kMaxRelaxationPasses].
inline int readRelaxationPasses(const Context& ctx, const Field& field)
{
  const long long passes = readInteger(ctx, field);
  if (passes < 1 || passes > kMaxRelaxationPasses)
    ctx.fail(field, "must be an integer in [1, " + std::to_string(kMaxRelaxationPasses) + "], got " +
                        field.node.Scalar());
  return static_cast<int>(passes);
}

/// What a body's reader needs of the scene read before the body: the physics (read first) and the
/// nodes of the bodies before it.
struct SceneSoFar
{
  const PhysicsDef& physics;
  long long nodes = 0;  ///< nodes of the bodies before this one

  /// Fails at `field` if a body of `body_nodes` nodes would take the scene over kMaxSceneNodes. Each reader
  /// calls it before building its body, so that a scene over the limit fails without first taking the
  /// memory of the body that crosses it (a cloth of 10^6 nodes holds 6 10^6 springs).
  void requireNodes(const Context& ctx, const Field& field, long long body_nodes) const
  {
    if (nodes + body_nodes > kMaxSceneNodes)
      ctx.fail(field, "the scene would have " + std::to_string(nodes + body_nodes) + " nodes, more than " +
                          std::to_string(kMaxSceneNodes) +
                          (nodes > 0 ? " (" + std::to_string(nodes) + " in the bodies before this one)" : ""));
  }
};

/// The last stage of a procedural body's reader: `build(name, def)` (buildCreature, buildLimb, ...) with
/// the body's name, which its own checks quote. A std::invalid_argument from a check the reader did not
/// make is still one line at the body.
template <typename Def, typename Build>
BodyDef buildProceduralBody(const Context& ctx, const Field& field, const Def& def, Build build)
{
  const std::string name = readNonEmptyString(ctx, requiredKey(ctx, field, "name"));
  try
  {
    return build(name, def);
  }
  catch (const std::invalid_argument& e)
  {
    ctx.fail(field, e.what());
  }
}

using BodyReader = BodyDef (*)(const Context& ctx, const Field& body, const SceneSoFar& scene);

struct BodyType
{
  const char* name;
  BodyReader read;
};

/// Every body type a scene may use.
const std::vector<BodyType>& bodyTypes();

/// The keys every body type allows around its own: name, type, <own...>, anchors.
Keys withCommonBodyKeys(const Keys& own);

BodyDef readCustomBody(const Context& ctx, const Field& body, const SceneSoFar& scene);
BodyDef readRopeBody(const Context& ctx, const Field& body, const SceneSoFar& scene);
BodyDef readClothBody(const Context& ctx, const Field& body, const SceneSoFar& scene);
BodyDef readJellyBody(const Context& ctx, const Field& body, const SceneSoFar& scene);

// Procedurally animated body types (creature, limb, humanoid).
BodyDef readCreatureBody(const Context& ctx, const Field& body, const SceneSoFar& scene);
BodyDef readLimbBody(const Context& ctx, const Field& body, const SceneSoFar& scene);
BodyDef readHumanoidBody(const Context& ctx, const Field& body, const SceneSoFar& scene);
/// The limb-motion keys that `limb` and `humanoid` share (limb_reader.cpp): gravity, frame_period,
/// max_frames_per_step, iterations, tension, retention, curve_samples.
const Keys& limbMotionKeys();
/// Reads the limbMotionKeys() present in `body` (a mapping checked by requireMap) into `motion`.
void readLimbMotion(const Context& ctx, const Field& body, LimbMotion& motion);

}  // namespace soft_body_sim::scene_yaml
