// Pass 1's depth test and write (rasterDepthPass, coverage.h).
//
// A triangle whose bounds within the tile span at most 8 × 8 pixels and 64
// samples (nearly every triangle of a 10^6-triangle terrain at 1080p) takes
// the small-triangle path: its masks over its bounds straight from the
// edge functions, then per block it touches the same steps as below.
// The fast path walks each triangle block by block (block_coverage.h) and
// tests the covered samples of a block from its masks; a block the
// triangle covers whole, eight pixels wide, is tested and written in SIMD
// lanes at float formats without an alpha test (depth_lanes.h: every
// entry of its rows a vector at a time, the same bits, ties handed back
// to the id rule here); other whole blocks take their keys a block row at
// a time, eight in SIMD doubles (depth_keys.h, the same bits). Samples
// tested from masks at 4 (8, 16) spp take a pixel's four samples as one
// vector (pixelSampleKeys, the same bits). In front of that, a
// hierarchical depth test per block of the rect: an upper bound of the
// keys stored in the block against a lower bound of the triangle's keys
// there; a block where the triangle is behind everything stored is skipped
// (every sample would fail: key > stored, ties impossible). Within one
// triangle every sample is tested once, so the order of the samples does
// not change the result; the triangles keep their bin order. The reference
// path (CoveragePath::Reference) and the traced triangles run the scalar
// per-sample loop in (py, px, s) order, without the hierarchical test.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>

#include "raster/coverage.h"
#include "raster/depth_bounds.h"
#include "raster/depth_keys.h"
#include "raster/depth_lanes.h"

namespace rastray {

namespace {

std::string hexKey(uint32_t key) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08x", key);
  return buf;
}

// Whether the traced pixel lies in t's pixel bounds within the tile.
bool tracedIn(const TraceRequest& trace, const TriangleSetup& t, const TileRect& rect) {
  return trace.sink && trace.pixel.x >= std::max(rect.x0, t.pixelMin.x) &&
         trace.pixel.x <= std::min(rect.x1 - 1, t.pixelMax.x) &&
         trace.pixel.y >= std::max(rect.y0, t.pixelMin.y) &&
         trace.pixel.y <= std::min(rect.y1 - 1, t.pixelMax.y);
}

// The depth test at a sample: the fragment's key against the stored key and
// the setup that wrote it (instance and triangle -1 when nothing did).
void traceDepthTest(TraceSink& sink, const std::vector<TriangleSetup>& setups, const TriangleSetup& t, int s,
                    uint32_t key, uint32_t stored, uint32_t winner, bool pass) {
  TraceEvent e{TraceStage::Depth, s, t.instance, t.triangle, 1, pass ? "pass" : "fail", {}};
  e.add("key", hexKey(key)).add("stored", hexKey(stored));
  e.add("stored_instance", winner == kNoSetup ? "-1" : std::to_string(setups[winner].instance));
  e.add("stored_triangle", winner == kNoSetup ? "-1" : std::to_string(setups[winner].triangle));
  sink.record(std::move(e));
}

// Per block of the rect (kCoverageBlock² pixels aligned to its corner): an
// upper bound of every key stored there, recomputed from the target when a
// write has made it stale (keys only decrease, so a stale bound is still
// an upper bound, only a looser one).
class BlockDepthBounds {
 public:
  BlockDepthBounds(const DepthTarget& target, const TileRect& rect, bool cleared)
      : target_(target),
        rect_(rect),
        columns_((rect.x1 - rect.x0 + kCoverageBlock - 1) / kCoverageBlock),
        bound_(size_t(columns_) * size_t((rect.y1 - rect.y0 + kCoverageBlock - 1) / kCoverageBlock),
               kClearDepthKey),
        stale_(bound_.size(), 1),
        left_(bound_.size(), 0) {
    if (cleared)
      for (size_t b = 0; b < left_.size(); ++b) left_[b] = blockSamples(b, target.spp);
  }

