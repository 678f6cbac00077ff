// Binning: which triangles touch which screen tile. Tiles are
// kTileSize × kTileSize pixels and are rasterized independently (in
// parallel); each bin lists setup indices in increasing order, so a tile
// sees its triangles in the same order whatever the thread count.
//
// A triangle is binned to the tiles its pixel bounds overlap, less those
// that one of its edges misses entirely: E + bias < 0 at the sample-box
// corner where E is largest means no sample of the tile (within the
// triangle's bounds) is covered. The corner lies inside the image, so the
// value is within setup.h's int64 bound and the test is exact.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "common/parallel.h"
#include "raster/setup.h"

namespace rastray {

constexpr int kTileSize = 64;

struct TileRect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // pixels [x0, x1) × [y0, y1)
};

struct TileGrid {
  int width = 0, height = 0;  // image
  int tilesX = 0, tilesY = 0;
  TileGrid(int w, int h);
  int count() const { return tilesX * tilesY; }
  TileRect rect(int tile) const;
};

// The extremes of a pattern's sample offsets within a pixel (units).
struct SampleBox {
  glm::i64vec2 lo{0}, hi{0};
  explicit SampleBox(const SampleGrid& grid);
};

// Whether some sample of pixels [x0, x1] × [y0, y1] (inclusive) might be
// covered by t: false only when one edge is negative at all of them.
inline bool edgesReach(const TriangleSetup& t, int64_t unitsPerPixel, const SampleBox& box, int x0, int y0,
                       int x1, int y1) {
  const int64_t X0 = int64_t(x0) * unitsPerPixel + box.lo.x, X1 = int64_t(x1) * unitsPerPixel + box.hi.x;
  const int64_t Y0 = int64_t(y0) * unitsPerPixel + box.lo.y, Y1 = int64_t(y1) * unitsPerPixel + box.hi.y;
  for (const EdgeFunction& e : t.edge)
    if (e.at(e.a > 0 ? X1 : X0, e.b > 0 ? Y1 : Y0) + e.bias < 0) return false;
  return true;
}

// Calls f(tile) for every tile t is binned to, in increasing tile order.
template <typename F>
void forEachBinnedTile(const TileGrid& grid, int64_t unitsPerPixel, const SampleBox& box,
                       const TriangleSetup& t, F&& f) {
  const int tx0 = t.pixelMin.x / kTileSize, tx1 = t.pixelMax.x / kTileSize;
  const int ty0 = t.pixelMin.y / kTileSize, ty1 = t.pixelMax.y / kTileSize;
  if (tx0 == tx1 && ty0 == ty1) {  // within one tile: its bounds overlap it, nothing to test
    f(ty0 * grid.tilesX + tx0);
    return;
  }
  for (int ty = ty0; ty <= ty1; ++ty) {
    const int y0 = std::max(ty * kTileSize, t.pixelMin.y),
              y1 = std::min(ty * kTileSize + kTileSize - 1, t.pixelMax.y);
    for (int tx = tx0; tx <= tx1; ++tx) {
      const int x0 = std::max(tx * kTileSize, t.pixelMin.x),
                x1 = std::min(tx * kTileSize + kTileSize - 1, t.pixelMax.x);
      if (edgesReach(t, unitsPerPixel, box, x0, y0, x1, y1)) f(ty * grid.tilesX + tx);
    }
  }
}

// bins[tile] = indices into `setups` (those accepted by `select`) binned to
// the tile, increasing. In parallel: per-chunk counts, exact bin sizes
// from their prefix sums in chunk order, then each chunk fills its own
// slots, so the bins are the serial result whatever the thread count. The
// counting pass notes each setup's fate in 4 bytes (not selected, one tile,
// several tiles) and a chunk's several-tile setups' tiles in a list of its
// own, so the filling pass never reads the 304-byte setups again: they are
// out of cache by then (at 10^6 triangles the re-reads were about half of
// the filling pass's time).
template <typename Select>
std::vector<std::vector<uint32_t>> binTriangles(const TileGrid& grid, const SampleGrid& samples,
                                                const std::vector<TriangleSetup>& setups, Select select) {
  constexpr uint32_t kNotSelected = 0xFFFFFFFFu, kSeveralTiles = 0xFFFFFFFEu;
  const size_t tiles = size_t(grid.count());
  std::vector<std::vector<uint32_t>> bins(tiles);
  if (setups.empty()) return bins;
  // Few enough chunks that the counts (chunks × tiles) stay small.
  const size_t maxChunks = 16 * size_t(std::max(1, tbb::this_task_arena::max_concurrency()));
  const size_t chunks = std::min(maxChunks, (setups.size() + 4095) / 4096);
  const size_t perChunk = (setups.size() + chunks - 1) / chunks;
  const SampleBox box(samples);
  const int64_t U = samples.unitsPerPixel;
  std::vector<uint32_t> slot(chunks * tiles, 0);  // counts, then each chunk's next slot per tile
  std::vector<uint32_t> fate(setups.size());      // its one tile, or kNotSelected, kSeveralTiles
  // Per chunk, for each of its kSeveralTiles setups in order: the number
  // of its tiles, then the tiles, increasing.
  std::vector<std::vector<uint32_t>> spans(chunks);
  const auto forChunks = [&](auto&& body) {
    parallelFor(tbb::blocked_range<size_t>(0, chunks, 1), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t c = r.begin(); c != r.end(); ++c)
        body(slot.data() + c * tiles, spans[c], c * perChunk, std::min(setups.size(), (c + 1) * perChunk));
    });
  };
  forChunks([&](uint32_t* count, std::vector<uint32_t>& span, size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      if (!select(setups[i])) {
        fate[i] = kNotSelected;
        continue;
      }
      const size_t at = span.size();
      span.push_back(0);
      forEachBinnedTile(grid, U, box, setups[i], [&](int tile) {
        ++count[tile];
        span.push_back(uint32_t(tile));
      });
      const size_t n = span.size() - at - 1;
      fate[i] = n == 1 ? span[at + 1] : n == 0 ? kNotSelected : kSeveralTiles;
      if (n < 2) {
        span.resize(at);
        continue;
      }
      span[at] = uint32_t(n);
    }
  });
  for (size_t tile = 0; tile < tiles; ++tile) {
    uint32_t total = 0;
    for (size_t c = 0; c < chunks; ++c) {
      const uint32_t n = slot[c * tiles + tile];
      slot[c * tiles + tile] = total;
      total += n;
    }
    bins[tile].resize(total);
  }
  forChunks([&](uint32_t* next, const std::vector<uint32_t>& span, size_t begin, size_t end) {
    const uint32_t* tilesOf = span.data();
    for (size_t i = begin; i < end; ++i) {
      if (fate[i] == kNotSelected) continue;
      if (fate[i] != kSeveralTiles) {
        bins[fate[i]][next[fate[i]]++] = uint32_t(i);
        continue;
      }
      const uint32_t n = *tilesOf++;
      for (const uint32_t* t = tilesOf; t != tilesOf + n; ++t) bins[*t][next[*t]++] = uint32_t(i);
      tilesOf += n;
    }
  });
  return bins;
}

}  // namespace rastray
