// `type: volume`: a soft solid, a box, a ball or a closed surface file filled with tetrahedra
// (bodies/volume.h).
#include "scene/body_readers.h"
#include "soft_body_sim/core/bodies/volume.h"

namespace soft_body_sim::scene_yaml
{
namespace
{
VolumeShape readVolumeShape(const Context& ctx, const Field& field)
{
  const std::string name = readNonEmptyString(ctx, field);
  if (name == "box")
    return VolumeShape::Box;
  if (name == "sphere")
    return VolumeShape::Sphere;
  if (name == "mesh")
    return VolumeShape::Mesh;
  ctx.fail(field, "unknown shape " + quoted(name) + "; valid shapes: box, sphere, mesh");
}

/// `pinned: [...]`: box face names and node indices, as written (the builder checks both: the node count
/// is known only once the body is meshed).
void readPinnedNodesAndFaces(const Context& ctx, const Field& field, VolumeDef& volume)
{
  for (const Field& item : requireList(ctx, field))
  {
    if (!item.node.IsScalar())
      ctx.fail(item, "expected a node index or a face name, got " + describe(item.node));
    const std::string& text = item.node.Scalar();
    if (readsAsNodeIndex(text))
      volume.pinned_nodes.push_back(readInt(ctx, item));
    else
      volume.pinned_faces.push_back(readNonEmptyString(ctx, item));
  }
}
}  // namespace

BodyDef readVolumeBody(const Context& ctx, const Field& field, const SceneSoFar& scene)
{
  requireMap(ctx, field, withCommonBodyKeys({ "shape", "size", "radius", "mesh", "resolution", "position",
                                              "youngs_modulus", "poisson_ratio", "density", "pinned", "friction", "pressure",
                                              "surface_samples" }));
  VolumeDef volume;
  volume.shape = readVolumeShape(ctx, requiredKey(ctx, field, "shape"));
  readOptional(ctx, field, "size", volume.size, readVec3);
  readOptional(ctx, field, "radius", volume.radius, readNumber);
  if (const std::optional<Field> value = optionalKey(field, "mesh"))
  {
    volume.mesh = readNonEmptyString(ctx, *value);
    if (volume.shape == VolumeShape::Mesh)  // on another shape the builder says the key does not belong
      volume.surface = readMeshFile(ctx, *value, Vec3::Ones()).triangles;
  }
  const Field resolution = requiredKey(ctx, field, "resolution");
  volume.resolution = readNumber(ctx, resolution);
  volume.position = readVec3(ctx, requiredKey(ctx, field, "position"));
  volume.youngs_modulus = readNumber(ctx, requiredKey(ctx, field, "youngs_modulus"));
  readOptional(ctx, field, "poisson_ratio", volume.poisson_ratio, readNumber);
  volume.density = readNumber(ctx, requiredKey(ctx, field, "density"));
  if (const std::optional<Field> value = optionalKey(field, "pinned"))
    readPinnedNodesAndFaces(ctx, *value, volume);
  readOptional(ctx, field, "friction", volume.friction, readNumber);
  readOptional(ctx, field, "pressure", volume.pressure, readNumber);
  readOptional(ctx, field, "surface_samples", volume.surface_samples, readNumber);
  volume.max_tetrahedra = scene.max_tetrahedra;
  BodyDef body = buildBody(ctx, field, volume, buildVolume);
  // The node count is known only after meshing; the mesher's own limit (max_tetrahedra) bounds the memory
  // that takes, so the scene's limit is checked here, at the key that sets the count.
  scene.requireNodes(ctx, resolution, static_cast<long long>(body.nodes.size()));
  return body;
}

}  // namespace soft_body_sim::scene_yaml
