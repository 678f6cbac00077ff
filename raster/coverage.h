// Coverage and depth test: per-sample coverage with the integer edge
// functions of setup.h, the per-sample depth keys and the depth test (the
// stage between setup/binning and shading).
//
// Coverage is stepped incrementally: E at a pixel's corner plus a
// per-sample constant a·ox + b·oy, all in exact int64 (setup.h proves the
// range). A pixel is skipped at once when one edge is negative at all of
// its samples.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <vector>

#include "common/trace.h"
#include "raster/bin.h"
#include "raster/depth.h"
#include "raster/setup.h"

namespace rastray {

constexpr uint32_t kNoSetup = 0xFFFFFFFFu;

// Per-triangle scratch for the sample offsets of the three edges.
struct CoverageScratch {
  std::vector<int64_t> offsets[3];
  int64_t maxOffset[3] = {0, 0, 0};
};

// Calls f(px, py, s) for each sample of t inside `rect` that the fill rule
// assigns to t, in (py, px, s) order. Returns the number of samples whose
// coverage was evaluated (bounding box ∩ rect).
template <typename F>
uint64_t forEachCoveredSample(const TriangleSetup& t, const SampleGrid& grid, const TileRect& rect,
                              CoverageScratch& scratch, F&& f) {
  const int x0 = std::max(rect.x0, t.pixelMin.x), x1 = std::min(rect.x1 - 1, t.pixelMax.x);
  const int y0 = std::max(rect.y0, t.pixelMin.y), y1 = std::min(rect.y1 - 1, t.pixelMax.y);
  if (x0 > x1 || y0 > y1) return 0;
  const int spp = grid.spp;
  const int64_t U = grid.unitsPerPixel;
  for (int e = 0; e < 3; ++e) {
    scratch.offsets[e].resize(size_t(spp));
    int64_t m = INT64_MIN;
    for (int s = 0; s < spp; ++s) {
      const int64_t o = t.edge[e].a * grid.offsets[size_t(s)].x + t.edge[e].b * grid.offsets[size_t(s)].y;
      scratch.offsets[e][size_t(s)] = o;
      m = std::max(m, o);
    }
    scratch.maxOffset[e] = m;
  }
  const int64_t* o0 = scratch.offsets[0].data();
  const int64_t* o1 = scratch.offsets[1].data();
  const int64_t* o2 = scratch.offsets[2].data();
  for (int py = y0; py <= y1; ++py) {
    // Edge values (with the fill-rule bias) at the top-left corner of pixel (x0, py).
    int64_t e0 = t.edge[0].at(int64_t(x0) * U, int64_t(py) * U) + t.edge[0].bias;
    int64_t e1 = t.edge[1].at(int64_t(x0) * U, int64_t(py) * U) + t.edge[1].bias;
    int64_t e2 = t.edge[2].at(int64_t(x0) * U, int64_t(py) * U) + t.edge[2].bias;
    const int64_t s0 = t.edge[0].a * U, s1 = t.edge[1].a * U, s2 = t.edge[2].a * U;
    for (int px = x0; px <= x1; ++px, e0 += s0, e1 += s1, e2 += s2) {
      if (e0 + scratch.maxOffset[0] < 0 || e1 + scratch.maxOffset[1] < 0 || e2 + scratch.maxOffset[2] < 0)
        continue;
      for (int s = 0; s < spp; ++s)
        if (e0 + o0[s] >= 0 && e1 + o1[s] >= 0 && e2 + o2[s] >= 0) f(px, py, s);
    }
  }
  return uint64_t(x1 - x0 + 1) * uint64_t(y1 - y0 + 1) * uint64_t(spp);
}

// A per-sample depth target: keys (smaller = nearer) and the winning
// setup index; sample (x, y, s) lives at ((y·width) + x)·spp + s. Without
// winners (keysOnly) it is a plain depth map.
struct DepthTarget {
  int width = 0, height = 0, spp = 1;
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
    return (size_t(y) * size_t(width) + size_t(x)) * size_t(spp) + size_t(s);
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
// (key against the stored key and winner) and each MASK discard.
void rasterDepthPass(const std::vector<TriangleSetup>& setups, const std::vector<uint32_t>& bin,
                     const SampleGrid& grid, const TileRect& rect, DepthFormat format, DepthFunc func,
                     const std::function<bool(const TriangleSetup&, int px, int py, int s)>& alphaTest,
                     const TraceRequest& trace, DepthTarget* target, DepthPassCounters* counters);

// Records t's setup (facing, snapped vertices and edge functions with their
// fill-rule class, in fixed-point units of 1/unitsPerPixel pixel) and, at
// every sample of pixel (px, py), the three edge values and whether the
// fill rule covers it.
void traceCoverage(TraceSink& sink, const TriangleSetup& t, const SampleGrid& grid, int px, int py);

}  // namespace rastray
