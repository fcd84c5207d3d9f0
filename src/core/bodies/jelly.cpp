#include "soft_body_sim/core/bodies/jelly.h"

#include <algorithm>
#include <stdexcept>

#include "soft_body_sim/core/bodies/cloth.h"
#include "soft_body_sim/core/format_number.h"

namespace soft_body_sim
{
BodyDef buildJelly(const std::string& name, const JellyDef& jelly)
{
  const std::string what = "jelly '" + name + "'";
  requireDefinition(jelly.nx >= 1 && jelly.ny >= 1, what, { "nx", "ny" }, "nx and ny must be >= 1");
  requireGrid(what, jelly.corners, jelly.mass);
  requireSprings(what, "edges", jelly.edges);
  requireSprings(what, "diagonals", jelly.diagonals);
  requireDefinition(jelly.pressure > 0.0, what, { "pressure" }, "pressure must be > 0");
  requireDefinition(jelly.thickness >= 0.0, what, { "thickness" }, "thickness must be >= 0");
  requireSelfContact(what, jelly.self_collision, jelly.self_friction, jelly.thickness, "thickness");
  if (jelly.self_collision)
  {
    // A parallelogram cell of area A: each corner lies A / d from the diagonal d it is not on, the
    // nearest of the springs it does not end on.
    const Vec3 across = (jelly.corners.top_right - jelly.corners.top_left) / jelly.nx;
    const Vec3 down = (jelly.corners.bottom_left - jelly.corners.top_left) / jelly.ny;
    const double clearance =
        across.cross(down).norm() / std::max((across + down).norm(), (across - down).norm());
    requireDefinition(jelly.thickness <= 0.25 * clearance, what, { "thickness" },
                      "self_collision needs a thickness of at most a quarter of the distance from a cell's "
                      "corner to its diagonal (" + formatNumber(clearance) + " m): thicker, its nodes start "
                      "less than two contact distances from the springs of their cells");
  }
  BodyDef body;
  body.name = name;
  body.type = "jelly";
  body.contact_radius = jelly.thickness;
  body.self_collision = jelly.self_collision;
  body.self_friction = jelly.self_friction;
  body.springs_collide = true;
  const int columns = jelly.nx + 1;
  addSpringGrid(body, jelly.corners, columns, jelly.ny + 1, jelly.mass, jelly.edges, jelly.diagonals);
  // One gas cell per square, its nodes right along the top edge, then down the left edge: counter-
  // clockwise about top x left.
  const auto node = [columns](int i, int j) { return j * columns + i; };
  const Vec3 normal = jelly.corners.areaNormal().normalized();
  for (int j = 0; j < jelly.ny; ++j)
    for (int i = 0; i < jelly.nx; ++i)
    {
      CellDef cell;
      cell.nodes[0] = node(i, j);
      cell.nodes[1] = node(i + 1, j);
      cell.nodes[2] = node(i + 1, j + 1);
      cell.nodes[3] = node(i, j + 1);
      cell.normal = normal;
      cell.pressure = jelly.pressure;  // rest area: the initial one
      body.cells.push_back(cell);
    }
  addGridTriangles(body, columns, jelly.ny + 1, jelly.face_contacts);
  return body;
}

}  // namespace soft_body_sim
