// Four nodes' columns as AVX2 registers, for the kernels that update four elements at once (springs, xpbd
// rows) on a processor that has AVX2 (hasWideLanes). Each function is compiled for AVX2 alone, without
// FMA: lane by lane the same operations and roundings as the scalar and the two-lane (column_packets.h)
// kernels, so the same bits on every processor.
#pragma once

#include <cstddef>

#include <immintrin.h>

namespace soft_body_sim
{
/// A helper of the four-lane kernels: compiled for AVX2 and inlined into them (functions compiled for AVX2
/// alone, `[[gnu::target("avx2")]]`, which a caller runs only where hasWideLanes).
#define SOFT_BODY_SIM_WIDE [[gnu::target("avx2"), gnu::always_inline]] inline

/// Whether the four-lane kernels run: the processor has AVX2 (asked once), unless useWideLanes(false).
bool hasWideLanes();
/// With false, the kernels take the two lanes (column_packets.h) that a processor without AVX2 takes; with
/// true, four again where the processor has AVX2. For the tests, which check that both give the same bits.
void useWideLanes(bool on);

/// Columns i[0..3] of a 3 x N column-major array as (x_i0, ..., x_i3), (y_...), (z_...).
struct ColumnQuad
{
  __m256d x, y, z;
};

/// Each column's (x, y) loaded whole and transposed in registers, its z gathered by lanes; no load leaves
/// the array.
SOFT_BODY_SIM_WIDE ColumnQuad loadColumns4(const double* array, const std::ptrdiff_t i[4])
{
  const double* const c0 = array + 3 * i[0];
  const double* const c1 = array + 3 * i[1];
  const double* const c2 = array + 3 * i[2];
  const double* const c3 = array + 3 * i[3];
  // (x0, y0, x2, y2) and (x1, y1, x3, y3)
  const __m256d xy_02 = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(c0)), _mm_loadu_pd(c2), 1);
  const __m256d xy_13 = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(c1)), _mm_loadu_pd(c3), 1);
  const __m128d z_01 = _mm_loadh_pd(_mm_load_sd(c0 + 2), c1 + 2);
  const __m128d z_23 = _mm_loadh_pd(_mm_load_sd(c2 + 2), c3 + 2);
  return { _mm256_unpacklo_pd(xy_02, xy_13), _mm256_unpackhi_pd(xy_02, xy_13),
           _mm256_insertf128_pd(_mm256_castpd128_pd256(z_01), z_23, 1) };
}

/// Lane l's (x, y) of two packets x, y as SSE2 halves, for the lanes' scatters: xy[l] = (x_l, y_l).
SOFT_BODY_SIM_WIDE void lanePairs(__m256d x, __m256d y, __m128d xy[4])
{
  const __m256d low = _mm256_unpacklo_pd(x, y);   // (x0, y0, x2, y2)
  const __m256d high = _mm256_unpackhi_pd(x, y);  // (x1, y1, x3, y3)
  xy[0] = _mm256_castpd256_pd128(low);
  xy[1] = _mm256_castpd256_pd128(high);
  xy[2] = _mm256_extractf128_pd(low, 1);
  xy[3] = _mm256_extractf128_pd(high, 1);
}

/// Columns i .. i + 3 of a 3 x N column-major array, the twelve doubles from `column` (a run's ends), by
/// three loads transposed in registers.
SOFT_BODY_SIM_WIDE ColumnQuad loadRun4(const double* column)
{
  const __m256d lo = _mm256_loadu_pd(column);        // x0 y0 z0 x1
  const __m256d mid = _mm256_loadu_pd(column + 4);   // y1 z1 x2 y2
  const __m256d hi = _mm256_loadu_pd(column + 8);    // z2 x3 y3 z3
  const __m256d xy = _mm256_blend_pd(lo, mid, 0b1100);         // x0 y0 x2 y2
  const __m256d zx = _mm256_permute2f128_pd(lo, hi, 0x21);     // z0 x1 z2 x3
  const __m256d yz = _mm256_blend_pd(mid, hi, 0b1100);         // y1 z1 y3 z3
  return { _mm256_blend_pd(xy, zx, 0b1010), _mm256_shuffle_pd(xy, yz, 0b0101), _mm256_blend_pd(zx, yz, 0b1010) };
}

/// The twelve doubles from `column` (columns i .. i + 3) plus (sign 1) or minus (sign -1) the columns
/// (x_l, y_l, z_l) of the lanes, each double by one addition or subtraction.
template <int sign>
SOFT_BODY_SIM_WIDE void addToRun4(double* column, __m256d x, __m256d y, __m256d z)
{
  const __m256d xy = _mm256_unpacklo_pd(x, y);         // x0 y0 x2 y2
  const __m256d yz = _mm256_unpackhi_pd(y, z);         // y1 z1 y3 z3
  const __m256d zx = _mm256_shuffle_pd(z, x, 0b1010);  // z0 x1 z2 x3
  const __m256d part[3] = { _mm256_permute2f128_pd(xy, zx, 0x20), _mm256_blend_pd(yz, xy, 0b1100),
                            _mm256_permute2f128_pd(zx, yz, 0x31) };
  for (int p = 0; p < 3; ++p)
  {
    const __m256d now = _mm256_loadu_pd(column + 4 * p);
    _mm256_storeu_pd(column + 4 * p, sign > 0 ? now + part[p] : now - part[p]);
  }
}

}  // namespace soft_body_sim
