// resolveTile (raster/resolve.h): the box filter's colour and the centre
// sample's depth and ids land on exactly the tile's pixels, whatever the
// alignment of the image rows (the resolve streams rows out with
// non-temporal stores on their 16-byte aligned middle and plain stores at
// the ends), and nothing outside the tile is written.
#include "raster/resolve.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <string>

namespace rastray {
namespace {

TEST(Resolve, WritesExactlyTheTilesPixelsAtAnyRowAlignment) {
  const float sentinel = -7.0f;
  for (int spp : {1, 4}) {
    // Odd image widths and tile corners: rows start at every offset modulo 16 bytes.
    for (int width : {61, 64, 130}) {
      for (int x0 : {0, 1, 3, 5}) {
        const int height = 9;
        const TileRect rect{x0, 2, std::min(width, x0 + 100), 7};  // wider than a tile too
        const TileSampleIndex index{rect, spp};
        TileSamples samples;
        samples.color.resize(index.count());
        samples.front.resize(index.count());
        for (size_t i = 0; i < index.count(); ++i) {
          const float v = float(i);
          samples.color[i] = glm::vec4(v, v + 0.25f, -v, 0.5f + float(i % 3));
          samples.front[i] = SampleHit{uint32_t(i % 5), uint32_t(i), 0.125f * v, 0.0f, 0.0f};
        }
        FlatImage image(width, height);
        for (size_t p = 0; p < image.color.size(); ++p) {
          image.color[p] = glm::vec4(sentinel);
          image.depth[p] = sentinel;
          image.instance[p] = image.triangle[p] = 0xDEADBEEFu;
        }
        const int centre = spp == 1 ? 0 : 2;
        resolveTile(rect, spp, centre, samples, &image);
        for (int y = 0; y < height; ++y)
          for (int x = 0; x < width; ++x) {
            const size_t p = image.index(x, y);
            const bool inside = x >= rect.x0 && x < rect.x1 && y >= rect.y0 && y < rect.y1;
            SCOPED_TRACE("spp " + std::to_string(spp) + " width " + std::to_string(width) + " x0 " +
                         std::to_string(x0) + " pixel " + std::to_string(x) + "," + std::to_string(y));
            if (!inside) {
              ASSERT_EQ(image.color[p], glm::vec4(sentinel));
              ASSERT_EQ(image.depth[p], sentinel);
              ASSERT_EQ(image.instance[p], 0xDEADBEEFu);
              ASSERT_EQ(image.triangle[p], 0xDEADBEEFu);
              continue;
            }
            // The box filter: (0 + s0 + … ) / spp, in sample order.
            glm::vec4 sum(0.0f);
            for (int s = 0; s < spp; ++s) sum += samples.color[index(x, y, s)];
            const glm::vec4 expected = sum / float(spp);
            ASSERT_EQ(0, std::memcmp(&image.color[p], &expected, sizeof expected));
            const SampleHit& h = samples.front[index(x, y, centre)];
            ASSERT_EQ(image.depth[p], h.depth);
            ASSERT_EQ(image.instance[p], h.instance);
            ASSERT_EQ(image.triangle[p], h.triangle);
          }
      }
    }
  }
}

}  // namespace
}  // namespace rastray
