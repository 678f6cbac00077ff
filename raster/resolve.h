// Resolve: samples to pixels. Colour is the box filter (mean) of the
// sample colours in premultiplied space. Z and IDs come from the sample
// nearest the pixel centre (SPEC §6, common/sampling.h centreSampleIndex),
// and at that sample from the nearest visible surface: the front-most
// transparent layer when there is one, else the opaque surface, else
// nothing (+inf, kNoId). So a pixel seen through glass-like BLEND sheets
// reports the first sheet, as a deep reader's first layer would.
#pragma once

#include <glm/glm.hpp>
#include <vector>

#include "common/hit.h"
#include "common/image.h"
#include "raster/bin.h"

namespace rastray {

// One tile's final per-sample results, sample (x, y, s) at
// ((y − rect.y0)·rectWidth + (x − rect.x0))·spp + s.
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