  size_t block(int x, int y) const {
    return size_t((y - rect_.y0) / kCoverageBlock) * size_t(columns_) +
           size_t((x - rect_.x0) / kCoverageBlock);
  }
  // Whether every key stored in block b is nearer than the lowest key a
  // triangle can have there (lowestKey(), computed only when needed): a
  // stale bound that already decides it is not refreshed.
  // A block of a cleared rect where fewer samples were written than it
  // holds still has a sample at kClearDepthKey, so its bound is that key
  // and nothing is culled there: known without refreshing (reading its
  // keys), which small triangles would otherwise do once each.
  template <typename F>
  bool culls(size_t b, F lowestKey) {
    if (bound_[b] == kClearDepthKey && !stale_[b]) return false;
    if (left_[b] != 0) return false;
    const uint32_t lowest = lowestKey();
    if (lowest > bound_[b]) return true;
    if (!stale_[b]) return false;
    refresh(b);
    return lowest > bound_[b];
  }
  void markStale(size_t b) { stale_[b] = 1; }
  // `n` samples of block b were written (by the fast walk, which counts).
  void addWrites(size_t b, uint32_t n) { left_[b] = n >= left_[b] ? 0 : left_[b] - n; }
  // Every sample of block b was just written, the largest key being `key`.
  void setExact(size_t b, uint32_t key) {
    bound_[b] = key;
    stale_[b] = 0;
  }
  // Whether b (a block clipped to a triangle's bounds) is the whole of its block of the rect.
  bool wholeBlock(const PixelBlock& b) const {
    const int bx = rect_.x0 + (b.x - rect_.x0) / kCoverageBlock * kCoverageBlock;
    const int by = rect_.y0 + (b.y - rect_.y0) / kCoverageBlock * kCoverageBlock;
    return b.x == bx && b.y == by && b.w == std::min(kCoverageBlock, rect_.x1 - bx) &&
           b.h == std::min(kCoverageBlock, rect_.y1 - by);
  }
  // Written by a walk that does not count its writes (reference, traced):
  // their number is unknown, so the blocks are refreshed when asked.
  void markStale(const PixelBounds& r) {
    constexpr int B = kCoverageBlock;
    for (int y = rect_.y0 + (r.y0 - rect_.y0) / B * B; y <= r.y1; y += B)
      for (int x = rect_.x0 + (r.x0 - rect_.x0) / B * B; x <= r.x1; x += B) {
        stale_[block(x, y)] = 1;
        left_[block(x, y)] = 0;
      }
  }

 private:
  void refresh(size_t b) {
    const int x0 = rect_.x0 + int(b % size_t(columns_)) * kCoverageBlock;
    const int y0 = rect_.y0 + int(b / size_t(columns_)) * kCoverageBlock;
    const int x1 = std::min(x0 + kCoverageBlock, rect_.x1), y1 = std::min(y0 + kCoverageBlock, rect_.y1);
    const size_t n = size_t(x1 - x0) * size_t(target_.spp);
    uint32_t m = 0;
    for (int y = y0; y < y1; ++y) m = std::max(m, maxKey(&target_.keys[target_.index(x0, y, 0)], n));
    bound_[b] = m;
    stale_[b] = 0;
  }

  // Samples of block b within the rect.
  uint32_t blockSamples(size_t b, int spp) const {
    const int x0 = rect_.x0 + int(b % size_t(columns_)) * kCoverageBlock;
    const int y0 = rect_.y0 + int(b / size_t(columns_)) * kCoverageBlock;
    return uint32_t(std::min(kCoverageBlock, rect_.x1 - x0) * std::min(kCoverageBlock, rect_.y1 - y0) * spp);
  }

  const DepthTarget& target_;
  TileRect rect_;
  int columns_;
  std::vector<uint32_t> bound_;
  std::vector<uint8_t> stale_;
  // Per block, its samples less the writes counted since the pass began
  // on a cleared rect (a count of writes, not of distinct samples; 0 once
  // they reach the samples, when unknown, and always when the rect was
  // not cleared): while above 0, a sample of the block still holds
  // kClearDepthKey. (A count down, so culls() divides nothing.)
  std::vector<uint32_t> left_;
};

// Whether none of the eight keys equals its stored key (then bit k of
// *less says keys[k] < stored[k], unsigned); false on a tie, which the
// caller decides per sample.
inline bool rowLess(const uint32_t (&keys)[8], const uint32_t* stored, uint32_t* less) {
#if defined(__SSE2__)
  const __m128i bias = _mm_set1_epi32(int(0x80000000u));
  const __m128i k0 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(keys));
  const __m128i k1 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(keys + 4));
  const __m128i s0 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(stored));
  const __m128i s1 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(stored + 4));
  const int ties = _mm_movemask_epi8(_mm_or_si128(_mm_cmpeq_epi32(k0, s0), _mm_cmpeq_epi32(k1, s1)));
  if (ties != 0) return false;
  // Unsigned a < b as signed (a ^ 2^31) < (b ^ 2^31).
  const __m128i l0 = _mm_cmplt_epi32(_mm_xor_si128(k0, bias), _mm_xor_si128(s0, bias));
  const __m128i l1 = _mm_cmplt_epi32(_mm_xor_si128(k1, bias), _mm_xor_si128(s1, bias));
  *less = uint32_t(_mm_movemask_ps(_mm_castsi128_ps(l0))) | uint32_t(_mm_movemask_ps(_mm_castsi128_ps(l1)))
                                                                << 4;
  return true;
