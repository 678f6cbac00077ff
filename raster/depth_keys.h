// Depth keys of a triangle's depth plane over a row of eight sample
// positions, in SIMD doubles, with the same bits as the per-sample scalar
// depthKey(format, plane.at(x, y)) (coverage.h sampleDepthKey).
//
// Why the bits agree: Plane::at evaluates (v0 + dx·(x − x0)) + dy·(y − y0)
// left to right. The first sum depends on the column only and the second
// product on the row only, so the row's values are columnTerm[i] + rowTerm,
// the same IEEE double operations in the same order, one addition per
// sample (x86-64's baseline has no FMA, so the scalar path contracts
// nothing either; a build with -mfma -ffp-contract=fast would break this,
// and the equivalence tests would say so). The clamp to [0, 1] is
// max(0, z) then min(1, z) with the operands in the order that returns z
// itself for NaN and −0 (MAXPD/MINPD return their second operand when
// unordered or equal), as std::clamp does; the conversion to float rounds
// to nearest even in both (CVTPD2PS, CVTSD2SS). Unorm formats take the
// scalar lround per lane on the same doubles. The one exception: when both
// terms are NaN (a plane that is not finite, which setup does not make),
// the sum is either operand's NaN, as the compiler orders the commuting
// addition, in the scalar path too.
#pragma once

#include <cstdint>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "raster/depth.h"
#include "raster/setup.h"

namespace rastray {

// v0 + dx·(x − x0) at the eight columns x = px0 + i + offsetX (i < 8):
// the column part of Plane::at.
// double(px0 + i) is double(px0) + i exactly (integers below 2^53), so the
// SIMD form performs the scalar operations on the same values.
inline void planeColumnTerms(const Plane& p, int px0, double offsetX, double (&column)[8]) {
#if defined(__SSE2__)
  const __m128d x0 = _mm_set1_pd(double(px0)), ox = _mm_set1_pd(offsetX), origin = _mm_set1_pd(p.x0);
  const __m128d dx = _mm_set1_pd(p.dx), v0 = _mm_set1_pd(p.v0);
  for (int i = 0; i < 8; i += 2) {
    const __m128d x = _mm_add_pd(x0, _mm_set_pd(double(i + 1), double(i)));
    _mm_storeu_pd(column + i, _mm_add_pd(v0, _mm_mul_pd(dx, _mm_sub_pd(_mm_add_pd(x, ox), origin))));
  }
#else
  for (int i = 0; i < 8; ++i) column[i] = p.v0 + p.dx * ((double(px0 + i) + offsetX) - p.x0);
#endif
}

// dy·(y − y0) at y = py + offsetY: the row part of Plane::at.
inline double planeRowTerm(const Plane& p, int py, double offsetY) {
  return p.dy * ((double(py) + offsetY) - p.y0);
}

#if defined(__SSE2__)
// The eight keys as two vectors (lanes 0–3, 4–7), float formats only.
inline void floatRowKeys(bool reversed, const double (&column)[8], double row, __m128i& lo, __m128i& hi) {
  const __m128d r = _mm_set1_pd(row), zero = _mm_setzero_pd(), one = _mm_set1_pd(1.0);
  const auto clamped = [&](int i) {
    const __m128d z = _mm_add_pd(_mm_loadu_pd(column + i), r);
    return _mm_cvtpd_ps(_mm_min_pd(one, _mm_max_pd(zero, z)));  // NaN and −0 pass through, as std::clamp
  };
  lo = _mm_castps_si128(_mm_movelh_ps(clamped(0), clamped(2)));
  hi = _mm_castps_si128(_mm_movelh_ps(clamped(4), clamped(6)));
  if (reversed) {
    const __m128i oneBits = _mm_set1_epi32(0x3F800000);  // depthKey: kOneBits − bits
    lo = _mm_sub_epi32(oneBits, lo);
    hi = _mm_sub_epi32(oneBits, hi);
  }
}
#endif

#if defined(__SSE2__)
// The float keys of four samples of pixel (px, py), at the positions
// (px + qx[k], py + qy[k]), k < 4, as one vector (lane k: sample k):
// Plane::at's operations per lane in its order, (v0 + dx·(x − x0)) +
// dy·(y − y0) with x = px + qx[k], then floatRowKeys' clamp, conversion
// and reversal, so depthKey's bits (the same argument as above).
inline __m128i pixelSampleKeys(bool reversed, const Plane& p, int px, int py, const double* qx,
                               const double* qy) {
  const __m128d x = _mm_set1_pd(double(px)), y = _mm_set1_pd(double(py));
  const __m128d v0 = _mm_set1_pd(p.v0), dx = _mm_set1_pd(p.dx), dy = _mm_set1_pd(p.dy);
  const __m128d x0 = _mm_set1_pd(p.x0), y0 = _mm_set1_pd(p.y0);
  const __m128d zero = _mm_setzero_pd(), one = _mm_set1_pd(1.0);
  const auto clamped = [&](int k) {
    const __m128d u = _mm_add_pd(v0, _mm_mul_pd(dx, _mm_sub_pd(_mm_add_pd(x, _mm_loadu_pd(qx + k)), x0)));
    const __m128d z = _mm_add_pd(u, _mm_mul_pd(dy, _mm_sub_pd(_mm_add_pd(y, _mm_loadu_pd(qy + k)), y0)));
    return _mm_cvtpd_ps(_mm_min_pd(one, _mm_max_pd(zero, z)));  // NaN and −0 pass through, as std::clamp
  };
  const __m128i bits = _mm_castps_si128(_mm_movelh_ps(clamped(0), clamped(2)));
  return reversed ? _mm_sub_epi32(_mm_set1_epi32(0x3F800000), bits) : bits;  // depthKey: kOneBits − bits
}
#endif

// keys[i] = depthKey(format, column[i] + row), bit for bit.
inline void planeRowKeys(DepthFormat format, const double (&column)[8], double row, uint32_t (&keys)[8]) {
#if defined(__SSE2__)
  if (format == DepthFormat::FloatReversed || format == DepthFormat::Float) {
    __m128i lo, hi;
    floatRowKeys(format == DepthFormat::FloatReversed, column, row, lo, hi);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(keys), lo);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(keys + 4), hi);
    return;
  }
#endif
  for (int i = 0; i < 8; ++i) keys[i] = depthKey(format, column[i] + row);
}

}  // namespace rastray
