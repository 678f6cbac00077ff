#include "raster/resolve.h"

namespace rastray {

void resolveTile(const TileRect& rect, int spp, int centreSample, const TileSamples& samples,
                 FlatImage* image) {
  const TileSampleIndex local{rect, spp};
  for (int y = rect.y0; y < rect.y1; ++y)
    for (int x = rect.x0; x < rect.x1; ++x) {
      const size_t base = local(x, y, 0);
      glm::vec4 sum(0.0f);
      for (int s = 0; s < spp; ++s) sum += samples.color[base + size_t(s)];
      const size_t p = image->index(x, y);
      image->color[p] = sum / float(spp);
      const SampleHit& h = samples.front[base + size_t(centreSample)];
      image->depth[p] = h.depth;
      image->instance[p] = h.instance;
      image->triangle[p] = h.triangle;
    }
}

}  // namespace rastray