#else
  uint32_t m = 0;
  for (int k = 0; k < 8; ++k) {
    if (keys[k] == stored[k]) return false;
    m |= uint32_t(keys[k] < stored[k]) << k;
  }
  *less = m;
  return true;
#endif
}

#if defined(__SSE2__)
// Lane k all ones where bit k of m (m < 16) is set, else zero.
inline __m128i laneMask4(uint32_t m) {
  const __m128i bits = _mm_set_epi32(8, 4, 2, 1);
  return _mm_cmpeq_epi32(_mm_and_si128(_mm_set1_epi32(int(m)), bits), bits);
}
#endif

#if defined(__SSE2__)
// The small-triangle path's coverage of rows [0, h) of its bounds at one
// sample: r0, r1, r2 each edge's E + bias + offset at the row's first
// pixel, stepped by s0, s1, s2 a row; col[e][v] the lanes' column terms
// (columns 2v, 2v + 1: that many times a·U). Bit 8·j + i set when every
// edge's sum at pixel (i, j) is >= 0 (int64, exact: each sum is an edge
// function at a sample of the image or of the eight pixels right of a
// row's first, well within its range); columns from 2·V on are left to
// the caller to mask.
template <int V>
inline uint64_t smallRows(const __m128i (&col)[3][4], int64_t r0, int64_t r1, int64_t r2, int64_t s0,
                          int64_t s1, int64_t s2, int h) {
  uint64_t m = 0;
  for (int j = 0; j < h; ++j) {
    const __m128i b0 = _mm_set1_epi64x(r0), b1 = _mm_set1_epi64x(r1), b2 = _mm_set1_epi64x(r2);
    uint32_t failed = 0;
    for (int v = 0; v < V; ++v) {
      const __m128i x = _mm_or_si128(_mm_or_si128(_mm_add_epi64(b0, col[0][v]), _mm_add_epi64(b1, col[1][v])),
                                     _mm_add_epi64(b2, col[2][v]));
      failed |= uint32_t(_mm_movemask_pd(_mm_castsi128_pd(x))) << (2 * v);
    }
    m |= uint64_t(~failed & 0xFFu) << (8 * j);
    r0 += s0, r1 += s1, r2 += s2;
  }
  return m;
}
#endif

}  // namespace

