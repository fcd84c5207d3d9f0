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

/// Columns i and i + 1 of a 3 x N column-major array, the six doubles from `column` (a run's ends).
inline ColumnPair loadRun2(const double* column)
{
  const Packet xy = _mm_loadu_pd(column);      // x0 y0
  const Packet zx = _mm_loadu_pd(column + 2);  // z0 x1
  const Packet yz = _mm_loadu_pd(column + 4);  // y1 z1
  return { _mm_shuffle_pd(xy, zx, 0b10), _mm_shuffle_pd(xy, yz, 0b01), _mm_shuffle_pd(zx, yz, 0b10) };
}

/// The six doubles from `column` (columns i, i + 1) plus (sign 1) or minus (sign -1) the lanes' columns.
template <int sign>
inline void addToRun2(double* column, const Packet& x, const Packet& y, const Packet& z)
{
  const Packet part[3] = { _mm_unpacklo_pd(x, y), _mm_shuffle_pd(z, x, 0b10), _mm_unpackhi_pd(y, z) };
  for (int p = 0; p < 3; ++p)
  {
    const Packet now = _mm_loadu_pd(column + 2 * p);
    _mm_storeu_pd(column + 2 * p, sign > 0 ? now + part[p] : now - part[p]);
  }
}

}  // namespace soft_body_sim
