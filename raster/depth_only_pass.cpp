#include "raster/depth_only_pass.h"

#include <algorithm>
#include <cstring>
#include <string>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__linux__)
#include <sys/mman.h>
#endif

#include "common/error.h"
#include "raster/depth_bounds.h"
#include "raster/depth_keys.h"

namespace rastray {

namespace {

constexpr int B = kCoverageBlock;

// Set bits of a block mask (no POPCNT in the x86-64 baseline; the
// builtin would call libgcc).
inline int bitCount(uint64_t m) {
  m = m - ((m >> 1) & 0x5555555555555555ull);
  m = (m & 0x3333333333333333ull) + ((m >> 2) & 0x3333333333333333ull);
  m = (m + (m >> 4)) & 0x0F0F0F0F0F0F0F0Full;
  return int((m * 0x0101010101010101ull) >> 56);
}

// One block row's test and write: lanes i < width of `row` (texels), the
// covered lanes in `cover` (bit i). Returns the bits written; `rowMax`
// receives the largest key the row holds afterwards. The scalar form (rows
// narrower than a block, builds without SSE2).
template <typename Alpha>
uint32_t testRowScalar(const uint32_t (&keys)[8], uint32_t* row, int width, uint32_t cover, Alpha& alpha,
                       uint32_t* rowMax) {
  uint32_t written = 0, m = 0;
  for (int i = 0; i < width; ++i) {
    const uint32_t stored = row[i];
    uint32_t out = stored;
    if (((cover >> i) & 1u) && keys[i] < stored && alpha(i)) {
      out = keys[i];
      written |= 1u << i;
    }
    row[i] = out;
    m = std::max(m, out);
  }
  *rowMax = m;
  return written;
}

#if defined(__SSE2__)
// The lanes of an 8-bit mask as two vectors of all-ones / zero lanes.
inline void laneMasks(uint32_t bits, __m128i& lo, __m128i& hi) {
  const __m128i b = _mm_set1_epi32(int32_t(bits));
  const __m128i l = _mm_setr_epi32(1, 2, 4, 8), h = _mm_setr_epi32(16, 32, 64, 128);
  lo = _mm_cmpeq_epi32(_mm_and_si128(b, l), l);
  hi = _mm_cmpeq_epi32(_mm_and_si128(b, h), h);
}

inline uint32_t laneBits(__m128i lo, __m128i hi) {
  return uint32_t(_mm_movemask_ps(_mm_castsi128_ps(lo))) |
         (uint32_t(_mm_movemask_ps(_mm_castsi128_ps(hi))) << 4);
}

// Unsigned a < b per lane (SSE2 compares signed: flip the sign bits).
inline __m128i lessU32(__m128i a, __m128i b) {
  const __m128i flip = _mm_set1_epi32(int32_t(0x80000000u));
  return _mm_cmplt_epi32(_mm_xor_si128(a, flip), _mm_xor_si128(b, flip));
}

inline __m128i select(__m128i mask, __m128i a, __m128i b) {
  return _mm_or_si128(_mm_and_si128(mask, a), _mm_andnot_si128(mask, b));
}

// The largest unsigned lane of lo and hi.
inline uint32_t maxU32(__m128i lo, __m128i hi) {
  const __m128i m = select(lessU32(lo, hi), hi, lo);
  const __m128i m2 = _mm_shuffle_epi32(m, _MM_SHUFFLE(1, 0, 3, 2));
  const __m128i m3 = select(lessU32(m, m2), m2, m);
  const __m128i m4 = _mm_shuffle_epi32(m3, _MM_SHUFFLE(2, 3, 0, 1));
  return uint32_t(_mm_cvtsi128_si32(select(lessU32(m3, m4), m4, m3)));
}

// testRowScalar for a full row of eight texels, with the keys as vectors.
template <typename Alpha>
uint32_t testRowSimd(__m128i klo, __m128i khi, uint32_t* row, uint32_t cover, Alpha& alpha,
                     uint32_t* rowMax) {
  const __m128i slo = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row));
  const __m128i shi = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + 4));
  __m128i clo, chi;
  laneMasks(cover, clo, chi);
  __m128i plo = _mm_and_si128(clo, lessU32(klo, slo)), phi = _mm_and_si128(chi, lessU32(khi, shi));
  uint32_t pass = laneBits(plo, phi);
  if (alpha.active() && pass) {
    for (uint32_t m = pass; m; m &= m - 1) {
      const int i = __builtin_ctz(m);
      if (!alpha(i)) pass &= ~(1u << i);
    }
    laneMasks(pass, plo, phi);
  }
  const __m128i nlo = select(plo, klo, slo), nhi = select(phi, khi, shi);
  _mm_storeu_si128(reinterpret_cast<__m128i*>(row), nlo);
  _mm_storeu_si128(reinterpret_cast<__m128i*>(row + 4), nhi);
  *rowMax = maxU32(nlo, nhi);
  return pass;
}
#endif

}  // namespace

