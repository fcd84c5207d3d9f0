#include "soft_body_sim/scene/scene_loader.h"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <utility>

#include "scene/body_readers.h"
#include "scene/listed_nodes_scan.h"
#include "soft_body_sim/core/contact/mesh_field.h"
#include "soft_body_sim/core/input_file.h"
#include "soft_body_sim/scene/mesh_uri.h"
#include "scene/yaml_reader.h"

namespace soft_body_sim
{
namespace
{
using namespace scene_yaml;

const Keys kSceneKeys = { "frame_id", "rate", "physics", "planes", "colliders", "robot_colliders", "cameras", "bodies" };
const Keys kCameraKeys = { "name",      "frame",     "position",  "orientation", "width",      "height", "horizontal_fov",
                           "rate",      "min_range", "max_range", "background",  "noise" };
const Keys kNoiseKeys = { "depth_stddev", "seed" };
const Keys kPhysicsKeys = { "integrator", "dt", "substeps", "iterations", "gravity", "drag", "guard" };
const Keys kGuardKeys = { "policy", "max_speed" };
const Keys kPlaneKeys = { "name", "point", "normal", "restitution", "friction", "color" };
const Keys kAnchorKeys = { "name", "node", "frame" };
const Keys kPlacementKeys = { "name",     "shape",    "position",         "orientation", "velocity",
                              "friction", "angular_velocity", "restitution", "frame", "color" };

// --- scene parts -------------------------------------------------------------------------------

/// A tf frame id: tf2 rejects ids with a leading slash (a tf1 habit): say so here, not at run time.
std::string readFrameId(const Context& ctx, const Field& field)
{
  const std::string frame = readNonEmptyString(ctx, field);
  if (frame.front() == '/')
    ctx.fail(field, "tf frame " + quoted(frame) + " must not start with '/'");
  return frame;
}

/// A number in [0, 1].
double readFraction(const Context& ctx, const Field& field)
{
  const double value = readNonNegative(ctx, field);
  if (value > 1.0)
    ctx.fail(field, "must be in [0, 1], got " + field.node.Scalar());
  return value;
}

IntegratorType readIntegrator(const Context& ctx, const Field& field)
{
  const std::string name = readNonEmptyString(ctx, field);
  IntegratorType type{};
  if (!integratorFromName(name, type))
    ctx.fail(field, "unknown integrator " + quoted(name) + "; valid integrators: " + join(integratorNames()));
  return type;
}

GuardPolicy readGuardPolicy(const Context& ctx, const Field& field)
{
  const std::string name = readNonEmptyString(ctx, field);
  GuardPolicy policy{};
  if (!guardPolicyFromName(name, policy))
    ctx.fail(field, "unknown policy " + quoted(name) + "; valid policies: " + join(guardPolicyNames()));
  return policy;
}

GuardSettings readGuard(const Context& ctx, const Field& field)
{
  requireMap(ctx, field, kGuardKeys);
  GuardSettings guard;
  readOptional(ctx, field, "policy", guard.policy, readGuardPolicy);
  readOptional(ctx, field, "max_speed", guard.max_speed, readPositive);
  return guard;
}

PhysicsDef readPhysics(const Context& ctx, const Field& field)
{
  requireMap(ctx, field, kPhysicsKeys);
  PhysicsDef physics;
  readOptional(ctx, field, "integrator", physics.integrator, readIntegrator);
  if (const std::optional<Field> value = optionalKey(field, "dt"))
  {
    // `auto`: the world picks a stable step from the scene's stiffest spring (chooseStableStep).
    if (value->node.IsScalar() && value->node.Tag() != "!" && value->node.Scalar() == "auto")
      physics.auto_dt = true;
    else
      physics.step.dt = readPositive(ctx, *value);
  }
  readOptional(ctx, field, "substeps", physics.step.substeps, readAtLeastOne);
  readOptional(ctx, field, "iterations", physics.step.iterations, readAtLeastOne);
  readOptional(ctx, field, "gravity", physics.gravity, readVec3);
  readOptional(ctx, field, "drag", physics.drag, readNonNegative);
  readOptional(ctx, field, "guard", physics.guard, readGuard);
  return physics;
}

Plane readPlane(const Context& ctx, const Field& field)
{
  requireMap(ctx, field, kPlaneKeys);
  Plane plane;
  plane.point = readVec3(ctx, requiredKey(ctx, field, "point"));
  const Field normal = requiredKey(ctx, field, "normal");
  plane.normal = readVec3(ctx, normal);
  if (!(plane.normal.norm() > 1e-12))
    ctx.fail(normal, "must not be the zero vector");
  readOptional(ctx, field, "restitution", plane.restitution, readFraction);
  readOptional(ctx, field, "friction", plane.friction, readNonNegative);
  readOptional(ctx, field, "name", plane.name, readNonEmptyString);
  readOptional(ctx, field, "color", plane.color, readColor);
  return plane;
}

/// A quaternion written [x, y, z, w], as given (checkCollider rejects a zero one).
Eigen::Quaterniond readOrientation(const Context& ctx, const Field& field)
{
  const std::vector<Field> q = requireListOfSize(ctx, field, 4, "numbers (a quaternion x, y, z, w)");
  return Eigen::Quaterniond(readNumber(ctx, q[3]), readNumber(ctx, q[0]), readNumber(ctx, q[1]),
                            readNumber(ctx, q[2]));
}

/// The keys every collider shape has: name, pose, motion and surface (checked by checkCollider).
ColliderPlacement readPlacement(const Context& ctx, const Field& field)
{
  ColliderPlacement at;
  at.name = readNonEmptyString(ctx, requiredKey(ctx, field, "name"));
  readOptional(ctx, field, "position", at.position, readVec3);
  readOptional(ctx, field, "orientation", at.orientation, readOrientation);
  readOptional(ctx, field, "velocity", at.velocity, readVec3);
  readOptional(ctx, field, "angular_velocity", at.angular_velocity, readVec3);
  readOptional(ctx, field, "friction", at.friction, readNumber);
  readOptional(ctx, field, "restitution", at.restitution, readNumber);
  readOptional(ctx, field, "frame", at.frame, readFrameId);
  readOptional(ctx, field, "color", at.color, readColor);
  if (!at.frame.empty())  // readFrameId takes no empty id
    for (const char* key : { "velocity", "angular_velocity" })
      if (const std::optional<Field> motion = optionalKey(field, key))
        ctx.fail(*motion, "a collider on a tf frame moves with its frame; " + std::string(key) +
                              " is for colliders without one");
  return at;
}

Keys withPlacementKeys(const Keys& own)
{
  Keys keys = kPlacementKeys;
  keys.insert(keys.end(), own.begin(), own.end());
  return keys;
}

/// `shape` as parsed, checked by checkCollider (its error at the key it names), appended to `shapes`.
template <typename Shape>
void addChecked(const Context& ctx, const Field& field, const Shape& shape, std::vector<Shape>& shapes)
{
  try
  {
    checkCollider(shape);
  }
  catch (const DefinitionError& e)
  {
    failAtKeys(ctx, field, e);
  }
  shapes.push_back(shape);
}

/// A shape with a radius and a length (capsule, cylinder).
template <typename Shape>
Shape readRadiusAndLength(const Context& ctx, const Field& field)
{
  requireMap(ctx, field, withPlacementKeys({ "radius", "length" }));
  Shape shape;
  shape.at = readPlacement(ctx, field);
  shape.radius = readNumber(ctx, requiredKey(ctx, field, "radius"));
  shape.length = readNumber(ctx, requiredKey(ctx, field, "length"));
  return shape;
}

/// A mesh: its file read with its scale (readMeshFile).
Mesh readMesh(const Context& ctx, const Field& field)
{
  requireMap(ctx, field, withPlacementKeys({ "mesh", "scale", "voxel_size" }));
  Mesh mesh;
  mesh.at = readPlacement(ctx, field);
  const Field uri = requiredKey(ctx, field, "mesh");
  mesh.uri = readNonEmptyString(ctx, uri);
  readOptional(ctx, field, "scale", mesh.scale, readVec3);
  readOptional(ctx, field, "voxel_size", mesh.voxel_size, readPositive);
  if (!(mesh.scale.minCoeff() > 0.0))
    return mesh;  // checkCollider says so at `scale`; the file is not read at a scale that makes no solid
  MeshFile file = readMeshFile(ctx, uri, mesh.scale);
  mesh.triangles = std::make_shared<const TriangleMesh>(std::move(file.triangles));
  mesh.uri = drawableMeshUri(mesh.uri, file.path);
  return mesh;
}

/// One item of `colliders:`, added to `colliders` by its shape.
void readCollider(const Context& ctx, const Field& field, Colliders& colliders)
{
  requireMapping(ctx, field);
  const Field shape = requiredKey(ctx, field, "shape");
  const std::string name = readNonEmptyString(ctx, shape);
  if (name == "sphere")
  {
    requireMap(ctx, field, withPlacementKeys({ "radius" }));
    Sphere sphere;
    sphere.at = readPlacement(ctx, field);
    sphere.radius = readNumber(ctx, requiredKey(ctx, field, "radius"));
    addChecked(ctx, field, sphere, colliders.spheres);
  }
  else if (name == "capsule")
  {
    addChecked(ctx, field, readRadiusAndLength<Capsule>(ctx, field), colliders.capsules);
  }
  else if (name == "cylinder")
  {
    addChecked(ctx, field, readRadiusAndLength<Cylinder>(ctx, field), colliders.cylinders);
  }
  else if (name == "box")
  {
    requireMap(ctx, field, withPlacementKeys({ "size" }));
    Box box;
    box.at = readPlacement(ctx, field);
    box.size = readVec3(ctx, requiredKey(ctx, field, "size"));
    addChecked(ctx, field, box, colliders.boxes);
  }
  else if (name == "mesh")
  {
    addChecked(ctx, field, readMesh(ctx, field), colliders.meshes);
  }
  else
  {
    ctx.fail(shape, "unknown shape " + quoted(name) + "; valid shapes: sphere, capsule, cylinder, box, mesh");
  }
}

RobotCollidersDef readRobotColliders(const Context& ctx, const Field& field)
{
  requireMap(ctx, field, { "param", "friction", "restitution" });
  RobotCollidersDef robot;
  readOptional(ctx, field, "param", robot.param, readNonEmptyString);
  readOptional(ctx, field, "friction", robot.friction, readNonNegative);
  readOptional(ctx, field, "restitution", robot.restitution, readFraction);
  return robot;
}

/// `anchors: [{name, node}]`, read after the body's type has expanded it, since `node` indexes the
/// expanded body; a negative index counts from the end (-1 is the last node).
void readAnchors(const Context& ctx, const Field& field, BodyDef& body)
{
  const std::size_t count = body.nodes.size();
  for (const Field& item : requireList(ctx, field))
  {
    requireMap(ctx, item, kAnchorKeys);
    AnchorDef anchor;
    const Field name = requiredKey(ctx, item, "name");
    anchor.name = readNonEmptyString(ctx, name);
    for (const AnchorDef& other : body.anchors)
      if (other.name == anchor.name)
        ctx.fail(name, "duplicate anchor name " + quoted(anchor.name));
    anchor.node = readNodeIndex(ctx, requiredKey(ctx, item, "node"), static_cast<int>(count));
    readOptional(ctx, item, "frame", anchor.frame, readFrameId);
    body.anchors.push_back(anchor);
  }
}

/// One item of `cameras:`, checked by checkCamera (its error at the key it names).
CameraDef readCamera(const Context& ctx, const Field& field)
{
  requireMap(ctx, field, kCameraKeys);
  CameraDef camera;
  const Field name = requiredKey(ctx, field, "name");
  camera.name = readNonEmptyString(ctx, name);
  // It names topics (~<name>/...) and tf frames (<name>_link): a ROS name's letters only.
  const bool valid = std::isalpha(static_cast<unsigned char>(camera.name[0])) &&
                     std::all_of(camera.name.begin(), camera.name.end(),
                                 [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
  if (!valid)
    ctx.fail(name, "a camera's name starts with a letter and has only letters, digits and underscores (it names "
                   "topics and tf frames); got " + quoted(camera.name));
  readOptional(ctx, field, "frame", camera.frame, readFrameId);
  readOptional(ctx, field, "position", camera.position, readVec3);
  readOptional(ctx, field, "orientation", camera.orientation, readOrientation);
  readOptional(ctx, field, "width", camera.width, readAtLeastOne);
  readOptional(ctx, field, "height", camera.height, readAtLeastOne);
  readOptional(ctx, field, "horizontal_fov", camera.horizontal_fov, readNumber);
  readOptional(ctx, field, "rate", camera.rate, readPositive);
  readOptional(ctx, field, "min_range", camera.min_range, readNonNegative);
  readOptional(ctx, field, "max_range", camera.max_range, readPositive);
  readOptional(ctx, field, "background", camera.background, readColor);
  if (const std::optional<Field> noise = optionalKey(field, "noise"))
  {
    requireMap(ctx, *noise, kNoiseKeys);
    DepthNoise read;
    readOptional(ctx, *noise, "depth_stddev", read.depth_stddev, readNonNegative);
    if (const std::optional<Field> seed = optionalKey(*noise, "seed"))
    {
      const long long value = readInteger(ctx, *seed);
      if (value < 0)
        ctx.fail(*seed, "seed must be an integer >= 0");
      read.seed = static_cast<std::uint64_t>(value);
    }
    camera.noise = read;
  }
  try
  {
    checkCamera(camera);
  }
  catch (const DefinitionError& e)
  {
    failAtKeys(ctx, field, e);
  }
  return camera;
}

BodyDef readBody(const Context& ctx, const Field& field, const SceneSoFar& scene)
{
  requireMapping(ctx, field);
  // The type decides which other keys are allowed, so it is checked before them.
  const Field type = requiredKey(ctx, field, "type");
  const std::string name = readNonEmptyString(ctx, type);
  Keys names;
  for (const BodyType& body_type : bodyTypes())
  {
    if (name == body_type.name)
    {
      BodyDef body = body_type.read(ctx, field, scene);
      if (const std::optional<Field> color = optionalKey(field, "color"))
        body.color = readColor(ctx, *color);
      if (const std::optional<Field> anchors = optionalKey(field, "anchors"))
        readAnchors(ctx, *anchors, body);
      return body;
    }
    names.push_back(body_type.name);
  }
  ctx.fail(type, "unknown body type " + quoted(name) + "; valid types: " + join(names));
}

SceneDef readScene(const Context& ctx, const Field& root, const SceneLimits& limits)
{
  if (!root.node.IsMap())
    ctx.fail(root, "a scene must be a YAML mapping with the keys " + join(kSceneKeys) + "; got " +
                       (root.node.IsNull() ? "an empty document" : describe(root.node)));
  requireMap(ctx, root, kSceneKeys);
  SceneDef scene;
  readOptional(ctx, root, "frame_id", scene.frame_id, readNonEmptyString);
  readOptional(ctx, root, "rate", scene.rate, readPositive);
  readOptional(ctx, root, "physics", scene.physics, readPhysics);
  // Planes and colliders share their names (each names a wrench: World::colliderWrenches).
  std::map<std::string, std::string> collider_by_name;  // to name the first collider in a duplicate error
  const auto unique = [&](const Field& item, const std::string& name) {
    const auto [first, inserted] = collider_by_name.emplace(name, item.path);
    if (!inserted)
      ctx.fail(requiredKey(ctx, item, "name"), "duplicate collider name " + quoted(name) + " (first used by " +
                                                   first->second + ")");
  };
  if (const std::optional<Field> planes = optionalKey(root, "planes"))
    for (const Field& item : requireList(ctx, *planes))
    {
      scene.colliders.planes.push_back(readPlane(ctx, item));
      if (!scene.colliders.planes.back().name.empty())
        unique(item, scene.colliders.planes.back().name);
    }
  if (const std::optional<Field> colliders = optionalKey(root, "colliders"))
    for (const Field& item : requireList(ctx, *colliders))
    {
      readCollider(ctx, item, scene.colliders);
      unique(item, readNonEmptyString(ctx, requiredKey(ctx, item, "name")));
    }

  readOptional(ctx, root, "robot_colliders", scene.robot_colliders, readRobotColliders);
  if (const std::optional<Field> cameras = optionalKey(root, "cameras"))
    for (const Field& item : requireList(ctx, *cameras))
    {
      scene.cameras.push_back(readCamera(ctx, item));
      for (std::size_t k = 0; k + 1 < scene.cameras.size(); ++k)
        if (scene.cameras[k].name == scene.cameras.back().name)
          ctx.fail(requiredKey(ctx, item, "name"), "duplicate camera name " + quoted(scene.cameras.back().name));
    }

  const Field bodies = requiredKey(ctx, root, "bodies");
  std::map<std::string, std::string> path_by_name;  // to name the first body in a duplicate error
  SceneSoFar so_far{ scene.physics, limits.tetrahedra };
  for (const Field& item : requireList(ctx, bodies))
  {
    scene.bodies.push_back(readBody(ctx, item, so_far));
    so_far.nodes += static_cast<long long>(scene.bodies.back().nodes.size());
    const std::string& name = scene.bodies.back().name;
    const auto [first, inserted] = path_by_name.emplace(name, item.path);
    if (!inserted)
      ctx.fail(requiredKey(ctx, item, "name"), "duplicate body name " + quoted(name) + " (first used by " +
                                                   first->second + ")");
  }
  if (scene.bodies.empty())
    ctx.fail(bodies, "must not be empty; a scene needs at least one body");
  // The rule against passing through, at the key that mends it (with `dt: auto`, buildWorld checks it).
  if (!scene.physics.auto_dt)
    if (const std::optional<TunnellingRisk> risk = tunnellingRisk(scene, scene.physics.step))
    {
      const std::optional<Field> physics = optionalKey(root, "physics");
      const std::optional<Field> substeps = physics ? optionalKey(*physics, "substeps") : std::nullopt;
      ctx.fail(substeps ? *substeps : firstPresent(requireList(ctx, bodies)[risk->body], { "self_collision" }),
               risk->why);
    }
  // Built once here, as wide as the thickest body needs: every world built from the scene (a reset too)
  // shares them.
  buildMeshFields(scene.colliders.meshes, maxContactRadius(scene));
  return scene;
}

}  // namespace

namespace scene_yaml
{
MeshFile readMeshFile(const Context& ctx, const Field& uri, const Vec3& scale)
{
  const std::size_t slash = ctx.source().rfind('/');
  const std::string folder = slash == std::string::npos ? std::string() : ctx.source().substr(0, slash);
  const std::string text = readNonEmptyString(ctx, uri);
  MeshFile file;
  try
  {
    file.path = resolveMeshUri(text, folder);
  }
  catch (const std::invalid_argument& e)
  {
    ctx.fail(uri, e.what());
  }
  try
  {
    file.triangles = readTriangleMesh(file.path, scale);
  }
  catch (const DefinitionError& e)
  {
    ctx.fail(uri, e.what());
  }
  return file;
}
}  // namespace scene_yaml

SceneDef loadSceneFile(const std::string& path)
{
  const std::string unreadable = unreadableFileReason(path, kMaxSceneFileBytes, "kMaxSceneFileBytes");
  if (!unreadable.empty())
    throw SceneError(escapeControlCharacters(path + ": cannot open scene file: " + unreadable));
  std::ifstream file(path, std::ios::binary | std::ios::ate);
  const std::streamoff bytes = file.tellg();
  if (!file || bytes < 0 || static_cast<std::uintmax_t>(bytes) > kMaxSceneFileBytes || !file.seekg(0))
    throw SceneError(escapeControlCharacters(path) + ": cannot open scene file");
  // Read into a string of the file's size: one copy of it in memory, where growing a string as it is read
  // would hold up to two.
  std::string text(static_cast<std::size_t>(bytes), '\0');
  file.read(text.data(), static_cast<std::streamsize>(text.size()));
  if (file.bad())
    throw SceneError(escapeControlCharacters(path) + ": cannot open scene file");
  text.resize(static_cast<std::size_t>(file.gcount()));
  return parseScene(text, path);
}

SceneDef parseScene(const std::string& yaml_text, const std::string& source, const SceneLimits& limits)
{
  const Context ctx(source);
  ListedNodesScan scan(ctx);
  const YAML::Node root = loadSingleDocument(ctx, yaml_text, scan);
  return readScene(ctx, Field{ root, "", root.Mark() }, limits);
}

}  // namespace soft_body_sim
