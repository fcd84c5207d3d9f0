// The visiting order of the two-node elements' kernels (springs, distance constraints).
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace soft_body_sim
{
/// Rows grouped by colour so that no two rows of a colour share a node (see edgeColourOrder).
struct EdgeColouring
{
  std::vector<std::uint32_t> order;        ///< the rows, colour after colour
  std::vector<std::size_t> colour_starts;  ///< colour c is order[colour_starts[c], colour_starts[c + 1])
  /// The last colour is the 64th, whose rows may share a node (a node with 64 rows or more).
  bool last_shares_nodes = false;
};

/// `rows` (indices into `ends`, the two nodes of each row) grouped by a greedy edge colouring, colour after
/// colour, each colour in the order of `rows`. In model order consecutive rows of a rope or a cloth share
/// a node, so each update waits for its predecessor's result at that node (a store to forward, or a square
/// root and divisions); within a colour the processor overlaps them, and a colour's rows can be updated
/// several at once. A node with 64 rows or more puts the rest in the 64th colour (still correct when
/// visited one by one, only slower). `node_count` bounds the nodes.
EdgeColouring edgeColourOrder(const std::vector<std::pair<int, int>>& ends, const std::vector<std::uint32_t>& rows,
                              int node_count);

}  // namespace soft_body_sim
