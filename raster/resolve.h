// Resolve: samples to pixels. Colour is the box filter (mean) of the
// sample colours in premultiplied space. Z and IDs come from the sample
// nearest the pixel centre (SPEC §6, common/sampling.h centreSampleIndex),
// and at that sample from the nearest visible surface: the front-most
// transparent layer when there is one, else the opaque surface, else
// nothing (+inf, kNoId). So a pixel seen through glass-like BLEND sheets
// reports the first sheet, as a deep reader's first layer would.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "common/hit.h"
#include "common/image.h"
#include "raster/bin.h"

namespace rastray {

// The tile-local sample index: sample s of pixel (x, y) of a tile lives at
// ((y − rect.y0)·rectWidth + (x − rect.x0))·spp + s, the order of
// TileSamples and of the transparency passes' per-sample lists.
struct TileSampleIndex {
  TileRect rect;
  int spp = 1;

  int width() const { return rect.x1 - rect.x0; }
  size_t count() const { return size_t(width()) * size_t(rect.y1 - rect.y0) * size_t(spp); }
  uint32_t operator()(int x, int y, int s) const {
    return uint32_t((size_t(y - rect.y0) * size_t(width()) + size_t(x - rect.x0)) * size_t(spp) + size_t(s));
  }
  // The inverse: pixel and sample of a local index.
  glm::ivec2 pixel(uint32_t local) const {
    const uint32_t p = local / uint32_t(spp);
    return {rect.x0 + int(p % uint32_t(width())), rect.y0 + int(p / uint32_t(width()))};
  }
  int sample(uint32_t local) const { return int(local % uint32_t(spp)); }
};

// One tile's final per-sample results, in TileSampleIndex order.
struct TileSamples {
  std::vector<glm::vec4> color;  // composited, premultiplied
  std::vector<SampleHit> front;  // nearest visible surface per sample
};

void resolveTile(const TileRect& rect, int spp, int centreSample, const TileSamples& samples,
                 FlatImage* image);

// over(front, back) = front + (1 − front.a)·back (premultiplied, SPEC §4).
inline glm::vec4 over(const glm::vec4& front, const glm::vec4& back) {
  return front + (1.0f - front.a) * back;
}

}  // namespace rastray
