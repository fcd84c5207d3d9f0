#include "soft_body_sim/core/bodies/rod.h"

#include <cmath>

#include "soft_body_sim/core/elements/rods.h"

namespace soft_body_sim
{
BodyDef buildRod(const std::string& name, const RodDef& rod)
{
  const std::string what = "rod '" + name + "'";
  requireDefinition(rod.nodes >= 2, what, { "nodes" }, "nodes must be >= 2");
  requireDefinition((rod.to - rod.from).norm() > 0.0, what, { "to", "from" },
                    "to must differ from 'from'; a rod needs a length");
  requireDefinition(rod.radius > 0.0, what, { "radius" }, "radius must be > 0");
  requireDefinition(rod.youngs_modulus > 0.0, what, { "youngs_modulus" }, "youngs_modulus must be > 0");
  const double shear_modulus = rod.shear_modulus ? *rod.shear_modulus : rod.youngs_modulus / 2.6;
  requireDefinition(shear_modulus > 0.0, what, { "shear_modulus" }, "shear_modulus must be > 0");
  requireDefinition(rod.density > 0.0, what, { "density" }, "density must be > 0");
  requireDefinition(rod.damping >= 0.0, what, { "damping" }, "damping must be >= 0");
  requireDefinition(rod.end_moment.allFinite(), what, { "end_moment" }, "end_moment must be finite [N m]");
  requireSelfContact(what, rod.self_collision, rod.self_friction, rod.radius, "radius");

  const double area = M_PI * rod.radius * rod.radius;
  const double second_moment = 0.25 * M_PI * std::pow(rod.radius, 4);  // I; the polar moment J = 2 I
  const Vec3 axis = (rod.to - rod.from).normalized();
  const double segment = (rod.to - rod.from).norm() / (rod.nodes - 1);
  const double stretching = rod.youngs_modulus * area / segment;  // E A / l [N/m]

  BodyDef body;
  body.name = name;
  body.type = "rod";
  body.contact_radius = rod.radius;
  body.self_collision = rod.self_collision;
  body.self_friction = rod.self_friction;
  for (int i = 0; i < rod.nodes; ++i)
  {
    const double share = (i == 0 || i == rod.nodes - 1) ? 0.5 : 1.0;
    body.nodes.push_back(NodeDef{ rod.from + (static_cast<double>(i) / (rod.nodes - 1)) * (rod.to - rod.from),
                                  share * rod.density * area * segment, Vec3::Zero(), false });
  }
  for (int i = 0; i + 1 < rod.nodes; ++i)
  {
    body.springs.push_back(SpringDef{ i, i + 1, stretching, rod.damping * stretching, segment });
    body.contact_segments.emplace_back(i, i + 1);
  }

  Rod bending;
  bending.count = rod.nodes;
  bending.segment_length = segment;
  bending.bending_stiffness = rod.youngs_modulus * second_moment;
  bending.twisting_stiffness = shear_modulus * 2.0 * second_moment;
  bending.damping = rod.damping;
  bending.end_moment = rod.end_moment;
  // Frame at rest: x along the rod, y horizontal (across the rod and world z) unless the rod is vertical.
  Vec3 y = Vec3::UnitZ().cross(axis);
  y = y.norm() > 1e-9 ? Vec3(y.normalized()) : Vec3::UnitY();
  Eigen::Matrix3d frame;
  frame << axis, y, axis.cross(y);
  bending.rest_frame = Eigen::Quaterniond(frame);
  for (int index : rod.clamped)
  {
    const int node = resolveNodeIndex(index, rod.nodes);
    body.nodes[static_cast<std::size_t>(node)].pinned = true;
    clampRod(bending, node);
  }
  body.rod = bending;
  return body;
}

}  // namespace soft_body_sim
