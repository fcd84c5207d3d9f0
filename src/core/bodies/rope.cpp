#include "soft_body_sim/core/bodies/rope.h"

#include <stdexcept>

namespace soft_body_sim
{
BodyDef buildRope(const std::string& name, const RopeDef& rope)
{
  if (rope.nodes < 2 || !(rope.mass > 0.0) || !(rope.stiffness > 0.0) || rope.damping < 0.0 ||
      rope.bending < 0.0 || rope.bending_damping < 0.0)
    throw std::invalid_argument("rope '" + name + "': needs >= 2 nodes, mass > 0, stiffness > 0, no negative "
                                "damping or bending");
  if (!((rope.to - rope.from).norm() > 0.0))
    throw std::invalid_argument("rope '" + name + "': from and to must differ");
  BodyDef body;
  body.name = name;
  body.type = "rope";
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
    body.springs.push_back(SpringDef{ i, i + 1, rope.stiffness, rope.damping, std::nullopt });
  if (rope.bending > 0.0)
    for (int i = 0; i + 2 < rope.nodes; ++i)
      body.springs.push_back(SpringDef{ i, i + 2, rope.bending, rope.bending_damping, std::nullopt });
  return body;
}

}  // namespace soft_body_sim
