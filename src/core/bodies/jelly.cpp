#include "soft_body_sim/core/bodies/jelly.h"

#include <stdexcept>

#include "soft_body_sim/core/bodies/cloth.h"

namespace soft_body_sim
{
BodyDef buildJelly(const std::string& name, const JellyDef& jelly)
{
  if (jelly.nx < 1 || jelly.ny < 1 || !(jelly.mass > 0.0) || !(jelly.edges.stiffness > 0.0) ||
      !(jelly.diagonals.stiffness > 0.0) || jelly.edges.damping < 0.0 || jelly.diagonals.damping < 0.0 ||
      !(jelly.pressure > 0.0))
    throw std::invalid_argument("jelly '" + name + "': needs nx, ny >= 1, mass > 0, edge and diagonal "
                                "stiffness > 0, no negative damping, pressure > 0");
  if (!jelly.corners.spansParallelogram())
    throw std::invalid_argument("jelly '" + name + "': the corners span no parallelogram");
  BodyDef body;
  body.name = name;
  body.type = "jelly";
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
  return body;
}

}  // namespace soft_body_sim
