// The end of a tile: BLEND layers composited over the opaque colours,
// the resolve to pixels (resolve.h), the per-sample hits, and the deep
// samples (every layer, then the opaque surface); and, once every tile is
// done, the frame's deep image from the tiles' pieces.
#include <algorithm>
#include <string>

#include "raster/tile_renderer.h"

namespace rastray {

// Composites each sample's layers (front to back) over its opaque colour in
// premultiplied space, and makes the front-most layer the sample's front
// hit. Returns the opaque colours from before (empty when there are no
// layers: then samples->color still holds them).
std::vector<glm::vec4> TileRenderer::compositeLayers(const std::vector<BlendLayer>& layers,
                                                     TileSamples* samples) const {
  if (layers.empty()) return {};
  std::vector<glm::vec4> opaqueColor = samples->color;
  const size_t count = samples->color.size();
  std::vector<glm::vec4> acc(count, glm::vec4(0.0f));
  std::vector<bool> hasFront(count, false);
  for (const BlendLayer& l : layers) {
    acc[l.local] = over(acc[l.local], l.color);  // acc is in front of the new layer
    if (!hasFront[l.local]) {
      hasFront[l.local] = true;
      samples->front[l.local] = l.hit;
    }
  }
  for (size_t i = 0; i < count; ++i)
    if (hasFront[i]) samples->color[i] = over(acc[i], samples->color[i]);
  return opaqueColor;
}

void TileRenderer::traceLayersAndFinal(const TileSampleIndex& index, const TraceRequest& trace,
                                       const std::vector<BlendLayer>& layers,
                                       const TileSamples& samples) const {
  const uint32_t base = index(trace.pixel.x, trace.pixel.y, 0);
  for (const BlendLayer& l : layers)
    if (l.local >= base && l.local < base + uint32_t(grid_.spp))
      trace.sink->record(
          TraceEvent{TraceStage::Blend, int(l.local - base), l.hit.instance, l.hit.triangle, 1, "", {}}
              .add("layer", std::to_string(l.rank))
              .add("interpolated_depth", traceNumber(l.hit.depth))
              .add("color", traceColor(l.color)));
  for (int s = 0; s < grid_.spp; ++s) {
    TraceEvent e{TraceStage::Final, s, kNoId, kNoId, 1, "", {}};
    e.add("color", traceColor(samples.color[base + uint32_t(s)]));
    if (s == centre_) e.add("resolve", "centre sample: Z and ids");
    trace.sink->record(std::move(e));
  }
}

void TileRenderer::copyHits(const TileSampleIndex& index, const TileSamples& samples,
                            std::vector<SampleHit>* hits) const {
  // The frame's sample order (the target may be the tile's own).
  const TileRect& rect = index.rect;
  const size_t spp = size_t(grid_.spp);
  for (int py = rect.y0; py < rect.y1; ++py)
    for (int px = rect.x0; px < rect.x1; ++px)
      for (size_t s = 0; s < spp; ++s)
        (*hits)[(size_t(py) * size_t(camera_.width) + size_t(px)) * spp + s] =
            samples.front[index(px, py, int(s))];
}

// Per pixel: for each sample its layers front to back, then the opaque
// surface (interpolated hit, opaque colour).
void TileRenderer::appendDeepSamples(const TileSampleIndex& index, const std::vector<BlendLayer>& layers,
                                     const DepthTarget& target, const std::vector<glm::vec4>& opaqueColor,
                                     const TileOutputs& out) const {
  const TileRect& rect = index.rect;
  size_t li = 0;
  for (int py = rect.y0; py < rect.y1; ++py)
    for (int px = rect.x0; px < rect.x1; ++px) {
      uint32_t c = 0;
      for (int s = 0; s < grid_.spp; ++s) {
        const uint32_t local = index(px, py, s);
        for (; li < layers.size() && layers[li].local == local; ++li, ++c) {
          const BlendLayer& l = layers[li];
          // Peeling stops after its last pass: it did not look behind that layer.
          const bool cutOff =
              options_.transparency == TransparencyMode::Peel && l.rank + 1 == uint32_t(options_.peelLayers);
          out.deep->push_back({l.color, l.hit.depth, l.hit.instance, l.hit.triangle, uint32_t(s), cutOff});
        }
        const uint32_t win = target.winners[target.index(px, py, s)];
        if (win == kNoSetup) continue;
        const SampleHit hit = interpolatedHit(setups_[win], glm::dvec2(px, py) + grid_.positions[size_t(s)]);
        out.deep->push_back({opaqueColor[local], hit.depth, hit.instance, hit.triangle, uint32_t(s)});
        ++c;
      }
      out.deepCounts->push_back(c);
    }
}

DeepImage assembleDeepImage(const TileGrid& tiles, const std::vector<std::vector<DeepSample>>& deep,
                            const std::vector<std::vector<uint32_t>>& deepCounts) {
  DeepImage d;
  d.width = tiles.width;
  d.height = tiles.height;
  std::vector<uint32_t> perPixel(size_t(tiles.width) * size_t(tiles.height));
  for (int tile = 0; tile < tiles.count(); ++tile) {
    const TileRect r = tiles.rect(tile);
    size_t k = 0;
    for (int y = r.y0; y < r.y1; ++y)
      for (int x = r.x0; x < r.x1; ++x)
        perPixel[size_t(y) * size_t(tiles.width) + size_t(x)] = deepCounts[size_t(tile)][k++];
  }
  d.offsets.assign(perPixel.size() + 1, 0);
  for (size_t i = 0; i < perPixel.size(); ++i) d.offsets[i + 1] = d.offsets[i] + perPixel[i];
  d.samples.resize(d.offsets.back());
  for (int tile = 0; tile < tiles.count(); ++tile) {
    const TileRect r = tiles.rect(tile);
    size_t k = 0;
    for (int y = r.y0; y < r.y1; ++y)
      for (int x = r.x0; x < r.x1; ++x) {
        const size_t p = size_t(y) * size_t(tiles.width) + size_t(x);
        std::copy_n(deep[size_t(tile)].begin() + std::ptrdiff_t(k), perPixel[p],
                    d.samples.begin() + d.offsets[p]);
        k += perPixel[p];
      }
  }
  return d;
}

}  // namespace rastray
