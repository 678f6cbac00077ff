// Pass 1 of a tile: OPAQUE and MASK triangles with depth test and write
// (coverage.h), then deferred shading: only the samples that won the depth
// test are shaded, at the sample (--shading-rate sample) or once per pixel
// and triangle with the pixel centre's footprint (--shading-rate pixel).
#include <algorithm>
#include <cstdio>
#include <functional>
#include <utility>

#include "common/primary_refinement.h"
#include "common/shading_kernel.h"
#include "raster/primary_samples.h"
#include "raster/tile_renderer.h"

namespace rastray {

void TileRenderer::opaquePass(const TileRect& rect, const std::vector<uint32_t>& bin,
                              const TraceRequest& trace, DepthTarget* target, ThreadCounters& n) const {
  std::function<bool(const TriangleSetup&, int, int, int)> alphaTest;
  if (analysis_.alphaTest)
    alphaTest = [this](const TriangleSetup& t, int px, int py, int s) { return alphaCovered(t, px, py, s); };
  rasterDepthPass(setups_, bin, grid_, rect, options_.depthFormat, options_.depthFunc, alphaTest, trace,
                  target, &n.opaque, coveragePath());
}

void TileRenderer::shadeVisible(const TileSampleIndex& index, const DepthTarget& target,
                                const TraceRequest& trace, bool allFronts, TileSamples& samples,
                                ThreadCounters& n) const {
  const TileRect& rect = index.rect;
  const int spp = grid_.spp;
  samples.color.assign(index.count(), glm::vec4(0.0f));
  samples.front.assign(index.count(), SampleHit{});
  // The tile's winning samples in three steps: gather the hits to shade
  // with their primary rays (in pixel and sample order), refine them on
  // their planes as one batch (common/primary_refinement.h), then shade
  // them as one batch through the shading kernel (common/shading_kernel.h),
  // the one the ray caster shades its primary hits with. Each sample takes the
  // colour of the hit it shaded or, at shading rate pixel, of the first
  // sample of its pixel on the same triangle. Per-thread scratch: no
  // allocation per tile once grown.
  struct Assignment {
    uint32_t local;    // TileSampleIndex
    uint32_t request;  // index into `requests`
  };
  thread_local std::vector<uint32_t> winners;       // setup per request
  thread_local std::vector<glm::dvec2> positions;   // image position per request
  thread_local std::vector<uint32_t> requestLocal;  // the sample a request is shaded at
  thread_local std::vector<SampleHit> hits;         // interpolated, per request
  thread_local std::vector<Ray> rays;               // primary ray through the sample, per request
  thread_local std::vector<glm::dvec2> footprints;  // image position of the texture footprint
  thread_local std::vector<ShadeHit> requests;      // refined (refinePrimaryHits)
  thread_local std::vector<glm::vec4> colors;
  thread_local std::vector<Assignment> assignments;
  winners.clear();
  positions.clear();
  requestLocal.clear();
  footprints.clear();
  assignments.clear();
  const auto addRequest = [&](uint32_t win, uint32_t local, const glm::dvec2& pos,
                              const glm::dvec2& footprint) {
    winners.push_back(win);
    positions.push_back(pos);
    requestLocal.push_back(local);
    footprints.push_back(footprint);
    return uint32_t(winners.size() - 1);
  };
  std::vector<std::pair<uint64_t, uint32_t>> pixelCache;  // shading rate pixel: (triangle, request)
  for (int py = rect.y0; py < rect.y1; ++py)
    for (int px = rect.x0; px < rect.x1; ++px) {
      pixelCache.clear();
      const glm::dvec2 corner(px, py);
      const bool traced = trace.sink && px == trace.pixel.x && py == trace.pixel.y;
      for (int s = 0; s < spp; ++s) {
        const uint32_t win = target.winners[target.index(px, py, s)];
        if (win == kNoSetup) continue;
        const uint32_t local = index(px, py, s);
        const glm::dvec2 pos = corner + grid_.positions[size_t(s)];
        uint32_t request;
        if (options_.shadingRate == ShadingRate::Pixel) {
          const TriangleSetup& t = setups_[win];
          auto it = std::find_if(pixelCache.begin(), pixelCache.end(),
                                 [&](const auto& e) { return e.first == t.id(); });
          if (it != pixelCache.end()) {
            request = it->second;
            // The sample's own hit only where someone reads it: the
            // resolve's centre sample, the per-sample hits, the trace.
            if (allFronts || s == centre_ || traced) samples.front[local] = interpolatedHit(t, pos);
          } else {
            // First covered sample of this triangle, footprint of the pixel centre (MSAA-like).
            request = addRequest(win, local, pos, corner + glm::dvec2(0.5));
            pixelCache.emplace_back(t.id(), request);
          }
        } else {
          request = addRequest(win, local, pos, pos);
        }
        assignments.push_back({local, request});
      }
    }
  // Each request's interpolated hit and primary ray in double lanes
  // (interpolatedHit's and PrimaryRays' bits: raster/primary_samples.h).
  const size_t count = winners.size();
  hits.resize(count);
  rays.resize(count);
  primarySamples(primaryConstants_, setups_.data(), winners.data(), positions.data(), count, hits.data(),
                 rays.data());
  for (size_t r = 0; r < count; ++r) samples.front[requestLocal[r]] = hits[r];
  // Refined on their planes in double lanes (refinePrimaryHit's bits).
  requests.resize(hits.size());
  refinePrimaryHits(scene_, rays.data(), hits.data(), footprints.data(), hits.size(), requests.data());
  colors.resize(requests.size());
  shadePrimaryHits(shader_, requests.data(), requests.size(), colors.data(), shadingPath());
  n.shadedSamples += requests.size();
  for (const Assignment& a : assignments) samples.color[a.local] = colors[a.request];

  if (trace.sink && trace.pixel.x >= rect.x0 && trace.pixel.x < rect.x1 && trace.pixel.y >= rect.y0 &&
      trace.pixel.y < rect.y1) {
    const int px = trace.pixel.x, py = trace.pixel.y;
    for (int s = 0; s < spp; ++s) {
      const uint32_t win = target.winners[target.index(px, py, s)];
      if (win == kNoSetup) continue;
      const TriangleSetup& t = setups_[win];
      const uint32_t local = index(px, py, s);
      const SampleHit& h = samples.front[local];
      char b[64];
      std::snprintf(b, sizeof b, "(%.6f, %.6f)", double(h.b1), double(h.b2));
      trace.sink->record(TraceEvent{TraceStage::Shade, s, t.instance, t.triangle, 1, "", {}}
                             .add("interpolated_depth", traceNumber(h.depth))
                             .add("b", b)
                             .add("color", traceColor(samples.color[local])));
    }
  }
}

}  // namespace rastray
