#include "soft_body_sim/core/bodies/jelly.h"

#include <stdexcept>

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
  const int rows = jelly.ny + 1;
  const double node_mass = jelly.mass / (columns * rows);
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < columns; ++i)
      body.nodes.push_back(NodeDef{ jelly.corners.at(static_cast<double>(i) / jelly.nx, static_cast<double>(j) / jelly.ny),
                                    node_mass, Vec3::Zero(), false });

  const auto node = [columns](int i, int j) { return j * columns + i; };
  const auto link = [&body](int a, int b, const SpringParameters& p) {
    body.springs.push_back(SpringDef{ a, b, p.stiffness, p.damping, std::nullopt });
  };
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < columns; ++i)
    {
      if (i + 1 < columns)
        link(node(i, j), node(i + 1, j), jelly.edges);
      if (j + 1 < rows)
        link(node(i, j), node(i, j + 1), jelly.edges);
    }
  // Right along the top edge, then down the left edge: counter-clockwise about top x left.
  const Vec3 normal = jelly.corners.areaNormal().normalized();
  for (int j = 0; j < jelly.ny; ++j)
    for (int i = 0; i < jelly.nx; ++i)
    {
      link(node(i, j), node(i + 1, j + 1), jelly.diagonals);
      link(node(i + 1, j), node(i, j + 1), jelly.diagonals);
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
