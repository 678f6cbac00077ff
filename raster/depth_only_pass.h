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
// Where the time went at 2048² per face was memory and per-texel work: a
// cube map is 6 × 16 MB of keys, far beyond the caches, and nearly every
// texel of the Cornell box's faces lies in an 8×8 block that one wall
// covers whole. So a tile is drawn into a local buffer (64² keys, 16 KB,
// cache-resident) lazily, by 8×8 blocks: a block starts clear without
// being cleared, and a triangle that covers a block whole and is nearer
// than everything the block holds takes it as a plane (the triangle's
// setup index, no keys computed) when its four corner keys prove it
// (Avx2Row::keyRange; the first triangle covering a whole tile takes its
// 64 blocks at once). A block's keys are computed into the buffer only
// when a triangle draws part of it or meets its plane. The map keeps the
// same three states per block (BlockDepthMap): clear, a plane, or keys;
// only the blocks of keys are written to memory, and a lookup of a plane
// block evaluates the plane at the texel's sample (the bits of
// sampleDepthKey, which the kernels' keys equal). store() writes every
// texel's key into a plain DepthMap, for the tests and rasterDepthOnlyPass.
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
#include "raster/depth.h"

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

// A block of a tile (kCoverageBlock² texels) holds one of: nothing drawn
// (kBlockClear: every key kClearDepthKey), the keys of one triangle's
// depth plane (the setup's index), or keys stored texel by texel
// (kBlockKeys; in a BlockDepthMap, kBlockSlot | slot).
constexpr uint32_t kBlockClear = 0xFFFFFFFFu;
constexpr uint32_t kBlockKeys = 0xFFFFFFFEu;
// Blocks per tile (kTileSize / kCoverageBlock squared).
constexpr int kTileBlocks = (kTileSize / 8) * (kTileSize / 8);

// A one-sample depth map stored by 8×8 blocks, as the depth-only pass
// leaves it: per block, clear, a plane (an index into `planes`) or keys
// (kBlockSlot | slot: the block's 64 keys at slot · 64 of `keys`, rows of
// 8, the tiles' blocks of keys packed from the start of the buffer in the
// order the tiles stored them, so a map touches only the memory its
// blocks of keys fill). key(x, y) is the key a DepthMap of the same pass
// holds at (x, y), bit for bit.
constexpr uint32_t kBlockSlot = 0x80000000u;
struct BlockDepthMap {
  int width = 0, height = 0, blocksX = 0;
  DepthFormat format = DepthFormat::FloatReversed;
  glm::dvec2 sample{0.5};       // the texels' sample position within them
  DepthMap keys;                // blocks of keys, 64 a slot (as many slots as blocks)
  uint32_t slotsUsed = 0;       // taken atomically by the tiles' stores
  std::vector<uint32_t> owner;  // per block, rows of blocksX: kBlockClear, a plane or kBlockSlot | slot
  std::vector<Plane> planes;
  BlockDepthMap() = default;
  BlockDepthMap(int w, int h, DepthFormat f, const glm::dvec2& samplePosition);
  static bool isPlane(uint32_t o) { return o < kBlockSlot; }
  // Texel (x, y)'s index in the map's row-major order (y · width + x).
  size_t index(int x, int y) const { return size_t(y) * size_t(width) + size_t(x); }
  uint32_t key(int x, int y) const {
    const uint32_t o = owner[size_t(y / 8) * size_t(blocksX) + size_t(x / 8)];
    if (o == kBlockClear) return kClearDepthKey;
    if (o & kBlockSlot) return keys.keys[size_t(o & ~kBlockSlot) * 64 + size_t(y % 8) * 8 + size_t(x % 8)];
    return depthKey(format, planes[o].at(double(x) + sample.x, double(y) + sample.y));
  }
  // After every tile is stored (their planes are setup indices): keeps
  // only the planes of the setups that own blocks, renumbered.
  void keepPlanes(const std::vector<TriangleSetup>& setups);
};

// One tile of the pass, drawn into its local buffer.
class DepthOnlyTile {
 public:
  // `rect`: a TileGrid rect (at most kTileSize² texels).
  explicit DepthOnlyTile(const TileRect& rect);

  // Starts every block clear and draws the bin (grid.spp must be 1; the
  // setups must outlive the tile's key() and store() calls). `alphaTest`
  // as in rasterDepthPass (MASK coverage of a sample that passed the depth
  // test). Counters as rasterDepthPass's; samplesTested leaves out the
  // samples of blocks the hierarchical test skipped (all would fail).
  void render(const std::vector<TriangleSetup>& setups, const std::vector<uint32_t>& bin,
              const SampleGrid& grid, DepthFormat format, const AlphaTestFunction& alphaTest,
              DepthPassCounters* counters, CoveragePath path = CoveragePath::Fast,
              SimdLevel simd = SimdLevel::Best);

  // The key drawn at texel (px, py) of the rect (of a block not in the
  // buffer: the clear key, or its plane's key at the sample).
  uint32_t key(int px, int py) const {
    const size_t hb = blockOf(px, py);
    if ((blocks_.inBuffer >> hb) & 1u)
      return uint32_t(keys_[size_t(py - rect_.y0) * kTileSize + size_t(px - rect_.x0)]) ^ 0x80000000u;
    if (blocks_.owner[hb] == kBlockClear) return kClearDepthKey;
    return depthKey(format_,
                    (*setups_)[blocks_.owner[hb]].depth.at(double(px) + sample_.x, double(py) + sample_.y));
  }
  const TileRect& rect() const { return rect_; }
  // Computes the keys of every block into the buffer (key() then reads it):
  // for callers that ask key() of many texels. Changes no block's state.
  void loadAll();
  // Blocks held as a plane (for the tests).
  int planeBlocks() const;

  // Writes every texel's key into the map, then a store fence.
  void store(DepthMap* map) const;
  // Writes the blocks into `map` as they are (their owners as setup
  // indices; BlockDepthMap::keepPlanes renumbers them once every tile is
  // stored): only blocks of keys touch the map's keys.
  void store(BlockDepthMap* map) const;

  // The blocks' states, by block of the rect (rows of ceil(width / 8)):
  // owner kBlockClear, kBlockKeys or a setup index; a bit of inBuffer set
  // when the block's keys are in the buffer (always for kBlockKeys);
  // minKey, for a plane not in the buffer, its smallest key. Public for
  // the pass's kernels only.
  struct Blocks {
    uint32_t owner[kTileBlocks];
    uint32_t minKey[kTileBlocks];
    uint64_t inBuffer = 0;
  };

 private:
  size_t blockOf(int px, int py) const {
    return size_t((py - rect_.y0) / 8) * size_t(columns_) + size_t((px - rect_.x0) / 8);
  }
  TileRect rect_;
  int columns_ = 0;
  const std::vector<TriangleSetup>* setups_ = nullptr;
  DepthFormat format_ = DepthFormat::FloatReversed;
  glm::dvec2 sample_{0.5};
  Blocks blocks_;
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
