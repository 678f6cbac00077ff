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
  // render() hands pass 1 a cleared rect (a fresh tile target, or the
  // frame's target cleared or new).
  rasterDepthPass(setups_, bin, grid_, rect, options_.depthFormat, options_.depthFunc, alphaTest, trace,
                  target, &n.opaque, coveragePath(), /*clearedRect=*/true);
}

void TileRenderer::shadeVisible(const TileSampleIndex& index, const DepthTarget& target,
                                const TraceRequest& trace, bool allFronts, TileSamples& samples,
                                ThreadCounters& n) const {
  const TileRect& rect = index.rect;
  const int spp = grid_.spp;
  // Every sample is written exactly once below (a background sample in the
  // winner loop, a winner's hit and colour after the batch), so the
  // storage is only sized, never filled first. The lean form
  // (raster/resolve.h) has no front hits, only the winners' depths, and no
  // background samples (the resolve reads them as 0).
  const bool lean = samples.lean;
  const bool pixelRate = options_.shadingRate == ShadingRate::Pixel;
  samples.uniformShared = lean && pixelRate;
  samples.color.resize(index.count());
  if (lean)
    samples.depth.resize(index.count());
  else
    samples.front.resize(index.count());
  // The tile's winning samples a block of kPrimaryHitBlock at a time, in
  // pixel and sample order: the winner loop adds each to the fused pass's
  // block (PrimaryBatch: the interpolated hit, the primary ray and the hit
  // refined on its stored triangle's plane in double lanes, with
  // primarySamplesReference's and refinePrimaryHit's bits,
  // raster/primary_samples.h), whose results go as struct of arrays to the
  // shading kernel (PrimaryHitShader, common/shading_kernel.h: the kernel
  // the ray caster shades its primary hits with), straight into the
  // tile's colours. A hit's colour does not depend on its block (the
  // kernel's lane independence). At shading rate pixel a sample takes the
  // colour of the first sample of its pixel on the same triangle.
  struct Assignment {
    uint32_t local;   // TileSampleIndex
    uint32_t source;  // the sample whose colour it takes
  };
  thread_local std::vector<Assignment> assignments;
  PrimaryBatch batch(primaryConstants_, scene_, setups_.data(), planes_);
  batch.wantInterpolated(!lean);  // the lean form reads no front hits
  PrimaryHitShader kernel(shader_, shadingPath());
  // An unlit, emissive scene's colours need no ray and no refined hit.
  batch.wantShadingInputs(refinesHits_);
  alignas(64) uint32_t localOut[kPrimaryHitBlock];  // the sample each is shaded at
  alignas(64) double footprintX[kPrimaryHitBlock],
      footprintY[kPrimaryHitBlock];  // image position of the footprint
  assignments.clear();
  // The block's hits into the tile's samples, then its colours. At
  // shading rate sample the footprint is at the sample: the batch's own
  // positions.
  const double* const fpX = pixelRate ? footprintX : batch.x();
  const double* const fpY = pixelRate ? footprintY : batch.y();
  const auto flush = [&] {
    batch.run();
    const size_t count = batch.size();
    if (lean) {
      // The block's samples were added in increasing tile order, so they
      // are consecutive when the last is count − 1 after the first (a
      // run of a row without background): one copy.
      if (count > 0 && localOut[count - 1] - localOut[0] == count - 1)
        std::copy_n(batch.depths(), count, &samples.depth[localOut[0]]);
      else
        for (size_t r = 0; r < count; ++r) samples.depth[localOut[r]] = batch.depth(r);
    } else {
      for (size_t r = 0; r < count; ++r) samples.front[localOut[r]] = batch.hit(r);
    }
    kernel.shade(batch.hits(fpX, fpY, localOut), samples.color.data());
    n.shadedSamples += count;
    if (refinesHits_) n.refinedSamples += count;
    batch.clear();
  };
  const auto addRequest = [&](uint32_t win, uint32_t local, const glm::dvec2& pos,
                              const glm::dvec2& footprint) {
    const size_t k = batch.size();
    localOut[k] = local;
    footprintX[k] = footprint.x;
    footprintY[k] = footprint.y;
    batch.add(win, pos.x, pos.y);
    if (batch.full()) flush();
  };
  if (!pixelRate) {
    // Shading rate sample: every winner is shaded at its sample.
    const size_t rowSamples = size_t(rect.x1 - rect.x0) * size_t(spp);
    for (int py = rect.y0; py < rect.y1; ++py) {
      const uint32_t* rowWinners = &target.winners[target.index(rect.x0, py, 0)];
      const uint32_t local = index(rect.x0, py, 0);
      if (!lean) {
        for (size_t i = 0; i < rowSamples; ++i) {
          if (rowWinners[i] != kNoSetup) continue;
          samples.color[local + i] = glm::vec4(0.0f);
          samples.front[local + i] = SampleHit{};
        }
      }
      for (size_t i = 0; i < rowSamples;) {
        i = batch.addRow(rowWinners, i, rowSamples, spp, rect.x0, py, grid_.positions.data(), local,
                         localOut);
        if (batch.full()) flush();
      }
    }
  }
  std::vector<std::pair<uint64_t, uint32_t>> pixelCache;  // shading rate pixel: (triangle, local)
  for (int py = pixelRate ? rect.y0 : rect.y1; py < rect.y1; ++py) {
    // Shading rate pixel. The row's samples are consecutive in both the
    // target and the tile.
    const uint32_t* rowWinners = &target.winners[target.index(rect.x0, py, 0)];
    uint32_t local = index(rect.x0, py, 0);
    for (int px = rect.x0; px < rect.x1; ++px) {
      const glm::dvec2 corner(px, py);
      const bool traced = trace.sink && px == trace.pixel.x && py == trace.pixel.y;
      // A pixel whose samples were all won by one setup (a large
      // triangle's inside), in the lean form: what the loop below does for
      // it, without its per-sample search. Its first sample is shaded with
      // the centre's footprint, the others take that colour, and the
      // centre sample's depth is its own interpolated depth; the resolve
      // reads the first sample's colour for the others
      // (TileSamples::uniformShared). A pixel of background alone:
      // nothing to write.
      const uint32_t first = rowWinners[0];
      if (lean) {
        int same = 1;
        while (same < spp && rowWinners[same] == first) ++same;
        if (same == spp) {
          if (first != kNoSetup) {
            const TriangleSetup& t = setups_[first];
            addRequest(first, local, corner + grid_.positions[0], corner + glm::dvec2(0.5));
            if (centre_ != 0) {
              const glm::dvec2 c = corner + grid_.positions[size_t(centre_)];
              samples.depth[local + uint32_t(centre_)] = float(t.viewDepthAt(c.x, c.y));
            }
          }
          local += uint32_t(spp);
          rowWinners += spp;
          continue;
        }
      }
      pixelCache.clear();
      for (int s = 0; s < spp; ++s, ++local) {
        const uint32_t win = *rowWinners++;
        if (win == kNoSetup) {
          if (!lean) {
            samples.color[local] = glm::vec4(0.0f);
            samples.front[local] = SampleHit{};
          }
          continue;
        }
        const glm::dvec2 pos = corner + grid_.positions[size_t(s)];
        const TriangleSetup& t = setups_[win];
        auto it = std::find_if(pixelCache.begin(), pixelCache.end(),
                               [&](const auto& e) { return e.first == t.id(); });
        if (it != pixelCache.end()) {
          assignments.push_back({local, it->second});
          // The sample's own hit only where someone reads it: the
          // resolve's centre sample, the per-sample hits, the trace.
          if (lean) {
            if (s == centre_) samples.depth[local] = float(t.viewDepthAt(pos.x, pos.y));  // interpolatedHit's
          } else {
            samples.front[local] =
                allFronts || s == centre_ || traced ? interpolatedHit(t, pos) : SampleHit{};
          }
        } else {
          // First covered sample of this triangle, footprint of the pixel centre (MSAA-like).
          addRequest(win, local, pos, corner + glm::dvec2(0.5));
          pixelCache.emplace_back(t.id(), local);
        }
      }
    }
  }
  if (batch.size() > 0) flush();
  // After every chunk: a source sample's colour is final.
  for (const Assignment& a : assignments) samples.color[a.local] = samples.color[a.source];

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
