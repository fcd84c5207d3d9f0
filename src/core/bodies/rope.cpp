#include "soft_body_sim/core/bodies/rope.h"

#include <algorithm>
#include <optional>
#include <stdexcept>
#include <string>

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
  requireSelfContact(what, rope.self_collision, rope.self_friction, rope.radius, "radius");
  if (rope.path.empty())
    requireDefinition((rope.to - rope.from).norm() > 0.0, what, { "to", "from" },
                      "to must differ from 'from'; a rope needs a length");
  const std::vector<Vec3> layout = rope.path.empty() ? std::vector<Vec3>{ rope.from, rope.to } : rope.path;
  requireDefinition(layout.size() >= 2, what, { "path" }, "path needs at least 2 points");
  std::vector<double> along{ 0.0 };  // arc length [m] at each point of the layout
  for (std::size_t k = 1; k < layout.size(); ++k)
  {
    const double length = (layout[k] - layout[k - 1]).norm();
    requireDefinition(length > 0.0, what, { "path" },
                      "path point " + std::to_string(k) + " repeats the one before it; a rope needs a length");
    along.push_back(along.back() + length);
  }
  BodyDef body;
  body.name = name;
  body.type = "rope";
  body.contact_radius = rope.radius;
  body.self_collision = rope.self_collision;
  body.self_friction = rope.self_friction;
  const double node_mass = rope.mass / rope.nodes;
  std::size_t k = 1;  // the layout's segment from point k - 1 to point k holds node i
  for (int i = 0; i < rope.nodes; ++i)
  {
    const double fraction = static_cast<double>(i) / (rope.nodes - 1), s = along.back() * fraction;
    while (k + 1 < layout.size() && along[k] < s)
      ++k;
    // A straight rope's nodes at exactly the fraction of the way (the rope's bits as without a path).
    const double u =
        layout.size() == 2 ? fraction : std::clamp((s - along[k - 1]) / (along[k] - along[k - 1]), 0.0, 1.0);
    body.nodes.push_back(NodeDef{ layout[k - 1] + u * (layout[k] - layout[k - 1]), node_mass, Vec3::Zero(), false });
  }
  for (int index : rope.pinned)
    body.nodes[static_cast<std::size_t>(resolveNodeIndex(index, rope.nodes))].pinned = true;
  // Links' rest lengths stay empty: the initial layout is their rest shape (a path's chords, a little
  // shorter than its arc where it bends). Bending springs rest straight: twice the mean link.
  const double link = along.back() / (rope.nodes - 1);
  for (int i = 0; i + 1 < rope.nodes; ++i)
  {
    body.springs.push_back(SpringDef{ i, i + 1, rope.stiffness, rope.damping, std::nullopt });
    body.contact_segments.emplace_back(i, i + 1);
  }
  if (rope.bending > 0.0)
    for (int i = 0; i + 2 < rope.nodes; ++i)
      body.springs.push_back(SpringDef{ i, i + 2, rope.bending, rope.bending_damping,
                                        rope.path.empty() ? std::nullopt : std::optional<double>(2.0 * link) });
  return body;
}

}  // namespace soft_body_sim
