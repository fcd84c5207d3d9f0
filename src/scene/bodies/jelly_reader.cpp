// `type: jelly` (springy-viscous-jelly.txt): nx x ny gas-filled cells spanning three corners.
#include "scene/bodies/generated_body_keys.h"
#include "soft_body_sim/core/bodies/jelly.h"

namespace soft_body_sim::scene_yaml
{
BodyDef readJellyBody(const Context& ctx, const Field& field, const SceneSoFar& scene)
{
  requireMap(ctx, field, withCommonBodyKeys({ "nx", "ny", "top_left", "top_right", "bottom_left", "mass", "edges",
                                              "diagonals", "pressure", "thickness", "self_collision",
                                              "self_friction", "face_contacts" }));
  JellyDef jelly;
  jelly.nx = readCount(ctx, requiredKey(ctx, field, "nx"), 1);
  const Field ny = requiredKey(ctx, field, "ny");
  jelly.ny = readCount(ctx, ny, 1);
  checkGridSize(ctx, ny, jelly.nx + 1LL, jelly.ny + 1LL);
  scene.requireNodes(ctx, ny, (jelly.nx + 1LL) * (jelly.ny + 1LL));
  jelly.corners = readGridCorners(ctx, field);
  jelly.mass = readNumber(ctx, requiredKey(ctx, field, "mass"));
  jelly.edges = readSpringParameters(ctx, requiredKey(ctx, field, "edges"));
  jelly.diagonals = readSpringParameters(ctx, requiredKey(ctx, field, "diagonals"));
  jelly.pressure = readNumber(ctx, requiredKey(ctx, field, "pressure"));
  readOptional(ctx, field, "thickness", jelly.thickness, readNumber);
  readSelfContact(ctx, field, jelly);
  readOptional(ctx, field, "face_contacts", jelly.face_contacts, readBool);
  return buildBody(ctx, field, jelly, buildJelly);
}

}  // namespace soft_body_sim::scene_yaml
