// Block coverage: the fill-rule coverage of a triangle over a block of at
// most kCoverageBlock × kCoverageBlock pixels, as one bit mask per sample,
// exactly the samples the per-sample test E + bias >= 0 of setup.h accepts.
//
// A block is first classified from its extremes: E is affine, so its
// largest (smallest) value over the block's samples is E at the block's
// top-left pixel corner plus, per axis, the step a·U or b·U times
// (pixels − 1) when that step is positive (negative), plus the largest
// (smallest) sample offset a·ox + b·oy. Every partial sum is E (or E's
// linear part) at a pixel corner or sample inside the image, so setup.h's
// bound |E| <= 2^61 covers each intermediate: exact int64. A block whose
// samples all fail one edge is rejected; one whose samples all pass every
// edge is accepted without per-sample tests.
//
// Partial blocks compute their masks in int32 when they can (the proof):
// with lo = the block's smallest E + bias (< 0, else the edge passes
// everywhere) and range = hi − lo = |a·U|(w−1) + |b·U|(h−1) + (maxOffset −
// minOffset), write E + bias at pixel (i, j), sample s as lo + rel with
//   rel = (a·U·i − min(0, a·U(w−1))) + (b·U·j − min(0, b·U(h−1))) + (o_s − minOffset),
// three terms each in [0, their part of range]. When range <= 2^31 − 1,
// rel and the threshold T = −lo (0 < T <= range, as hi >= 0 for a block
// that is not rejected) fit int32 and E + bias >= 0 ⟺ rel >= T exactly;
// the eight pixels of a row are then compared in one pair of SSE2
// registers (baseline x86-64, no CPU-specific build; other targets run the
// same int32 arithmetic in a loop the compiler may vectorise). Larger
// ranges (only triangles thousands of pixels wide) take the int64
// per-sample test.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "raster/setup.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace rastray {

constexpr int kCoverageBlock = 8;  // pixels per block side (a row is one byte of a mask)

// Per-triangle scratch for the sample offsets of the three edges.
struct CoverageScratch {
  std::vector<int64_t> offsets[3];
  int64_t maxOffset[3] = {0, 0, 0};
  int64_t minOffset[3] = {0, 0, 0};
  std::vector<uint64_t> masks;      // per sample of a block (blockMasks)
  std::vector<uint64_t> bandMasks;  // per block and sample of a band (the ordered walk)
  std::vector<uint8_t> blocks;      // per block of a band: any sample covered
};

enum class BlockClass : uint8_t { Reject, Accept, Partial };

// A block: pixels [x, x + w) × [y, y + h), w, h <= kCoverageBlock; bit
// j·8 + i of a mask is pixel (x + i, y + j).
struct PixelBlock {
  int x = 0, y = 0, w = 0, h = 0;
};

// a·ox + b·oy per edge and sample, with their extremes.
inline void prepareOffsets(const TriangleSetup& t, const SampleGrid& grid, CoverageScratch& scratch) {
  const int spp = grid.spp;
  for (int e = 0; e < 3; ++e) {
    scratch.offsets[e].resize(size_t(spp));
    int64_t hi = INT64_MIN, lo = INT64_MAX;
    for (int s = 0; s < spp; ++s) {
      const int64_t o = t.edge[e].a * grid.offsets[size_t(s)].x + t.edge[e].b * grid.offsets[size_t(s)].y;
      scratch.offsets[e][size_t(s)] = o;
      hi = std::max(hi, o);
      lo = std::min(lo, o);
    }
    scratch.maxOffset[e] = hi;
    scratch.minOffset[e] = lo;
  }
  scratch.masks.resize(size_t(spp));
}

// Classifies block b; lo[e] receives each edge's smallest E + bias over the
// block's samples (valid unless rejected).
inline BlockClass classifyBlock(const TriangleSetup& t, const CoverageScratch& scratch, int64_t U,
                                const PixelBlock& b, int64_t lo[3]) {
  BlockClass c = BlockClass::Accept;
  for (int e = 0; e < 3; ++e) {
    const EdgeFunction& f = t.edge[e];
    const int64_t corner = f.at(int64_t(b.x) * U, int64_t(b.y) * U) + f.bias;
    const int64_t dx = f.a * U * (b.w - 1), dy = f.b * U * (b.h - 1);
    const int64_t hi = corner + std::max<int64_t>(dx, 0) + std::max<int64_t>(dy, 0) + scratch.maxOffset[e];
    if (hi < 0) return BlockClass::Reject;
    lo[e] = corner + std::min<int64_t>(dx, 0) + std::min<int64_t>(dy, 0) + scratch.minOffset[e];
    if (lo[e] < 0) c = BlockClass::Partial;
  }
  return c;
}

// The mask of every pixel of b (an accepted block).
inline uint64_t fullBlockMask(const PixelBlock& b) {
  const uint64_t row = (uint64_t(1) << b.w) - 1;
  uint64_t m = 0;
  for (int j = 0; j < b.h; ++j) m |= row << (8 * j);
  return m;
}