void rasterDepthPass(const std::vector<TriangleSetup>& setups, const std::vector<uint32_t>& bin,
                     const SampleGrid& grid, const TileRect& rect, DepthFormat format, DepthFunc func,
                     const std::function<bool(const TriangleSetup&, int, int, int)>& alphaTest,
                     const TraceRequest& trace, DepthTarget* target, DepthPassCounters* counters,
                     CoveragePath path, bool clearedRect) {
  CoverageScratch scratch;
  const bool keysOnly = target->winners.empty();
  uint32_t* keys = target->keys.data();
  uint32_t* winners = target->winners.data();
  const int spp = grid.spp;
  const int64_t U = grid.unitsPerPixel;
  BlockDepthBounds bounds(*target, rect, clearedRect);
  // DepthTarget::index's terms, held here (the key and winner stores
  // would otherwise make the compiler reload them per sample).
  const size_t targetWidth = size_t(target->width);
  const int targetX0 = target->x0, targetY0 = target->y0;
  glm::dvec2 lowPos(1.0), highPos(0.0);
  for (const glm::dvec2& q : grid.positions) {
    lowPos = glm::min(lowPos, q);
    highPos = glm::max(highPos, q);
  }
  // Whole covered blocks eight pixels wide go to the lanes (depth_lanes.h)
  // at float formats without an alpha test; their per-entry pixel offsets
  // and sample positions, a block row's 8·spp entries in target order.
  const bool blockLanes =
      !alphaTest && (format == DepthFormat::FloatReversed || format == DepthFormat::Float);
#if defined(__SSE2__)
  // A pixel's samples four a vector where the masks are tested
  // (testMaskedSamples) at float formats without an alpha test: the
  // samples' positions in the pixel, x and y apart.
  const bool pixelLanes = blockLanes && spp % 4 == 0;
  const bool reversedKeys = format == DepthFormat::FloatReversed;
  std::vector<double> sampleX(static_cast<size_t>(spp)), sampleY(static_cast<size_t>(spp));
  for (size_t s = 0; s < size_t(spp); ++s) {
    sampleX[s] = grid.positions[s].x;
    sampleY[s] = grid.positions[s].y;
  }
#endif
  std::vector<double> entries;
  DepthBlockLanes lanes;
  uint8_t coverBits[kCoverageBlock * 8];  // a partial block's entry bits, up to 8 spp
  if (blockLanes) {
    const size_t n = size_t(kCoverageBlock) * size_t(spp);
    entries.resize(3 * n);
    for (size_t j = 0; j < n; ++j) {
      entries[j] = double(j / size_t(spp));
      entries[n + j] = grid.positions[j % size_t(spp)].x;
      entries[2 * n + j] = grid.positions[j % size_t(spp)].y;
    }
    lanes.spp = spp;
    lanes.entryPixel = entries.data();
    lanes.entryX = entries.data() + n;
    lanes.entryY = entries.data() + 2 * n;
    lanes.reversed = format == DepthFormat::FloatReversed;
    lanes.rowStride = size_t(target->width) * size_t(spp);
  }

  // The depth test and write of t at one sample, traced when asked (the
  // reference and traced walks).
  const auto test = [&](const TriangleSetup& t, uint32_t index, uint64_t id, int px, int py, int s,
                        bool traceHere) {
    const size_t i = target->index(px, py, s);
    const uint32_t key = sampleDepthKey(t, grid, format, px, py, s);
    const uint32_t stored = keys[i];
    // The stored winner's id (another setup, likely out of cache) only
    // decides ties; keys only (shadow maps): ties change no key, so the
    // id rule is moot and a tie fails.
    bool pass = key < stored;
    if (key == stored && !keysOnly) {
      const uint32_t winner = winners[i];
      pass = passesDepthTest(func, key, id, stored, winner == kNoSetup ? UINT64_MAX : setups[winner].id());
    }
    const bool traced = traceHere && px == trace.pixel.x && py == trace.pixel.y;
    if (traced)
      traceDepthTest(*trace.sink, setups, t, s, key, stored, keysOnly ? kNoSetup : winners[i], pass);
    if (!pass) return;
    if (alphaTest && !alphaTest(t, px, py, s)) {
      ++counters->alphaRejected;
      if (traced)
        trace.sink->record(TraceEvent{TraceStage::Alpha, s, t.instance, t.triangle, 1, "discarded", {}}.add(
            "coverage", "below the MASK cutoff"));
      return;
    }
    ++counters->samplesPassed;
    keys[i] = key;
    if (!keysOnly) winners[i] = index;
  };

  // A triangle whose pixels within the rect span at most a block's width
  // and height and hold at most this many samples takes the
  // small-triangle path below (masks of 64 bits: 64 samples at most).
  constexpr int kSmallSamples = 64;
  uint64_t smallMasks[kSmallSamples];
  const glm::i64vec2* sampleOffsets = grid.offsets.data();
  // The next triangles' setups (304 bytes each, mostly not in cache at
  // 10^6 triangles) are fetched this many triangles ahead.
  constexpr size_t kPrefetch = 4;
  const size_t binSize = bin.size();
  for (size_t n = 0; n < binSize; ++n) {
    const uint32_t index = bin[n];
    if (n + kPrefetch < binSize) {
      // The fields the walk reads: the first 160 bytes (ids, vertices,
      // edges, bounds, depth plane), up to four cache lines.
      const char* next = reinterpret_cast<const char*>(&setups[bin[n + kPrefetch]]);
      __builtin_prefetch(next);
      __builtin_prefetch(next + 64);
      __builtin_prefetch(next + 128);
      __builtin_prefetch(next + 159);
    }
    const TriangleSetup& t = setups[index];
    const uint64_t id = t.id();
    const bool traceHere = tracedIn(trace, t, rect);
    if (traceHere || path == CoveragePath::Reference) {
      if (traceHere) traceCoverage(*trace.sink, t, grid, trace.pixel.x, trace.pixel.y);
      uint64_t tested = 0;
      counters->coverageTests +=
          forEachCoveredSample(path, t, grid, rect, scratch, [&](int px, int py, int s) {
            ++tested;
            test(t, index, id, px, py, s, traceHere);
          });
      counters->samplesTested += tested;
      const PixelBounds r = boundsIn(t, rect);
      if (!r.empty()) bounds.markStale(r);
      continue;
    }

    const PixelBounds r = boundsIn(t, rect);
    if (r.empty()) continue;
    counters->coverageTests += r.samples(spp);
    // The triangle's lowest key, computed when the hierarchical test first
    // needs it (a block of a cleared rect that still holds a cleared
    // sample never does).
    uint32_t triangleKey = 0;
    bool haveTriangleKey = false;
    const auto lowestKeyOver = [&](const PixelBlock& b) {
      if (!haveTriangleKey) {
        triangleKey = minKeyOverTriangle(t, format, U);
        haveTriangleKey = true;
      }
      return std::max(triangleKey, minKeyOverBlock(t, format, b, lowPos, highPos));
    };
    // The same test as `test` above without the trace (not traced here):
    // one sample of the block `written` counts for.
    const auto testKey = [&](int px, int py, int s, uint32_t key, uint32_t& written, uint32_t& writtenMax)
        __attribute__((always_inline)) {
      const size_t i =
          (size_t(py - targetY0) * targetWidth + size_t(px - targetX0)) * size_t(spp) + size_t(s);
      const uint32_t stored = keys[i];
      if (key > stored) return;
      if (key == stored &&
          (keysOnly || !passesDepthTest(func, key, id, stored,
                                        winners[i] == kNoSetup ? UINT64_MAX : setups[winners[i]].id())))
        return;
      if (alphaTest && !alphaTest(t, px, py, s)) {
        ++counters->alphaRejected;
        return;
      }
      ++counters->samplesPassed;
      keys[i] = key;
      if (!keysOnly) winners[i] = index;
      ++written;
      writtenMax = std::max(writtenMax, key);
    };
#if defined(__SSE2__)
    // The samples set in per-sample masks as testMaskedSamples below,
    // pixel by pixel, its samples four a vector (consecutive in the
    // target): the keys (pixelSampleKeys: sampleDepthKey's bits), the test
    // against the stored keys and the write, masked to the covered
    // samples. Only a vector holding a tie with a covered sample tests
    // them one by one (the id rule; keys only: a tie fails, as key <
    // stored says). Each covered sample is still tested once, so the
    // order changes nothing.
    const auto testPixelLanes = [&](int x0, int y0, const uint64_t* sampleMasks, uint32_t& written,
                                    uint32_t& writtenMax) __attribute__((always_inline)) {
      const __m128i signBit = _mm_set1_epi32(int(0x80000000u));
      const __m128i setup = _mm_set1_epi32(int(index));
      uint64_t pixels = 0;
      for (int s = 0; s < spp; ++s) pixels |= sampleMasks[s];
      while (pixels) {
        const int bit = __builtin_ctzll(pixels);
        pixels &= pixels - 1;
        const int px = x0 + (bit & 7), py = y0 + (bit >> 3);
        const size_t pixel = (size_t(py - targetY0) * targetWidth + size_t(px - targetX0)) * size_t(spp);
        for (int s = 0; s < spp; s += 4) {
          uint32_t cover = 0;
          for (int k = 0; k < 4; ++k) cover |= uint32_t(sampleMasks[s + k] >> bit & 1u) << k;
          if (cover == 0) continue;
          const __m128i key =
              pixelSampleKeys(reversedKeys, t.depth, px, py, &sampleX[size_t(s)], &sampleY[size_t(s)]);
          uint32_t* stored = keys + pixel + size_t(s);
          const __m128i old = _mm_loadu_si128(reinterpret_cast<const __m128i*>(stored));
          const uint32_t ties =
              uint32_t(_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(key, old)))) & cover;
          if (ties != 0 && !keysOnly) {
            alignas(16) uint32_t sampleKeys[4];
            _mm_store_si128(reinterpret_cast<__m128i*>(sampleKeys), key);
            for (int k = 0; k < 4; ++k)
              if (cover >> k & 1u) testKey(px, py, s + k, sampleKeys[k], written, writtenMax);
            continue;
          }
          // Unsigned key < stored as signed (key ^ 2^31) < (stored ^ 2^31).
          const __m128i less = _mm_cmplt_epi32(_mm_xor_si128(key, signBit), _mm_xor_si128(old, signBit));
          const uint32_t pass = uint32_t(_mm_movemask_ps(_mm_castsi128_ps(less))) & cover;
          if (pass == 0) continue;
          const __m128i write = laneMask4(pass);
          _mm_storeu_si128(reinterpret_cast<__m128i*>(stored),
                           _mm_or_si128(_mm_and_si128(write, key), _mm_andnot_si128(write, old)));
          if (!keysOnly) {
            __m128i* winner = reinterpret_cast<__m128i*>(winners + pixel + size_t(s));
            _mm_storeu_si128(winner, _mm_or_si128(_mm_and_si128(write, setup),
                                                  _mm_andnot_si128(write, _mm_loadu_si128(winner))));
          }
          const uint32_t passed = uint32_t(bitCount(pass));
          counters->samplesPassed += passed;
          written += passed;
        }
      }
    };
