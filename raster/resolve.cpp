#include "raster/resolve.h"

#include "common/box_filter.h"

namespace rastray {

void resolveTile(const TileRect& rect, int spp, int centreSample, const TileSamples& samples,
                 FlatImage* image) {
  const TileSampleIndex local{rect, spp};
  const size_t width = size_t(rect.x1 - rect.x0);
  for (int y = rect.y0; y < rect.y1; ++y) {
    // A tile row's samples and its image row are both contiguous.
    const size_t row = local(rect.x0, y, 0), first = image->index(rect.x0, y);
    boxFilter(samples.color.data() + row, spp, width, image->color.data() + first);
    for (size_t i = 0; i < width; ++i) {
      const SampleHit& h = samples.front[row + i * size_t(spp) + size_t(centreSample)];
      image->depth[first + i] = h.depth;
      image->instance[first + i] = h.instance;
      image->triangle[first + i] = h.triangle;
    }
  }
}

}  // namespace rastray
