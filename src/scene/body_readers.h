// The readers of each body type. A reader gets a body mapping whose `type` it owns, checks the keys
// (its own plus the common ones: name, type, anchors), parses their values into the type's definition
// and hands it to the type's builder (buildBody), which checks it and expands it into nodes, springs and
// constraints (plus a controller for procedural bodies). The loader then reads the anchors, whose node
// indices refer to the expanded body.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "soft_body_sim/core/bodies/controller.h"
#include "soft_body_sim/core/contact/mesh_field.h"
#include "soft_body_sim/core/scene_def.h"
#include "scene/yaml_reader.h"

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

/// What a body's reader needs of the scene read before the body: the physics (read first) and the
/// nodes of the bodies before it.
struct SceneSoFar
{
  const PhysicsDef& physics;
  double max_tetrahedra;  ///< the most tetrahedra a volume's mesh may be asked for (SceneLimits)
  long long nodes = 0;    ///< nodes of the bodies before this one

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

/// The field an error about `keys` points at: the first of them that `map` sets (a dotted key such as
/// "tendrils.mass" looks into nested mappings), else `map` itself.
Field firstPresent(const Field& map, const std::vector<std::string>& keys);

/// Reports `error` at the first of its keys that `map` sets, echoing the file's value there.
[[noreturn]] inline void failAtKeys(const Context& ctx, const Field& map, const DefinitionError& error)
{
  const Field at = firstPresent(map, error.keys());
  ctx.fail(at, error.what() + (at.node.IsScalar() ? ", got " + at.node.Scalar() : std::string()));
}

/// The last stage of every generated body's reader: `build(name, def)` (buildRope, buildCreature, ...)
/// with the body's `name`. The builder checks the definition; its DefinitionError becomes one line at the
/// first of the keys it names that the file sets (any other std::invalid_argument: at the body).
template <typename Def, typename Build>
BodyDef buildBody(const Context& ctx, const Field& field, const Def& def, Build build)
{
  const std::string name = readNonEmptyString(ctx, requiredKey(ctx, field, "name"));
  try
  {
    return build(name, def);
  }
  catch (const DefinitionError& e)
  {
    failAtKeys(ctx, field, e);
  }
  catch (const std::invalid_argument& e)
  {
    ctx.fail(field, e.what());
  }
}

/// True if a `pinned:` entry reads as a node index (it starts as a number does), not a name (a grid
/// corner, a box face).
inline bool readsAsNodeIndex(const std::string& text)
{
  return !text.empty() && std::string("+-0123456789").find(text[0]) != std::string::npos;
}

/// A mesh file as read: a mesh collider's shape or a volume's surface.
struct MeshFile
{
  std::string path;        ///< where the file is on disk
  TriangleMesh triangles;  ///< [m]
};
/// The mesh file named by the URI at `uri` (package://, file://, or a path relative to the scene file's
/// folder), read at `scale` (readTriangleMesh). A URI that does not resolve or a file that cannot be read
/// fails at `uri` with the path and the reason.
MeshFile readMeshFile(const Context& ctx, const Field& uri, const Vec3& scale);

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
BodyDef readRodBody(const Context& ctx, const Field& body, const SceneSoFar& scene);
BodyDef readClothBody(const Context& ctx, const Field& body, const SceneSoFar& scene);
BodyDef readJellyBody(const Context& ctx, const Field& body, const SceneSoFar& scene);
BodyDef readVolumeBody(const Context& ctx, const Field& body, const SceneSoFar& scene);

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
