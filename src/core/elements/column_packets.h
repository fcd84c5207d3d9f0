// Two nodes' columns as SIMD packets, for the kernels that update two elements at once (springs, xpbd rows).
#pragma once

#include <cstddef>

#include <Eigen/Core>

#include <emmintrin.h>

namespace soft_body_sim
{
/// One of Eigen's packets of two doubles (SSE2's register); GCC and Clang give such a vector type the
/// arithmetic operators, lane by lane with the same rounding as the scalar ones.
using Packet = Eigen::internal::Packet2d;

/// Columns i0 and i1 of a 3 x N column-major array as the packets (x_i0, x_i1), (y_i0, y_i1), (z_i0, z_i1).
struct ColumnPair
{
  Packet x, y, z;
};

/// (x, y) and (y, z) of each column loaded whole and transposed in registers: a packet built lane by lane
/// in memory is read before its halves' stores can be forwarded (the stall the profile showed), and no
/// load leaves the array.
inline ColumnPair loadColumns(const double* array, std::ptrdiff_t i0, std::ptrdiff_t i1)
{
  const Packet xy_0 = Eigen::internal::ploadu<Packet>(array + 3 * i0);
  const Packet xy_1 = Eigen::internal::ploadu<Packet>(array + 3 * i1);
  const Packet yz_0 = Eigen::internal::ploadu<Packet>(array + 3 * i0 + 1);
  const Packet yz_1 = Eigen::internal::ploadu<Packet>(array + 3 * i1 + 1);
  return { Eigen::internal::vec2d_unpacklo(xy_0, xy_1), Eigen::internal::vec2d_unpackhi(xy_0, xy_1),
           Eigen::internal::vec2d_unpackhi(yz_0, yz_1) };
}

/// Column i of a 3 x N column-major array plus (xy, z), and minus: one element's share on each of its two
/// ends, lane by lane in the scatters of the two- and four-lane kernels.
[[gnu::always_inline]] inline void addToColumn(double* array, std::ptrdiff_t i, const Packet& xy, double z)
{
  double* const column = array + 3 * i;
  _mm_storeu_pd(column, _mm_loadu_pd(column) + xy);
  column[2] += z;
}
[[gnu::always_inline]] inline void subtractFromColumn(double* array, std::ptrdiff_t i, const Packet& xy, double z)
{
  double* const column = array + 3 * i;
  _mm_storeu_pd(column, _mm_loadu_pd(column) - xy);
  column[2] -= z;
}

}  // namespace soft_body_sim
