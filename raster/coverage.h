// Coverage and depth test: per-sample coverage with the integer edge
// functions of setup.h, the per-sample depth keys and the depth test (the
// stage between setup/binning and shading).
//
// Two coverage walks give the same samples in the same (py, px, s) order:
//
//   forEachCoveredSampleReference  the scalar reference: every pixel of the
//       bounding box, E at the pixel corner stepped incrementally plus a
//       per-sample constant a·ox + b·oy; a pixel is skipped at once when
//       one edge is negative at all of its samples.
//   forEachCoveredSample           block by block (block_coverage.h): the
//       bounding box ∩ rect in blocks of kCoverageBlock² pixels aligned to
//       the rect, rejected or accepted whole from exact int64 extremes,
//       and per-sample masks only where an edge crosses the block.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <vector>

#include "common/trace.h"
#include "raster/bin.h"
#include "raster/block_coverage.h"
#include "raster/depth.h"
#include "raster/setup.h"

namespace rastray {

constexpr uint32_t kNoSetup = 0xFFFFFFFFu;

// Which coverage walk a pass uses (the results are identical; Reference is
// kept for the tests that prove it).
enum class CoveragePath { Fast, Reference };

namespace coverage_detail {

// The per-pixel tests of the pixels [xa, xb] of row py (the reference
// walk's inner loop).
template <typename F>
inline void coverRow(const TriangleSetup& t, const CoverageScratch& scratch, int spp, int64_t U, int xa,
                     int xb, int py, F& f) {
  int64_t e0 = t.edge[0].at(int64_t(xa) * U, int64_t(py) * U) + t.edge[0].bias;
  int64_t e1 = t.edge[1].at(int64_t(xa) * U, int64_t(py) * U) + t.edge[1].bias;
  int64_t e2 = t.edge[2].at(int64_t(xa) * U, int64_t(py) * U) + t.edge[2].bias;
  const int64_t s0 = t.edge[0].a * U, s1 = t.edge[1].a * U, s2 = t.edge[2].a * U;
  const int64_t* o0 = scratch.offsets[0].data();
  const int64_t* o1 = scratch.offsets[1].data();
  const int64_t* o2 = scratch.offsets[2].data();
  const int64_t m0 = scratch.maxOffset[0], m1 = scratch.maxOffset[1], m2 = scratch.maxOffset[2];
  for (int px = xa; px <= xb; ++px, e0 += s0, e1 += s1, e2 += s2) {
    if (e0 + m0 < 0 || e1 + m1 < 0 || e2 + m2 < 0) continue;
    for (int s = 0; s < spp; ++s)
      if (e0 + o0[s] >= 0 && e1 + o1[s] >= 0 && e2 + o2[s] >= 0) f(px, py, s);
  }
}

}  // namespace coverage_detail

// The bounding box of t ∩ rect, inclusive pixels; empty when x0 > x1 or y0 > y1.
struct PixelBounds {
  int x0, y0, x1, y1;
  bool empty() const { return x0 > x1 || y0 > y1; }
  uint64_t samples(int spp) const { return uint64_t(x1 - x0 + 1) * uint64_t(y1 - y0 + 1) * uint64_t(spp); }
};
inline PixelBounds boundsIn(const TriangleSetup& t, const TileRect& rect) {
  return {std::max(rect.x0, t.pixelMin.x), std::max(rect.y0, t.pixelMin.y),
          std::min(rect.x1 - 1, t.pixelMax.x), std::min(rect.y1 - 1, t.pixelMax.y)};
}

// Calls f(px, py, s) for each sample of t inside `rect` that the fill rule
// assigns to t, in (py, px, s) order, testing every pixel of the bounding
// box (the reference). Returns the number of samples whose coverage was
// evaluated (bounding box ∩ rect).
template <typename F>
uint64_t forEachCoveredSampleReference(const TriangleSetup& t, const SampleGrid& grid, const TileRect& rect,
                                       CoverageScratch& scratch, F&& f) {
  const PixelBounds r = boundsIn(t, rect);
  if (r.empty()) return 0;
  prepareOffsets(t, grid, scratch);
  for (int py = r.y0; py <= r.y1; ++py)
    coverage_detail::coverRow(t, scratch, grid.spp, grid.unitsPerPixel, r.x0, r.x1, py, f);
  return r.samples(grid.spp);
}

// The same samples in the same order and the same return value as
// forEachCoveredSampleReference, block by block.
template <typename F>
uint64_t forEachCoveredSample(const TriangleSetup& t, const SampleGrid& grid, const TileRect& rect,
                              CoverageScratch& scratch, F&& f) {
  constexpr int B = kCoverageBlock;
  const PixelBounds r = boundsIn(t, rect);
  if (r.empty()) return 0;
  prepareOffsets(t, grid, scratch);
  const int spp = grid.spp;
  const int64_t U = grid.unitsPerPixel;
  const int bx0 = rect.x0 + (r.x0 - rect.x0) / B * B;
  const int blocks = (r.x1 - bx0) / B + 1;
  // One band of blocks at a time: masks per block and sample, then the
  // band's rows in order.
  scratch.blocks.resize(size_t(blocks));
  std::vector<uint64_t>& masks = scratch.bandMasks;
  masks.resize(size_t(blocks) * size_t(spp));
  for (int by = rect.y0 + (r.y0 - rect.y0) / B * B; by <= r.y1; by += B) {
    const int cy0 = std::max(by, r.y0), cy1 = std::min(by + B - 1, r.y1);
    int first = blocks, last = -1;
    for (int j = 0; j < blocks; ++j) {
      const int cx0 = std::max(bx0 + j * B, r.x0), cx1 = std::min(bx0 + j * B + B - 1, r.x1);
      const PixelBlock b{cx0, cy0, cx1 - cx0 + 1, cy1 - cy0 + 1};
      const bool any = coverBlock(t, scratch, U, spp, b, &masks[size_t(j) * size_t(spp)]);
      scratch.blocks[size_t(j)] = any;
      if (any) {
        first = std::min(first, j);
        last = j;
      }
    }
    for (int py = cy0; py <= cy1; ++py) {
      const int shift = 8 * (py - cy0);
      for (int j = first; j <= last; ++j) {
        if (!scratch.blocks[size_t(j)]) continue;
        const uint64_t* m = &masks[size_t(j) * size_t(spp)];
        const int cx0 = std::max(bx0 + j * B, r.x0);
        uint32_t row = 0;
        for (int s = 0; s < spp; ++s) row |= uint32_t(m[s] >> shift) & 0xFFu;
        while (row) {
          const int i = __builtin_ctz(row);
          row &= row - 1;
          for (int s = 0; s < spp; ++s)
            if ((m[s] >> (shift + i)) & 1u) f(cx0 + i, py, s);
        }
      }
    }
  }
  return r.samples(spp);
}

// Either walk.
template <typename F>
uint64_t forEachCoveredSample(CoveragePath path, const TriangleSetup& t, const SampleGrid& grid,
                              const TileRect& rect, CoverageScratch& scratch, F&& f) {
  return path == CoveragePath::Reference ? forEachCoveredSampleReference(t, grid, rect, scratch, f)
                                         : forEachCoveredSample(t, grid, rect, scratch, f);
}

// A per-sample depth target: keys (smaller = nearer) and the winning
// setup index over the pixels [x0, x0 + width) × [y0, y0 + height) (the
// whole image, origin 0, or one tile's rectangle: a tile-local target);
// sample (x, y, s) lives at (((y − y0)·width) + x − x0)·spp + s. Without
// winners (keysOnly) it is a plain depth map.
struct DepthTarget {
  int width = 0, height = 0, spp = 1;
  int x0 = 0, y0 = 0;  // the first pixel stored
  std::vector<uint32_t> keys;
  std::vector<uint32_t> winners;
  DepthTarget() = default;
  DepthTarget(int w, int h, int samples, bool keysOnly = false)
      : width(w),
        height(h),
        spp(samples),
        keys(size_t(w) * size_t(h) * size_t(samples), kClearDepthKey),
        winners(keysOnly ? 0 : keys.size(), kNoSetup) {}
  size_t index(int x, int y, int s) const {
    return (size_t(y - y0) * size_t(width) + size_t(x - x0)) * size_t(spp) + size_t(s);
  }
};

struct DepthPassCounters {
  uint64_t coverageTests = 0;  // samples in bounding boxes
  uint64_t samplesTested = 0;  // covered samples that reached the depth test
  uint64_t samplesPassed = 0;  // ... and passed it (written)
  uint64_t alphaRejected = 0;  // MASK samples below the cutoff
};

// Window depth key of t at sample s of pixel (px, py).
inline uint32_t sampleDepthKey(const TriangleSetup& t, const SampleGrid& grid, DepthFormat format, int px,
                               int py, int s) {
  const glm::dvec2 p = glm::dvec2(px, py) + grid.positions[size_t(s)];
  return depthKey(format, t.depth.at(p.x, p.y));
}

// Pass 1 of a tile: depth test and write for the setups in `bin` (OPAQUE and
// MASK). `alphaTest`, when set, decides MASK coverage for a sample that
// passed the depth test (true: covered). `trace` (the caller passes an
// empty request unless its pixel lies in `rect`) receives, at that pixel,
// every triangle's setup and coverage (traceCoverage), each depth test
// (key against the stored key and winner) and each MASK discard. `path`
// picks the coverage walk (identical results). `clearedRect`: the
// target's samples in `rect` all hold kClearDepthKey (a tile's fresh
// target, as the camera pass gives it); the hierarchical depth test then
// knows a block still holds a cleared sample while fewer samples were
// written there than it has, without reading its keys (the same keys,
// winners and counters).
void rasterDepthPass(const std::vector<TriangleSetup>& setups, const std::vector<uint32_t>& bin,
                     const SampleGrid& grid, const TileRect& rect, DepthFormat format, DepthFunc func,
                     const std::function<bool(const TriangleSetup&, int px, int py, int s)>& alphaTest,
                     const TraceRequest& trace, DepthTarget* target, DepthPassCounters* counters,
                     CoveragePath path = CoveragePath::Fast, bool clearedRect = false);

// Records t's setup (facing, snapped vertices and edge functions with their
// fill-rule class, in fixed-point units of 1/unitsPerPixel pixel) and, at
// every sample of pixel (px, py), the three edge values and whether the
// fill rule covers it.
void traceCoverage(TraceSink& sink, const TriangleSetup& t, const SampleGrid& grid, int px, int py);

}  // namespace rastray
