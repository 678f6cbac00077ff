#include "raster/resolve.h"

#include <algorithm>
#include <cstdint>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "common/box_filter.h"

namespace rastray {

namespace {

// Copies `bytes` (a multiple of 4) to `dst` with stores that bypass the
// caches where the CPU has them (SSE2 non-temporal stores on the 16-byte
// aligned middle; plain stores at the ends). The frame's image is written
// once per frame and is far larger than the caches: plain stores would
// first read every line of it from memory only to overwrite it. Callers
// end the tile with streamFence() before another thread may read the image.
void streamCopy(void* dst, const void* src, size_t bytes) {
#if defined(__SSE2__)
  auto* d = static_cast<char*>(dst);
  const auto* s = static_cast<const char*>(src);
  const size_t head = std::min(bytes, size_t((16 - reinterpret_cast<uintptr_t>(d) % 16) % 16));
  std::memcpy(d, s, head);
  d += head, s += head, bytes -= head;
  for (; bytes >= 16; d += 16, s += 16, bytes -= 16)
    _mm_stream_si128(reinterpret_cast<__m128i*>(d), _mm_loadu_si128(reinterpret_cast<const __m128i*>(s)));
  std::memcpy(d, s, bytes);
#else
  std::memcpy(dst, src, bytes);
#endif
}

void streamFence() {
#if defined(__SSE2__)
  _mm_sfence();
#endif
}

}  // namespace

void resolveTile(const TileRect& rect, int spp, int centreSample, const TileSamples& samples,
                 FlatImage* image) {
  const TileSampleIndex local{rect, spp};
  // A tile row at a time (in pieces of at most kTileSize pixels), filtered
  // into the core's cache, then streamed out.
  glm::vec4 color[kTileSize];
  float depth[kTileSize];
  uint32_t instance[kTileSize], triangle[kTileSize];
  for (int y = rect.y0; y < rect.y1; ++y) {
    for (int x = rect.x0; x < rect.x1; x += kTileSize) {
      const size_t width = size_t(std::min(rect.x1 - x, kTileSize));
      // A tile row's samples and its image row are both contiguous.
      const size_t row = local(x, y, 0), first = image->index(x, y);
      boxFilter(samples.color.data() + row, spp, width, color);
      for (size_t i = 0; i < width; ++i) {
        const SampleHit& h = samples.front[row + i * size_t(spp) + size_t(centreSample)];
        depth[i] = h.depth;
        instance[i] = h.instance;
        triangle[i] = h.triangle;
      }
      streamCopy(image->color.data() + first, color, width * sizeof(glm::vec4));
      streamCopy(image->depth.data() + first, depth, width * sizeof(float));
      streamCopy(image->instance.data() + first, instance, width * sizeof(uint32_t));
      streamCopy(image->triangle.data() + first, triangle, width * sizeof(uint32_t));
    }
  }
  streamFence();
}

void resolveTileLean(const TileRect& rect, int spp, int centreSample, const TileSamples& samples,
                     const DepthTarget& target, const TriangleSetup* setups, FlatImage* image) {
  const TileSampleIndex local{rect, spp};
  glm::vec4 color[kTileSize];
  float depth[kTileSize];
  uint32_t instance[kTileSize], triangle[kTileSize];
  const SampleHit none;
  // The last winner's ids: consecutive pixels mostly share one.
  uint32_t last = kNoSetup, lastInstance = none.instance, lastTriangle = none.triangle;
  for (int y = rect.y0; y < rect.y1; ++y) {
    for (int x = rect.x0; x < rect.x1; x += kTileSize) {
      const size_t width = size_t(std::min(rect.x1 - x, kTileSize));
      const size_t row = local(x, y, 0), first = image->index(x, y);
      const uint32_t* winners = &target.winners[target.index(x, y, 0)];
      // Samples without a winner hold no colour: the full form's 0.
      boxFilterCovered(samples.color.data() + row, winners, kNoSetup, spp, width, color);
      for (size_t i = 0; i < width; ++i) {
        const size_t c = i * size_t(spp) + size_t(centreSample);
        const uint32_t w = winners[c];
        if (w == kNoSetup) {
          depth[i] = none.depth;
          instance[i] = none.instance;
          triangle[i] = none.triangle;
          continue;
        }
        if (w != last) {
          last = w;
          lastInstance = setups[w].instance;
          lastTriangle = setups[w].triangle;
        }
        depth[i] = samples.depth[row + c];
        instance[i] = lastInstance;
        triangle[i] = lastTriangle;
      }
      streamCopy(image->color.data() + first, color, width * sizeof(glm::vec4));
      streamCopy(image->depth.data() + first, depth, width * sizeof(float));
      streamCopy(image->instance.data() + first, instance, width * sizeof(uint32_t));
      streamCopy(image->triangle.data() + first, triangle, width * sizeof(uint32_t));
    }
  }
  streamFence();
}

}  // namespace rastray