namespace block_detail {

// The int64 per-sample test over a block (ranges beyond int32).
inline void masksInt64(const TriangleSetup& t, const CoverageScratch& scratch, int64_t U, int spp,
                       const PixelBlock& b, uint64_t* masks) {
  for (int s = 0; s < spp; ++s) masks[s] = 0;
  for (int j = 0; j < b.h; ++j)
    for (int i = 0; i < b.w; ++i) {
      const int64_t px = int64_t(b.x + i) * U, py = int64_t(b.y + j) * U;
      const int64_t e0 = t.edge[0].at(px, py) + t.edge[0].bias;
      const int64_t e1 = t.edge[1].at(px, py) + t.edge[1].bias;
      const int64_t e2 = t.edge[2].at(px, py) + t.edge[2].bias;
      for (int s = 0; s < spp; ++s)
        if (e0 + scratch.offsets[0][size_t(s)] >= 0 && e1 + scratch.offsets[1][size_t(s)] >= 0 &&
            e2 + scratch.offsets[2][size_t(s)] >= 0)
          masks[s] |= uint64_t(1) << (8 * j + i);
    }
}

}  // namespace block_detail

// Coverage masks of a partial block (lo from classifyBlock): masks[s] for
// s < spp.
inline void blockMasks(const TriangleSetup& t, const CoverageScratch& scratch, int64_t U, int spp,
                       const PixelBlock& b, const int64_t lo[3], uint64_t* masks) {
  // Per edge that some sample fails: lane terms, row base and threshold
  // (the int32 form above).
  int32_t lane[3][8], rowBase[3], threshold[3];
  int64_t rowStep[3];
  int active[3], n = 0;
  for (int e = 0; e < 3; ++e) {
    if (lo[e] >= 0) continue;  // every sample passes this edge
    const int64_t A = t.edge[e].a * U, Bv = t.edge[e].b * U;
    const int64_t minAx = std::min<int64_t>(A * (b.w - 1), 0), minBy = std::min<int64_t>(Bv * (b.h - 1), 0);
    const int64_t range = (A * (b.w - 1) - 2 * minAx) + (Bv * (b.h - 1) - 2 * minBy) +
                          (scratch.maxOffset[e] - scratch.minOffset[e]);
    if (range > INT32_MAX) {
      block_detail::masksInt64(t, scratch, U, spp, b, masks);
      return;
    }
    for (int i = 0; i < 8; ++i) lane[n][i] = int32_t(A * std::min(i, b.w - 1) - minAx);
    rowStep[n] = Bv;
    rowBase[n] = int32_t(-minBy);
    threshold[n] = int32_t(-lo[e]);
    active[n++] = e;
  }
  const uint32_t columns = (1u << b.w) - 1;
  for (int s = 0; s < spp; ++s) {
    int32_t sampleTerm[3];
    for (int k = 0; k < n; ++k)
      sampleTerm[k] = int32_t(scratch.offsets[active[k]][size_t(s)] - scratch.minOffset[active[k]]);
    uint64_t m = 0;
    for (int j = 0; j < b.h; ++j) {
      uint32_t row = columns;
#if defined(__SSE2__)
      for (int k = 0; k < n; ++k) {
        // b·U·j − minBy + o_s − minOffset: the row's part of rel, in [0, range].
        const int32_t base = int32_t(rowStep[k] * j + rowBase[k]) + sampleTerm[k];
        const __m128i vb = _mm_set1_epi32(base), vt = _mm_set1_epi32(threshold[k] - 1);
        const __m128i l0 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(lane[k]));
        const __m128i l1 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(lane[k] + 4));
        const __m128i c0 = _mm_cmpgt_epi32(_mm_add_epi32(l0, vb), vt);
        const __m128i c1 = _mm_cmpgt_epi32(_mm_add_epi32(l1, vb), vt);
        row &= uint32_t(_mm_movemask_ps(_mm_castsi128_ps(c0))) |
               (uint32_t(_mm_movemask_ps(_mm_castsi128_ps(c1))) << 4);
      }
#else
      for (int k = 0; k < n; ++k) {
        const int32_t base = int32_t(rowStep[k] * j + rowBase[k]) + sampleTerm[k];
        uint32_t bits = 0;
        for (int i = 0; i < 8; ++i) bits |= uint32_t(lane[k][i] + base >= threshold[k]) << i;
        row &= bits;
      }
#endif
      m |= uint64_t(row) << (8 * j);
    }
    masks[s] = m;
  }
}

// Covered samples of t in block b: masks[s] for s < spp; false when none.
inline bool coverBlock(const TriangleSetup& t, const CoverageScratch& scratch, int64_t U, int spp,
                       const PixelBlock& b, uint64_t* masks) {
  int64_t lo[3];
  switch (classifyBlock(t, scratch, U, b, lo)) {
    case BlockClass::Reject:
      return false;
    case BlockClass::Accept: {
      const uint64_t full = fullBlockMask(b);
      for (int s = 0; s < spp; ++s) masks[s] = full;
      return true;
    }
    case BlockClass::Partial:
      blockMasks(t, scratch, U, spp, b, lo, masks);
      break;
  }
  uint64_t any = 0;
  for (int s = 0; s < spp; ++s) any |= masks[s];
  return any != 0;
}

}  // namespace rastray
