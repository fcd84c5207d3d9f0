#include "soft_body_sim/core/bodies/cloth.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "soft_body_sim/core/bodies/rope.h"
#include "soft_body_sim/core/format_number.h"

namespace soft_body_sim
{
bool GridCorners::spansParallelogram() const
{
  // The sine of the angle between the edges: below 1e-9 the grid is a line (or a point).
  const Vec3 top = top_right - top_left;
  const Vec3 left = bottom_left - top_left;
  const double scale = top.norm() * left.norm();
  return scale > 0.0 && areaNormal().norm() > 1e-9 * scale;
}

const std::vector<std::string>& gridCornerNames()
{
  static const std::vector<std::string> names = { "top_left", "top_right", "bottom_left", "bottom_right" };
  return names;
}

std::optional<int> gridCornerNode(const std::string& name, int columns, int rows)
{
  if (name == "top_left")
    return 0;
  if (name == "top_right")
    return columns - 1;
  if (name == "bottom_left")
    return (rows - 1) * columns;
  if (name == "bottom_right")
    return rows * columns - 1;
  return std::nullopt;
}

void requireGrid(const std::string& what, const GridCorners& corners, double mass)
{
  requireDefinition(corners.spansParallelogram(), what, { "bottom_left", "top_right", "top_left" },
                    "top_left, top_right and bottom_left must span a parallelogram; they are collinear or coincide");
  requireDefinition(mass > 0.0, what, { "mass" }, "mass must be > 0");
}

void requireSprings(const std::string& what, const std::string& key, const SpringParameters& springs)
{
  requireDefinition(springs.stiffness > 0.0, what, { key + ".stiffness", key }, key + ".stiffness must be > 0");
  requireDefinition(springs.damping >= 0.0, what, { key + ".damping", key }, key + ".damping must be >= 0");
}

void addGridTriangles(BodyDef& body, int columns, int rows, bool face_contacts)
{
  const auto node = [columns](int i, int j) { return j * columns + i; };
  for (int j = 0; j + 1 < rows; ++j)
    for (int i = 0; i + 1 < columns; ++i)
    {
      body.faces.push_back({ node(i, j), node(i + 1, j), node(i + 1, j + 1) });
      body.faces.push_back({ node(i, j), node(i + 1, j + 1), node(i, j + 1) });
    }
  if (face_contacts)
    body.contact_triangles = body.faces;
}

void addSpringGrid(BodyDef& body, const GridCorners& corners, int columns, int rows, double mass,
                   const SpringParameters& edges, const SpringParameters& diagonals)
{
  const int first = static_cast<int>(body.nodes.size());
  const double node_mass = mass / (columns * rows);
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < columns; ++i)
      body.nodes.push_back(NodeDef{ corners.at(static_cast<double>(i) / (columns - 1), static_cast<double>(j) / (rows - 1)),
                                    node_mass, Vec3::Zero(), false });
  // Rest lengths stay empty: the flat initial layout is the rest shape.
  const auto node = [first, columns](int i, int j) { return first + j * columns + i; };
  const auto link = [&body](int a, int b, const SpringParameters& p) {
    body.springs.push_back(SpringDef{ a, b, p.stiffness, p.damping, std::nullopt });
  };
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < columns; ++i)
    {
      if (i + 1 < columns)
        link(node(i, j), node(i + 1, j), edges);
      if (j + 1 < rows)
        link(node(i, j), node(i, j + 1), edges);
    }
  for (int j = 0; j + 1 < rows; ++j)
    for (int i = 0; i + 1 < columns; ++i)
    {
      link(node(i, j), node(i + 1, j + 1), diagonals);
      link(node(i + 1, j), node(i, j + 1), diagonals);
    }
}

BodyDef buildCloth(const std::string& name, const ClothDef& cloth)
{
  const std::string what = "cloth '" + name + "'";
  requireDefinition(cloth.nx >= 2 && cloth.ny >= 2, what, { "nx", "ny" }, "nx and ny must be >= 2");
  requireGrid(what, cloth.corners, cloth.mass);
  requireSprings(what, "structural", cloth.structural);
  requireSprings(what, "shear", cloth.shear);
  if (cloth.bending)
    requireSprings(what, "bending", *cloth.bending);
  requireDefinition(cloth.thickness >= 0.0, what, { "thickness" }, "thickness must be >= 0");
  if (cloth.self_collision)
  {
    const double spacing = std::min((cloth.corners.top_right - cloth.corners.top_left).norm() / (cloth.nx - 1),
                                    (cloth.corners.bottom_left - cloth.corners.top_left).norm() / (cloth.ny - 1));
    // A node of radius r passes between four others of radius r at spacing d when d / sqrt(2) >= 2 r;
    // faces (face_contacts) close those gaps, and only neighbours overlapping at rest are left.
    if (cloth.face_contacts)
      requireDefinition(cloth.thickness < 0.5 * spacing, what, { "thickness" },
                        "self_collision needs a thickness below 0.5 times the node spacing (" + formatNumber(spacing) +
                            " m): thicker, neighbours overlap at rest");
    else
      requireDefinition(cloth.thickness >= 0.36 * spacing && cloth.thickness < 0.5 * spacing, what, { "thickness" },
                        "self_collision needs a thickness from 0.36 to 0.5 times the node spacing (" +
                            formatNumber(spacing) + " m): thinner, a node slips between four others; thicker, "
                            "neighbours overlap at rest (with face_contacts, any below 0.5)");
  }
  requireSelfContact(what, cloth.self_collision, cloth.self_friction, cloth.thickness, "thickness");
  BodyDef body;
  body.name = name;
  body.type = "cloth";
  body.contact_radius = cloth.thickness;
  body.self_collision = cloth.self_collision;
  body.self_friction = cloth.self_friction;
  const int nx = cloth.nx;
  const int ny = cloth.ny;
  addSpringGrid(body, cloth.corners, nx, ny, cloth.mass, cloth.structural, cloth.shear);
  for (int index : cloth.pinned)
    body.nodes[static_cast<std::size_t>(resolveNodeIndex(index, nx * ny))].pinned = true;
  const auto node = [nx](int i, int j) { return j * nx + i; };
  addGridTriangles(body, nx, ny, cloth.face_contacts);
  if (cloth.bending)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
      {
        if (i + 2 < nx)
          body.springs.push_back(SpringDef{ node(i, j), node(i + 2, j), cloth.bending->stiffness,
                                            cloth.bending->damping, std::nullopt });
        if (j + 2 < ny)
          body.springs.push_back(SpringDef{ node(i, j), node(i, j + 2), cloth.bending->stiffness,
                                            cloth.bending->damping, std::nullopt });
      }
  return body;
}

}  // namespace soft_body_sim