DepthMap::DepthMap(int w, int h) : width(w), height(h) {
  // Whole 2 MB pages (the huge-page size) and at least cache-line aligned.
  constexpr size_t kPage = size_t(2) << 20;
  const size_t bytes = std::max<size_t>(size_t(w) * size_t(h) * sizeof(uint32_t), 1);
  const size_t align = bytes >= kPage ? kPage : 64;
  void* p = std::aligned_alloc(align, (bytes + align - 1) / align * align);
  if (!p) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  if (align == kPage) madvise(p, (bytes + align - 1) / align * align, MADV_HUGEPAGE);  // advice only
#endif
  keys.reset(static_cast<uint32_t*>(p));
}

DepthOnlyTile::DepthOnlyTile(const TileRect& rect) : rect_(rect) {
  RASTRAY_CHECK(rect.x1 - rect.x0 <= kTileSize && rect.y1 - rect.y0 <= kTileSize && rect.x0 <= rect.x1 &&
                    rect.y0 <= rect.y1,
                "a depth-only tile is at most " + std::to_string(kTileSize) + " texels square");
}

void DepthOnlyTile::render(const std::vector<TriangleSetup>& setups, const std::vector<uint32_t>& bin,
                           const SampleGrid& grid, DepthFormat format, const AlphaTestFunction& alphaTest,
                           DepthPassCounters* counters, CoveragePath path) {
  RASTRAY_CHECK(grid.spp == 1,
                "the depth-only pass takes 1 sample per texel, not " + std::to_string(grid.spp));
  const TileRect& rect = rect_;
  const int width = rect.x1 - rect.x0, height = rect.y1 - rect.y0;
  for (int j = 0; j < height; ++j) std::fill_n(&keys_[size_t(j) * kTileSize], size_t(width), kClearDepthKey);
  CoverageScratch scratch;
  if (path == CoveragePath::Reference) {
    for (uint32_t index : bin) {
      const TriangleSetup& t = setups[index];
      counters->coverageTests +=
          forEachCoveredSampleReference(t, grid, rect, scratch, [&](int px, int py, int s) {
            ++counters->samplesTested;
            uint32_t& stored = keys_[size_t(py - rect.y0) * kTileSize + size_t(px - rect.x0)];
            const uint32_t key = sampleDepthKey(t, grid, format, px, py, s);
            if (!(key < stored)) return;  // keys only: a tie keeps the stored key
            if (alphaTest && !alphaTest(t, px, py, s)) {
              ++counters->alphaRejected;
              return;
            }
            ++counters->samplesPassed;
            stored = key;
          });
    }
    return;
  }
  const int columns = (width + B - 1) / B;
  const size_t blocks = size_t(columns) * size_t((height + B - 1) / B);
  // Per block of the rect: the exact largest key of each of its rows and
  // of the block (all clear to begin with).
  uint32_t rowMax[(kTileSize / B) * (kTileSize / B) * B], blockMax[(kTileSize / B) * (kTileSize / B)];
  std::fill_n(rowMax, blocks * B, kClearDepthKey);
  std::fill_n(blockMax, blocks, kClearDepthKey);
  const glm::dvec2 pos = grid.positions[0];
  const int64_t U = grid.unitsPerPixel;
  uint64_t mask = 0;

  for (uint32_t index : bin) {
    const TriangleSetup& t = setups[index];
    const PixelBounds r = boundsIn(t, rect);
    if (r.empty()) continue;
    counters->coverageTests += r.samples(1);
    prepareOffsets(t, grid, scratch);
    const uint32_t triangleKey = minKeyOverTriangle(t, format, U);
    for (int by = rect.y0 + (r.y0 - rect.y0) / B * B; by <= r.y1; by += B)
      for (int bx = rect.x0 + (r.x0 - rect.x0) / B * B; bx <= r.x1; bx += B) {
        const int cx0 = std::max(bx, r.x0), cy0 = std::max(by, r.y0);
        const PixelBlock b{cx0, cy0, std::min(bx + B - 1, r.x1) - cx0 + 1,
                           std::min(by + B - 1, r.y1) - cy0 + 1};
        int64_t lo[3];
        const BlockClass c = classifyBlock(t, scratch, U, b, lo);
        if (c == BlockClass::Reject) continue;
        const size_t hb = size_t((by - rect.y0) / B) * size_t(columns) + size_t((bx - rect.x0) / B);
        // Hierarchical test: behind every stored key of the block.
        if (blockMax[hb] != kClearDepthKey &&
            std::max(triangleKey, minKeyOverBlock(t, format, b, pos, pos)) > blockMax[hb])
          continue;
        if (c == BlockClass::Accept)
          mask = fullBlockMask(b);
        else
          blockMasks(t, scratch, U, 1, b, lo, &mask);
        if (mask == 0) continue;
        counters->samplesTested += uint64_t(bitCount(mask));
        // The block of the rect: bw texels wide at (bx, by); t's block b
        // starts shiftX columns and j0 rows into it.
        const int bw = std::min(B, rect.x1 - bx);
        const int shiftX = b.x - bx, j0 = b.y - by;
        double column[8];
        planeColumnTerms(t.depth, bx, pos.x, column);
        uint32_t* rowMaxOf = &rowMax[hb * B];
        for (int j = j0; j < j0 + b.h; ++j) {
          const uint32_t cover = uint32_t((mask >> (8 * (j - j0))) & 0xFFu) << shiftX;
          if (cover == 0) continue;
          uint32_t* row = &keys_[size_t(by + j - rect.y0) * kTileSize + size_t(bx - rect.x0)];
          struct Alpha {
            const AlphaTestFunction& test;
            const TriangleSetup& t;
            int x, y;
            DepthPassCounters* counters;
            bool active() const { return bool(test); }
            bool operator()(int i) {
              if (!test || test(t, x + i, y, 0)) return true;
              ++counters->alphaRejected;
              return false;
            }
          } alpha{alphaTest, t, bx, by + j, counters};
          const double rowTerm = planeRowTerm(t.depth, by + j, pos.y);
          uint32_t pass;
#if defined(__SSE2__)
          if (bw == B) {
            __m128i klo, khi;
            if (format == DepthFormat::FloatReversed || format == DepthFormat::Float) {
              floatRowKeys(format == DepthFormat::FloatReversed, column, rowTerm, klo, khi);
            } else {
              alignas(16) uint32_t k[8];
              planeRowKeys(format, column, rowTerm, k);
              klo = _mm_load_si128(reinterpret_cast<const __m128i*>(k));
              khi = _mm_load_si128(reinterpret_cast<const __m128i*>(k + 4));
            }
            pass = testRowSimd(klo, khi, row, cover, alpha, &rowMaxOf[j]);
          } else
#endif
          {
            uint32_t k[8];
            planeRowKeys(format, column, rowTerm, k);
            pass = testRowScalar(k, row, bw, cover, alpha, &rowMaxOf[j]);
          }
          counters->samplesPassed += uint64_t(bitCount(pass));
        }
        const int bh = std::min(B, rect.y1 - by);
        blockMax[hb] = *std::max_element(rowMaxOf, rowMaxOf + bh);
      }
  }
}

