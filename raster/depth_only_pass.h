// The shadow maps' depth-only pass: one sample per texel, keys only (no
// winners, so a key tie keeps the stored key, as rasterDepthPass does for
// a keys-only target), depth function Less.
//
// Contract: rendering a tile (DepthOnlyTile::render) and storing it into a
// DepthMap, once for each rect of a TileGrid (any order, in parallel),
// leaves in every texel exactly the key that clearing the map to
// kClearDepthKey and running rasterDepthPass (keys only, Less) over the
// same bins would: the nearest covered key, kClearDepthKey where nothing
// covers. The tests prove it against both.
//
// Where the time goes at 2048² per face is memory: a cube map is 6 × 16 MB
// of keys, far beyond the caches. So a tile is drawn into a local buffer
// (64² keys, 16 KB, cache-resident while its triangles are drawn; cleared
// there, not in the map) and then written out once with streaming stores,
// which write whole cache lines without first reading them: the map costs
// one pass of memory writes, and no clearing pass nor reads.
//
// Fast path (CoveragePath::Fast): the camera pass's block coverage
// (block_coverage.h) and hierarchical depth test (depth_bounds.h), with a
// bound per block that is exact once a triangle has drawn all of its rows
// (the kernels write whole block rows, so they see every key of them) and
// is never refreshed from memory. Keys are computed eight texels at a time
// in SIMD doubles (depth_keys.h: the scalar bits), and a block row is
// tested and written as one SIMD select, in SSE2 or, chosen at run time,
// AVX2. Reference path (CoveragePath::Reference): the scalar per-sample
// walk in (py, px) order.
#pragma once

#include <cstdint>
#include <cstdlib>
#include <functional>
#include <memory>
#include <vector>

#include "raster/bin.h"
#include "raster/coverage.h"

namespace rastray {

// Storage of depth maps, reused between frames. A frame's maps are freed
// when it ends and the next frame's are the same size; fresh pages from the
// kernel would be zeroed first (on the Cornell box's 2048² cube map, 96 MB
// a frame: a fifth of the frame's CPU time in clear_page before the
// pool). A freed buffer is kept for the next map of its size; a map of
// another size first returns every kept buffer to the system, so the pool
// never holds more than what the last frame's maps used and a change of
// size costs nothing beyond the new maps. Thread-safe.
struct DepthMapRelease {
  size_t bytes = 0;
  void operator()(uint32_t* keys) const;
};
// Kept buffers, in bytes (for the tests).
size_t depthMapPoolBytes();

// A one-sample depth map, texel (x, y) at y·width + x. Allocated without
// clearing (its keys are indeterminate until every tile has been stored),
// aligned for streaming stores and, on Linux, advised to use huge pages:
// a lookup per shaded sample lands anywhere in 16 MB, and 4 KB pages
// would add a TLB miss to most of them.
struct DepthMap {
  int width = 0, height = 0;
  std::unique_ptr<uint32_t[], DepthMapRelease> keys;
  DepthMap() = default;
  DepthMap(int w, int h);
  size_t index(int x, int y) const { return size_t(y) * size_t(width) + size_t(x); }
  uint32_t key(int x, int y) const { return keys[index(x, y)]; }
};

using AlphaTestFunction = std::function<bool(const TriangleSetup&, int px, int py, int s)>;

// The fast path's vector width: Best picks, at run time, AVX-512 (F and
// VL: whole covered blocks a row of eight doubles per vector) where the
// CPU has it, else AVX2; Avx2 stops at AVX2; Baseline keeps to SSE2
// (x86-64's baseline). Identical keys; the choice is there for the tests
// that prove it.
enum class SimdLevel { Best, Avx2, Baseline };

// One tile of the pass, drawn into its local buffer.
class DepthOnlyTile {
 public:
  // `rect`: a TileGrid rect (at most kTileSize² texels).
  explicit DepthOnlyTile(const TileRect& rect);

  // Clears the buffer and draws the bin (grid.spp must be 1). `alphaTest`
  // as in rasterDepthPass (MASK coverage of a sample that passed the depth
  // test). Counters as rasterDepthPass's; samplesTested leaves out the
  // samples of blocks the hierarchical test skipped (all would fail).
  void render(const std::vector<TriangleSetup>& setups, const std::vector<uint32_t>& bin,
              const SampleGrid& grid, DepthFormat format, const AlphaTestFunction& alphaTest,
              DepthPassCounters* counters, CoveragePath path = CoveragePath::Fast,
              SimdLevel simd = SimdLevel::Best);

  // The key drawn at texel (px, py) of the rect.
  uint32_t key(int px, int py) const {
    return uint32_t(keys_[size_t(py - rect_.y0) * kTileSize + size_t(px - rect_.x0)]) ^ 0x80000000u;
  }
  const TileRect& rect() const { return rect_; }

  // Writes the rect's keys into the map (streaming stores where the rows
  // allow, then a store fence so that they are visible once the task ends).
  void store(DepthMap* map) const;

 private:
  TileRect rect_;
  // Biased keys (key ^ 2^31 as int32, so that signed SIMD compares order
  // them), rows of kTileSize.
  alignas(64) int32_t keys_[kTileSize * kTileSize];
};

// render then store: the pass over one tile of `map`.
void rasterDepthOnlyPass(const std::vector<TriangleSetup>& setups, const std::vector<uint32_t>& bin,
                         const SampleGrid& grid, const TileRect& rect, DepthFormat format,
                         const AlphaTestFunction& alphaTest, DepthMap* map, DepthPassCounters* counters,
                         CoveragePath path = CoveragePath::Fast, SimdLevel simd = SimdLevel::Best);

}  // namespace rastray
