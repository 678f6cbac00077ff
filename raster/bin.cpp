#include "raster/bin.h"

#include <algorithm>

namespace rastray {

TileGrid::TileGrid(int w, int h)
    : width(w), height(h), tilesX((w + kTileSize - 1) / kTileSize), tilesY((h + kTileSize - 1) / kTileSize) {}

TileRect TileGrid::rect(int tile) const {
  const int tx = tile % tilesX, ty = tile / tilesX;
  return {tx * kTileSize, ty * kTileSize, std::min(width, (tx + 1) * kTileSize),
          std::min(height, (ty + 1) * kTileSize)};
}

SampleBox::SampleBox(const SampleGrid& grid) {
  lo = hi = grid.offsets.empty() ? glm::i64vec2(0) : grid.offsets[0];
  for (const glm::i64vec2& o : grid.offsets) {
    lo = glm::min(lo, o);
    hi = glm::max(hi, o);
  }
}

}  // namespace rastray