#endif
    // The samples of one block set in its per-sample masks (bit 8·y + x
    // from the block's corner x0, y0), tested a pixel's four samples at
    // once where pixelLanes allows, else sample by sample in bit order;
    // the block's hierarchical bound learns what was written.
    const auto testMaskedSamples = [&](int x0, int y0, const uint64_t* sampleMasks, size_t hb)
        __attribute__((always_inline)) {
      uint32_t written = 0, writtenMax = 0;
      int tested = 0;
      for (int s = 0; s < spp; ++s) tested += bitCount(sampleMasks[s]);
#if defined(__SSE2__)
      if (pixelLanes) {
        testPixelLanes(x0, y0, sampleMasks, written, writtenMax);
      } else
#endif
      {
        for (int s = 0; s < spp; ++s) {
          const glm::dvec2 q = grid.positions[size_t(s)];
          for (uint64_t m = sampleMasks[s]; m; m &= m - 1) {
            const int bit = __builtin_ctzll(m);
            const int px = x0 + (bit & 7), py = y0 + (bit >> 3);
            // sampleDepthKey's operations (the position px + q.x, py + q.y).
            testKey(px, py, s, depthKey(format, t.depth.at(double(px) + q.x, double(py) + q.y)), written,
                    writtenMax);
          }
        }
      }
      counters->samplesTested += uint64_t(tested);
      if (written != 0) {
        bounds.addWrites(hb, written);
        bounds.markStale(hb);
      }
    };
    // Block b (eight pixels wide) in lanes (depth_lanes.h): the samples
    // set in `masks` (per sample, as testMaskedSamples), or every sample
    // when masks is nullptr; `cover` the same as the lanes' entry bits. A
    // vector with a tie comes back, its covered entries tested here.
    const auto testLanes = [&](const PixelBlock& b, const uint64_t* masks, const uint8_t* cover,
                               uint32_t& written, uint32_t& writtenMax) {
      lanes.v0 = t.depth.v0, lanes.dx = t.depth.dx, lanes.dy = t.depth.dy;
      lanes.x0 = t.depth.x0, lanes.y0 = t.depth.y0;
      lanes.x = b.x, lanes.y = b.y, lanes.rows = b.h;
      lanes.index = index;
      lanes.cover = cover;
      const size_t first = target->index(b.x, b.y, 0);
      lanes.keys = keys + first;
      lanes.winners = keysOnly ? nullptr : winners + first;
      DepthBlockTally tally;
      size_t width = 1;
      for (size_t v = 0;; ++v) {
        v = depthBlockLanes(lanes, v, &width, &tally);
        if (v >= size_t(kCoverageBlock * spp) / width * size_t(b.h)) break;
        const int j = int(v % size_t(b.h)), py = b.y + j;
        for (size_t e = v / size_t(b.h) * width, end = e + width; e < end; ++e) {
          const int i = int(e / size_t(spp)), s = int(e % size_t(spp)), px = b.x + i;
          if (masks && !(masks[s] >> (8 * j + i) & 1u)) continue;
          testKey(px, py, s, sampleDepthKey(t, grid, format, px, py, s), written, writtenMax);
        }
      }
      counters->samplesPassed += tally.written;
      written += tally.written;
      writtenMax = std::max(writtenMax, tally.writtenMax);
    };
    constexpr int B = kCoverageBlock;
    const int w = r.x1 - r.x0 + 1, h = r.y1 - r.y0 + 1;
    if (w <= B && h <= B && w * h * spp <= kSmallSamples) {
      // Small triangle: its pixels within the rect span at most 8 × 8 (so
      // at most 2 × 2 blocks) and hold a few samples. Their masks straight
      // from the edge functions over its bounds, E + bias >= 0 at each
      // sample (exact int64: the rule block_coverage.h's masks implement;
      // E stepped by a·U and b·U from the bounds' corner, each step an E
      // at a pixel corner in the image, so the same integers as at()),
      // with bit 8·j + i for pixel (r.x0 + i, r.y0 + j), without
      // classifying blocks or preparing their int32 lanes. Then per block
      // of the rect holding a covered sample: its hierarchical test (on
      // the block clipped to the bounds, as the block walk's), the depth
      // tests of its samples in the partial-block order (sample, then
      // pixel) and the same counts. A block the walk would visit that
      // holds no covered sample is skipped: it tests and writes nothing,
      // and whether it is culled counts nothing either, so the keys,
      // winners and counters are the block walk's.
      // Edge e's part of sample k's offset in the pixel (exact int64),
      // added to the bounds' corner value where a sample's masks begin.
      const auto sampleTerm = [&](int e, int k) {
        return t.edge[e].a * sampleOffsets[k].x + t.edge[e].b * sampleOffsets[k].y;
      };
      const int64_t X0 = int64_t(r.x0) * U, Y0 = int64_t(r.y0) * U;
      int64_t row0 = t.edge[0].at(X0, Y0) + t.edge[0].bias, row1 = t.edge[1].at(X0, Y0) + t.edge[1].bias,
              row2 = t.edge[2].at(X0, Y0) + t.edge[2].bias;
      const int64_t stepX0 = int64_t(t.edge[0].a) * U, stepX1 = int64_t(t.edge[1].a) * U,
                    stepX2 = int64_t(t.edge[2].a) * U;
      const int64_t stepY0 = int64_t(t.edge[0].b) * U, stepY1 = int64_t(t.edge[1].b) * U,
                    stepY2 = int64_t(t.edge[2].b) * U;
      uint64_t any = 0;
      const uint64_t columns = ((uint64_t(1) << w) - 1) * 0x0101010101010101ull;
#if defined(__SSE2__)
      // Two columns a vector (int64 lanes: i·a·U added to the row's E),
      // a pixel covered when the three sums' sign bits are clear
      // (MOVMSKPD reads them); columns past w masked off after.
      __m128i col[3][4];
      const int64_t stepX[3] = {stepX0, stepX1, stepX2};
      for (int e = 0; e < 3; ++e) {
        const __m128i two = _mm_set1_epi64x(2 * stepX[e]);
        col[e][0] = _mm_set_epi64x(stepX[e], 0);
        for (int v = 1; v < 4; ++v) col[e][v] = _mm_add_epi64(col[e][v - 1], two);
      }
      for (int k = 0; k < spp; ++k) {
        const int64_t r0 = row0 + sampleTerm(0, k), r1 = row1 + sampleTerm(1, k),
                      r2 = row2 + sampleTerm(2, k);
        const uint64_t m = (w <= 4 ? smallRows<2>(col, r0, r1, r2, stepY0, stepY1, stepY2, h)
                                   : smallRows<4>(col, r0, r1, r2, stepY0, stepY1, stepY2, h)) &
                           columns;
        smallMasks[k] = m;
        any |= m;
      }
#else
      for (int k = 0; k < spp; ++k) smallMasks[k] = 0;
      for (int j = 0; j < h; ++j) {
        int64_t e0 = row0, e1 = row1, e2 = row2;
        for (int i = 0; i < w; ++i) {
          for (int k = 0; k < spp; ++k) {
            // Every one >= 0: their sign bits all clear.
            const int64_t m = (e0 + sampleTerm(0, k)) | (e1 + sampleTerm(1, k)) | (e2 + sampleTerm(2, k));
            smallMasks[k] |= uint64_t(~m) >> 63 << (8 * j + i);
          }
          e0 += stepX0, e1 += stepX1, e2 += stepX2;
        }
        row0 += stepY0, row1 += stepY1, row2 += stepY2;
      }
      for (int k = 0; k < spp; ++k) any |= smallMasks[k];
      (void)columns;
#endif
      if (any == 0) continue;
      const int bx0 = rect.x0 + (r.x0 - rect.x0) / B * B, by0 = rect.y0 + (r.y0 - rect.y0) / B * B;
      if (bx0 + B > r.x1 && by0 + B > r.y1) {  // one block
        const PixelBlock b{r.x0, r.y0, w, h};
        const size_t hb = bounds.block(r.x0, r.y0);
        if (bounds.culls(hb, [&] { return lowestKeyOver(b); })) continue;
        testMaskedSamples(r.x0, r.y0, smallMasks, hb);
        continue;
      }
      for (int by = by0; by <= r.y1; by += B)
        for (int bx = bx0; bx <= r.x1; bx += B) {
          const int cx0 = std::max(bx, r.x0), cy0 = std::max(by, r.y0);
          const int cw = std::min(bx + B - 1, r.x1) - cx0 + 1, ch = std::min(by + B - 1, r.y1) - cy0 + 1;
          // The bits of the bounds' mask within this block: its columns in
          // each of its rows.
          const uint64_t blockColumns = ((uint64_t(1) << cw) - 1) << (cx0 - r.x0);
          const uint64_t rows = (ch == B ? ~uint64_t(0) : (uint64_t(1) << (8 * ch)) - 1)
                                << (8 * (cy0 - r.y0));
          const uint64_t select = blockColumns * 0x0101010101010101ull & rows;
          if ((any & select) == 0) continue;
          const PixelBlock b{cx0, cy0, cw, ch};
          const size_t hb = bounds.block(bx, by);
          if (bounds.culls(hb, [&] { return lowestKeyOver(b); })) continue;
          uint64_t pieceMasks[kSmallSamples];
          for (int k = 0; k < spp; ++k) pieceMasks[k] = smallMasks[k] & select;
          testMaskedSamples(r.x0, r.y0, pieceMasks, hb);
        }
      continue;
    }
    prepareOffsets(t, grid, scratch);
    uint64_t* masks = scratch.masks.data();
    for (int by = rect.y0 + (r.y0 - rect.y0) / B * B; by <= r.y1; by += B)
      for (int bx = rect.x0 + (r.x0 - rect.x0) / B * B; bx <= r.x1; bx += B) {
        const int cx0 = std::max(bx, r.x0), cy0 = std::max(by, r.y0);
        const PixelBlock b{cx0, cy0, std::min(bx + B - 1, r.x1) - cx0 + 1,
                           std::min(by + B - 1, r.y1) - cy0 + 1};
        int64_t lo[3];
        const BlockClass c = classifyBlock(t, scratch, U, b, lo);
        if (c == BlockClass::Reject) continue;
        const size_t hb = bounds.block(bx, by);
        if (bounds.culls(hb, [&] { return lowestKeyOver(b); })) continue;
        uint32_t written = 0, writtenMax = 0;
        if (c == BlockClass::Accept) {
          counters->samplesTested += uint64_t(b.w) * uint64_t(b.h) * uint64_t(spp);
          if (blockLanes && b.w == B) {
            // Every sample covered, eight pixels wide: the block's keys
            // tested and written in lanes, vector by vector; a vector with a
            // tie comes back here, its entries tested one by one.
            testLanes(b, nullptr, nullptr, written, writtenMax);
          } else {
            // Every sample covered: each block row's keys eight at a time
            // (depth_keys.h: the bits of sampleDepthKey), then tested.
            for (int s = 0; s < spp; ++s) {
              const glm::dvec2& q = grid.positions[size_t(s)];
              double column[8];
              planeColumnTerms(t.depth, b.x, q.x, column);
              for (int py = b.y; py < b.y + b.h; ++py) {
                uint32_t rowKeys[8];
                planeRowKeys(format, column, planeRowTerm(t.depth, py, q.y), rowKeys);
                if (spp == 1 && b.w == 8 && !alphaTest && !keysOnly) {
                  // The row's eight samples are contiguous: compared at once,
                  // unless a key ties its stored one (the id rule decides).
                  const size_t i = target->index(b.x, py, 0);
                  uint32_t passMask = 0;
                  if (rowLess(rowKeys, keys + i, &passMask)) {
                    for (int k = 0; k < 8; ++k) {
                      if (!(passMask >> k & 1u)) continue;
                      keys[i + size_t(k)] = rowKeys[k];
                      winners[i + size_t(k)] = index;
                      writtenMax = std::max(writtenMax, rowKeys[k]);
                    }
                    // Eight bits counted in registers (the build has no
                    // POPCNT: __builtin_popcount is a library call).
                    uint32_t passed = passMask - ((passMask >> 1) & 0x55u);
                    passed = (passed & 0x33u) + ((passed >> 2) & 0x33u);
                    passed = (passed + (passed >> 4)) & 0x0Fu;
                    counters->samplesPassed += passed;
                    written += passed;
                    continue;
                  }
                }
                for (int k = 0; k < b.w; ++k) testKey(b.x + k, py, s, rowKeys[k], written, writtenMax);
              }
            }
          }
          if (written == 0) continue;
          bounds.addWrites(hb, written);
          if (written == uint32_t(b.w * b.h * spp) && bounds.wholeBlock(b))
            bounds.setExact(hb, writtenMax);  // every key of the block is new
          else
            bounds.markStale(hb);
          continue;
        }
        blockMasks(t, scratch, U, spp, b, lo, masks);
        uint32_t covered = 0;
        if (blockLanes && b.w == B && spp <= 8)
          for (int s = 0; s < spp; ++s) covered += uint32_t(bitCount(masks[s]));
        // The lanes where the block's rows hold two covered pixels a row
        // on average (a vector costs about what a sample costs alone).
        if (covered != 0 && covered >= uint32_t(2 * b.h * spp)) {
          // The lanes' entry bits: row j's 8·spp bits, pixel-major (the
          // masks' own layout at 1 spp).
          const uint8_t* cover = reinterpret_cast<const uint8_t*>(masks);
          if (spp > 1) {
            for (int j = 0; j < b.h; ++j) {
              uint64_t row = 0;
              for (int s = 0; s < spp; ++s)
                for (uint64_t m = masks[s] >> (8 * j) & 0xFFu; m; m &= m - 1)
                  row |= uint64_t(1) << (__builtin_ctzll(m) * spp + s);
              for (int k = 0; k < spp; ++k) coverBits[size_t(j * spp + k)] = uint8_t(row >> (8 * k));
            }
            cover = coverBits;
          }
          counters->samplesTested += covered;
          testLanes(b, masks, cover, written, writtenMax);
          if (written != 0) {
            bounds.addWrites(hb, written);
            bounds.markStale(hb);
          }
          continue;
        }
        testMaskedSamples(b.x, b.y, masks, hb);
      }
  }
}

}  // namespace rastray