void DepthOnlyTile::store(DepthMap* map) const {
  const int width = rect_.x1 - rect_.x0;
  for (int y = rect_.y0; y < rect_.y1; ++y) {
    const uint32_t* src = &keys_[size_t(y - rect_.y0) * kTileSize];
    uint32_t* dst = &map->keys[map->index(rect_.x0, y)];
    int i = 0;
#if defined(__SSE2__)
    // Streaming stores need 16-byte aligned destinations; the maps' rows
    // are whenever the width is a multiple of 4 (every tile starts at a
    // multiple of 64 texels).
    if ((reinterpret_cast<uintptr_t>(dst) & 15) == 0)
      for (; i + 4 <= width; i += 4)
        _mm_stream_si128(reinterpret_cast<__m128i*>(dst + i),
                         _mm_load_si128(reinterpret_cast<const __m128i*>(src + i)));
#endif
    std::memcpy(dst + i, src + i, size_t(width - i) * sizeof(uint32_t));
  }
#if defined(__SSE2__)
  _mm_sfence();  // streaming stores are weakly ordered: publish them before the task completes
#endif
}

void rasterDepthOnlyPass(const std::vector<TriangleSetup>& setups, const std::vector<uint32_t>& bin,
                         const SampleGrid& grid, const TileRect& rect, DepthFormat format,
                         const AlphaTestFunction& alphaTest, DepthMap* map, DepthPassCounters* counters,
                         CoveragePath path) {
  DepthOnlyTile tile(rect);
  tile.render(setups, bin, grid, format, alphaTest, counters, path);
  tile.store(map);
}

}  // namespace rastray
