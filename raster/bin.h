// Binning: which triangles touch which screen tile. Tiles are
// kTileSize × kTileSize pixels and are rasterized independently (in
// parallel); each bin lists setup indices in increasing order, so a tile
// sees its triangles in the same order whatever the thread count.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

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

// bins[tile] = indices into `setups` (those accepted by `select`) whose
// pixel bounds overlap the tile.
template <typename Select>
std::vector<std::vector<uint32_t>> binTriangles(const TileGrid& grid,
                                                const std::vector<TriangleSetup>& setups, Select select) {
  std::vector<std::vector<uint32_t>> bins(size_t(grid.count()));
  for (size_t i = 0; i < setups.size(); ++i) {
    const TriangleSetup& t = setups[i];
    if (!select(t)) continue;
    const int tx0 = t.pixelMin.x / kTileSize, tx1 = t.pixelMax.x / kTileSize;
    const int ty0 = t.pixelMin.y / kTileSize, ty1 = t.pixelMax.y / kTileSize;
    for (int ty = ty0; ty <= ty1; ++ty)
      for (int tx = tx0; tx <= tx1; ++tx) bins[size_t(ty * grid.tilesX + tx)].push_back(uint32_t(i));
  }
  return bins;
}

}  // namespace rastray
