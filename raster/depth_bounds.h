// Bounds for the hierarchical depth test of the depth passes
// (depth_pass.cpp, depth_only_pass.cpp): the largest key stored in a
// block, and lower bounds of the keys a triangle can write over a block or
// anywhere inside itself.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "raster/block_coverage.h"
#include "raster/depth.h"
#include "raster/setup.h"

namespace rastray {

// Set bits of a mask (x86-64's baseline has no POPCNT, so the builtin
// would call libgcc).
inline int bitCount(uint64_t m) {
  m = m - ((m >> 1) & 0x5555555555555555ull);
  m = (m & 0x3333333333333333ull) + ((m >> 2) & 0x3333333333333333ull);
  m = (m + (m >> 4)) & 0x0F0F0F0F0F0F0F0Full;
  return int((m * 0x0101010101010101ull) >> 56);
}

// The largest of n keys.
inline uint32_t maxKey(const uint32_t* keys, size_t n) {
  size_t i = 0;
  uint32_t m = 0;
#if defined(__SSE2__)
  // SSE2 has no unsigned 32-bit max: flip the sign bits, compare signed,
  // select, flip back.
  const __m128i flip = _mm_set1_epi32(int32_t(0x80000000u));
  __m128i acc = flip;  // 0 flipped
  for (; i + 4 <= n; i += 4) {
    const __m128i k = _mm_xor_si128(_mm_loadu_si128(reinterpret_cast<const __m128i*>(keys + i)), flip);
    const __m128i gt = _mm_cmpgt_epi32(k, acc);
    acc = _mm_or_si128(_mm_and_si128(gt, k), _mm_andnot_si128(gt, acc));
  }
  alignas(16) uint32_t lanes[4];
  _mm_store_si128(reinterpret_cast<__m128i*>(lanes), _mm_xor_si128(acc, flip));
  m = std::max(std::max(lanes[0], lanes[1]), std::max(lanes[2], lanes[3]));
#endif
  for (; i < n; ++i) m = std::max(m, keys[i]);
  return m;
}

// A lower bound of the key t gets at any sample in the box [xa, xb] ×
// [ya, yb] (pixels) of the depth plane, or, with `vertices`, at any sample
// inside the triangle (its exact plane values there lie between those at
// the snapped vertices, which are then used as the box's corners). Widened
// by a margin for rounding: Plane::at evaluates v0 + dx·(x − x0) + dy·(y −
// y0) in double; with u = 2^-53 each of its five operations errs by at
// most u relative, and the position x (px + ox, or a vertex ÷ U) by u·|x|,
// so a computed sample value lies within ≈ 5u·(|v0| + |dx·(x − x0)| +
// |dy·(y − y0)| + |dx·x| + |dy·y|) of the exact plane at the exact
// position, and so does the bound computed here: the margin 2^-45 times
// that sum (its largest over the corners; the sample's own lies between)
// covers both with a wide slack. depthKey is monotone in z
// (non-decreasing, non-increasing for reversed formats), so the key of the
// widened extreme bounds every sample's key. 0 (no bound) when the plane
// is not finite there.
inline uint32_t minKeyOf(DepthFormat format, const Plane& p, const double (&x)[3], const double (&y)[3],
                         int n) {
  double lo = INFINITY, hi = -INFINITY, size = 0.0;
  for (int i = 0; i < n; ++i) {
    const double u = p.dx * (x[i] - p.x0), v = p.dy * (y[i] - p.y0);
    const double z = p.v0 + u + v;
    lo = std::min(lo, z);
    hi = std::max(hi, z);
    size = std::max(
        size, std::abs(p.v0) + std::abs(u) + std::abs(v) + std::abs(p.dx * x[i]) + std::abs(p.dy * y[i]));
  }
  const double margin =
      size * 0x1p-45;  // = ldexp(size, -45) (a power of two scales exactly), without the libm call
  if (!std::isfinite(lo) || !std::isfinite(hi) || !std::isfinite(margin)) return 0;
  return isReversed(format) ? depthKey(format, hi + margin) : depthKey(format, lo - margin);
}

// Over the box of block b's sample positions: its four corners, as the
// plane is affine (the extremes of an affine function over a box).
inline uint32_t minKeyOverBlock(const TriangleSetup& t, DepthFormat format, const PixelBlock& b,
                                const glm::dvec2& lowPos, const glm::dvec2& highPos) {
  const double xa = double(b.x) + lowPos.x, xb = double(b.x + b.w - 1) + highPos.x;
  const double ya = double(b.y) + lowPos.y, yb = double(b.y + b.h - 1) + highPos.y;
  const Plane& p = t.depth;
  // The corner minimising (maximising) each term: the affine extremes.
  const double x[3] = {p.dx >= 0 ? xa : xb, p.dx >= 0 ? xb : xa, 0.0};
  const double y[3] = {p.dy >= 0 ? ya : yb, p.dy >= 0 ? yb : ya, 0.0};
  return minKeyOf(format, p, x, y, 2);
}

// Over the triangle: its three snapped vertices.
inline uint32_t minKeyOverTriangle(const TriangleSetup& t, DepthFormat format, int64_t U) {
  double x[3], y[3];
  // Units per pixel are a power of two for every pattern but the odd
  // grids: then dividing is multiplying by the exact reciprocal (the same
  // bits, without six divisions per triangle).
  if ((U & (U - 1)) == 0) {
    const double inv = 1.0 / double(U);
    for (int i = 0; i < 3; ++i) {
      x[i] = double(t.vertex[i].x) * inv;
      y[i] = double(t.vertex[i].y) * inv;
    }
  } else {
    for (int i = 0; i < 3; ++i) {
      x[i] = double(t.vertex[i].x) / double(U);  // rounded only when k > 1: in the margin
      y[i] = double(t.vertex[i].y) / double(U);
    }
  }
  return minKeyOf(format, t.depth, x, y, 3);
}

}  // namespace rastray
