// Keys shared by the readers of the generated bodies (rope, rod, cloth, jelly): node counts, spring
// families, grid corners, pinned nodes and self-contact. Private to those readers.
#pragma once

#include <string>
#include <vector>

#include "scene/body_readers.h"
#include "soft_body_sim/core/bodies/cloth.h"

namespace soft_body_sim::scene_yaml
{
/// The most nodes a generated body may have (see kMaxSceneNodes).
constexpr long long kMaxGeneratedNodes = kMaxSceneNodes;

/// An integer count in [minimum, kMaxGeneratedNodes].
inline int readCount(const Context& ctx, const Field& field, long long minimum)
{
  const long long value = readInteger(ctx, field);
  if (value < minimum || value > kMaxGeneratedNodes)
    ctx.fail(field, "must be an integer in [" + std::to_string(minimum) + ", " + std::to_string(kMaxGeneratedNodes) +
                        "], got " + field.node.Scalar());
  return static_cast<int>(value);
}

/// Fails at `field` if a grid of columns x rows nodes is larger than kMaxGeneratedNodes.
inline void checkGridSize(const Context& ctx, const Field& field, long long columns, long long rows)
{
  if (columns * rows > kMaxGeneratedNodes)
    ctx.fail(field, "the grid would have " + std::to_string(columns) + " x " + std::to_string(rows) +
                        " nodes, more than " + std::to_string(kMaxGeneratedNodes));
}

/// `{stiffness: k, damping: c}`: k [N/m] required, c [N s/m] (default 0); requireSprings checks them.
inline SpringParameters readSpringParameters(const Context& ctx, const Field& field)
{
  requireMap(ctx, field, { "stiffness", "damping" });
  SpringParameters spring;
  spring.stiffness = readNumber(ctx, requiredKey(ctx, field, "stiffness"));
  readOptional(ctx, field, "damping", spring.damping, readNumber);
  return spring;
}

/// The optional keys self_collision and self_friction of `body` (default false and 0), as given: the
/// builder checks them (requireSelfContact).
template <typename Def>
void readSelfContact(const Context& ctx, const Field& body, Def& def)
{
  readOptional(ctx, body, "self_collision", def.self_collision, readBool);
  readOptional(ctx, body, "self_friction", def.self_friction, readNumber);
}

/// The required keys top_left, top_right and bottom_left [m] of a grid body.
inline GridCorners readGridCorners(const Context& ctx, const Field& body)
{
  GridCorners corners;
  corners.top_left = readVec3(ctx, requiredKey(ctx, body, "top_left"));
  corners.top_right = readVec3(ctx, requiredKey(ctx, body, "top_right"));
  corners.bottom_left = readVec3(ctx, requiredKey(ctx, body, "bottom_left"));
  return corners;
}

/// `pinned: [...]`: node indices of a body of `node_count` nodes, a negative one counting from the end
/// (-1 is the last node); for a grid of columns x rows nodes (rows > 0) also the corner names of
/// gridCornerNames(). Returns non-negative indices.
inline std::vector<int> readPinned(const Context& ctx, const Field& field, int node_count, int columns = 0,
                                   int rows = 0)
{
  std::vector<int> pinned;
  for (const Field& item : requireList(ctx, field))
  {
    const bool named =
        rows > 0 && item.node.IsScalar() && !item.node.Scalar().empty() && !readsAsNodeIndex(item.node.Scalar());
    if (named)
    {
      const std::optional<int> corner = gridCornerNode(item.node.Scalar(), columns, rows);
      if (!corner)
        ctx.fail(item, "unknown corner " + quoted(item.node.Scalar()) + "; expected a node index or one of " +
                           join(gridCornerNames()));
      pinned.push_back(*corner);
      continue;
    }
    if (rows > 0 && !item.node.IsScalar())
      ctx.fail(item, "expected a node index or a corner name, got " + describe(item.node));
    pinned.push_back(readNodeIndex(ctx, item, node_count));
  }
  return pinned;
}

}  // namespace soft_body_sim::scene_yaml
