#include "core/elements/edge_colouring.h"

#include <cstddef>

namespace soft_body_sim
{
EdgeColouring edgeColourOrder(const std::vector<std::pair<int, int>>& ends, const std::vector<std::uint32_t>& rows,
                              int node_count)
{
  constexpr int kColours = 64;
  std::vector<std::uint64_t> used(static_cast<std::size_t>(node_count), 0);
  std::vector<std::uint8_t> colour(rows.size());
  std::size_t start[kColours + 1] = {};
  for (std::size_t k = 0; k < rows.size(); ++k)
  {
    const auto [a, b] = ends[rows[k]];
    const std::uint64_t taken = used[static_cast<std::size_t>(a)] | used[static_cast<std::size_t>(b)];
    int c = 0;  // the first free colour
    while (c < kColours - 1 && (taken >> c) & 1u)
      ++c;
    colour[k] = static_cast<std::uint8_t>(c);
    used[static_cast<std::size_t>(a)] |= std::uint64_t{ 1 } << c;
    used[static_cast<std::size_t>(b)] |= std::uint64_t{ 1 } << c;
    ++start[c + 1];
  }
  for (int c = 0; c < kColours; ++c)
    start[c + 1] += start[c];
  EdgeColouring colouring;
  for (int c = 0; c <= kColours; ++c)
    if (c == 0 || start[c] != start[c - 1])
      colouring.colour_starts.push_back(start[c]);
  colouring.last_shares_nodes = start[kColours] != start[kColours - 1];
  colouring.order.resize(rows.size());
  for (std::size_t k = 0; k < rows.size(); ++k)
    colouring.order[start[colour[k]]++] = rows[k];
  return colouring;
}

}  // namespace soft_body_sim
