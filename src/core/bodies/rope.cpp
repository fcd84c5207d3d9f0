#include "soft_body_sim/core/bodies/rope.h"

#include <stdexcept>

namespace soft_body_sim
{
BodyDef buildRope(const std::string& name, const RopeDef& rope)
{
  const std::string what = "rope '" + name + "'";
  requireDefinition(rope.nodes >= 2, what, { "nodes" }, "nodes must be >= 2");
  requireDefinition(rope.mass > 0.0, what, { "mass" }, "mass must be > 0");
  requireDefinition(rope.stiffness > 0.0, what, { "stiffness" }, "stiffness must be > 0");
  requireDefinition(rope.damping >= 0.0, what, { "damping" }, "damping must be >= 0");
  requireDefinition(rope.bending >= 0.0, what, { "bending" }, "bending must be >= 0");
  requireDefinition(rope.bending_damping >= 0.0, what, { "bending_damping" }, "bending_damping must be >= 0");
  requireDefinition(rope.bending_damping == 0.0 || rope.bending > 0.0, what, { "bending_damping" },
                    "bending_damping has no effect without bending > 0 (there are no bending springs to damp)");
  requireDefinition(rope.radius >= 0.0, what, { "radius" }, "radius must be >= 0");
  requireDefinition((rope.to - rope.from).norm() > 0.0, what, { "to", "from" },
                    "to must differ from 'from'; a rope needs a length");
  BodyDef body;
  body.name = name;
  body.type = "rope";
  body.contact_radius = rope.radius;
  const double node_mass = rope.mass / rope.nodes;
  for (int i = 0; i < rope.nodes; ++i)
  {
    const double s = static_cast<double>(i) / (rope.nodes - 1);
    body.nodes.push_back(NodeDef{ rope.from + s * (rope.to - rope.from), node_mass, Vec3::Zero(), false });
  }
  for (int index : rope.pinned)
    body.nodes[static_cast<std::size_t>(resolveNodeIndex(index, rope.nodes))].pinned = true;
  // Rest lengths stay empty: the straight initial layout is the rest shape.
  for (int i = 0; i + 1 < rope.nodes; ++i)
  {
    body.springs.push_back(SpringDef{ i, i + 1, rope.stiffness, rope.damping, std::nullopt });
    body.contact_segments.emplace_back(i, i + 1);
  }
  if (rope.bending > 0.0)
    for (int i = 0; i + 2 < rope.nodes; ++i)
      body.springs.push_back(SpringDef{ i, i + 2, rope.bending, rope.bending_damping, std::nullopt });
  return body;
}

}  // namespace soft_body_sim
