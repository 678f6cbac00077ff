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
#include "raster/coverage.h"
#include "raster/setup.h"

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

// One tile's final per-sample results, in TileSampleIndex order, in one
// of two forms. Full: `color` and `front` for every sample. Lean (`lean`,
// for a tile whose results are only its pixels: no per-sample hits, deep
// samples, BLEND layers or trace): `front` is not filled; a sample's ids
// are its depth-test winner's (the resolve reads them from the depth
// target), its depth is `depth`, set for every sample with a winner that
// the resolve reads (the centre sample; the opaque pass sets it from the
// same float as the full form's front hit); `color` is set only for
// samples with a winner (the resolve reads the others as the full form's
// 0). Why: the 20-byte front hit per sample, and the background samples,
// were written by the winner loop only for the resolve to read them back.
struct TileSamples {
  std::vector<glm::vec4> color;  // composited, premultiplied
  std::vector<SampleHit> front;  // nearest visible surface per sample (full form)
  std::vector<float> depth;      // the winner's interpolated depth (lean form)
  bool lean = false;
  // Lean form, shading once per pixel: a pixel whose samples were all won
  // by one setup holds its colour in its first sample only (the others
  // take it: the resolve reads it for them).
  bool uniformShared = false;
};

// The full form's resolve.
void resolveTile(const TileRect& rect, int spp, int centreSample, const TileSamples& samples,
                 FlatImage* image);
// The lean form's: the same pixels as resolveTile given the full form
// of the same tile, where front[i] = {setups[w].instance,
// setups[w].triangle, depth[i]} for a sample won by w, SampleHit{} and
// colour 0 for a sample without a winner (`target`'s kNoSetup), whatever
// its entries of `samples` hold.
void resolveTileLean(const TileRect& rect, int spp, int centreSample, const TileSamples& samples,
                     const DepthTarget& target, const TriangleSetup* setups, FlatImage* image);

// over(front, back) = front + (1 − front.a)·back (premultiplied, SPEC §4).
inline glm::vec4 over(const glm::vec4& front, const glm::vec4& back) {
  return front + (1.0f - front.a) * back;
}

}  // namespace rastray
