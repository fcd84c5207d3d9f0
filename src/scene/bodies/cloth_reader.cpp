// `type: cloth` (tum-mass-spring-tutorial.txt): a grid of nx x ny nodes spanning three corners.
#include "scene/bodies/generated_body_keys.h"

namespace soft_body_sim::scene_yaml
{
BodyDef readClothBody(const Context& ctx, const Field& field, const SceneSoFar& scene)
{
  requireMap(ctx, field, withCommonBodyKeys({ "nx", "ny", "top_left", "top_right", "bottom_left", "mass",
                                              "structural", "shear", "bending", "pinned", "thickness",
                                              "self_collision", "self_friction", "face_contacts" }));
  ClothDef cloth;
  cloth.nx = readCount(ctx, requiredKey(ctx, field, "nx"), 2);
  const Field ny = requiredKey(ctx, field, "ny");
  cloth.ny = readCount(ctx, ny, 2);
  checkGridSize(ctx, ny, cloth.nx, cloth.ny);
  scene.requireNodes(ctx, ny, static_cast<long long>(cloth.nx) * cloth.ny);
  cloth.corners = readGridCorners(ctx, field);
  cloth.mass = readNumber(ctx, requiredKey(ctx, field, "mass"));
  cloth.structural = readSpringParameters(ctx, requiredKey(ctx, field, "structural"));
  cloth.shear = readSpringParameters(ctx, requiredKey(ctx, field, "shear"));
  readOptional(ctx, field, "bending", cloth.bending, readSpringParameters);
  if (const std::optional<Field> value = optionalKey(field, "pinned"))
    cloth.pinned = readPinned(ctx, *value, cloth.nx * cloth.ny, cloth.nx, cloth.ny);
  readOptional(ctx, field, "thickness", cloth.thickness, readNumber);
  readSelfContact(ctx, field, cloth);
  readOptional(ctx, field, "face_contacts", cloth.face_contacts, readBool);
  return buildBody(ctx, field, cloth, buildCloth);
}

}  // namespace soft_body_sim::scene_yaml
