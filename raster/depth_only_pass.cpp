#include "raster/depth_only_pass.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <mutex>
#include <string>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
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

// The local buffer holds biased keys, key ^ 2^31 as int32, so that SSE2's
// signed compares order them as the unsigned keys (SSE2 has no unsigned
// compare nor 32-bit max).
constexpr uint32_t kBias = 0x80000000u;
constexpr int32_t kClearBiased = int32_t(kClearDepthKey ^ kBias);

// What a row kernel needs of the triangle and the pass besides the row.
struct RowContext {
  DepthFormat format;
  const AlphaTestFunction& alphaTest;
  const TriangleSetup& t;
  DepthPassCounters* counters;
  // The MASK test of the lanes in `pass` of row py from column px0 (bit i:
  // texel px0 + i); returns the lanes that stay covered.
  uint32_t alpha(uint32_t pass, int px0, int py) const {
    for (uint32_t m = pass; m; m &= m - 1) {
      const int i = __builtin_ctz(m);
      if (!alphaTest(t, px0 + i, py, 0)) {
        pass &= ~(1u << i);
        ++counters->alphaRejected;
      }
    }
    return pass;
  }
};

// The test and write of one block row, the scalar form (rows narrower than
// a block, builds without SSE2): lanes i < width of `row` (biased keys),
// covered lanes `cover`. Returns the lanes written; `rowMax` receives the
// largest biased key the row holds afterwards.
inline uint32_t testRowScalar(const RowContext& ctx, const double (&column)[8], double rowTerm, int32_t* row,
                              int width, uint32_t cover, int px0, int py, int32_t* rowMax) {
  uint32_t keys[8];
  planeRowKeys(ctx.format, column, rowTerm, keys);
  uint32_t pass = 0;
  for (int i = 0; i < width; ++i)
    if (((cover >> i) & 1u) && int32_t(keys[i] ^ kBias) < row[i]) pass |= 1u << i;
  if (pass && ctx.alphaTest) pass = ctx.alpha(pass, px0, py);
  int32_t m = INT32_MIN;
  for (int i = 0; i < width; ++i) {
    if ((pass >> i) & 1u) row[i] = int32_t(keys[i] ^ kBias);
    m = std::max(m, row[i]);
  }
  *rowMax = m;
  return pass;
}

#if defined(__SSE2__)
// Eight texels of a row in two SSE2 registers.
struct Sse2Row {
  using Acc = __m128i;
  static __m128i select(__m128i mask, __m128i a, __m128i b) {
    return _mm_or_si128(_mm_and_si128(mask, a), _mm_andnot_si128(mask, b));
  }
  static void laneMasks(uint32_t bits, __m128i& lo, __m128i& hi) {
    const __m128i v = _mm_set1_epi32(int32_t(bits));
    const __m128i l = _mm_setr_epi32(1, 2, 4, 8), h = _mm_setr_epi32(16, 32, 64, 128);
    lo = _mm_cmpeq_epi32(_mm_and_si128(v, l), l);
    hi = _mm_cmpeq_epi32(_mm_and_si128(v, h), h);
  }
  static __m128i maxI32(__m128i a, __m128i b) { return select(_mm_cmpgt_epi32(a, b), a, b); }

  // A full row of eight texels (testRowScalar's contract); `acc` gathers
  // the largest biased key written or kept.
  uint32_t operator()(const RowContext& ctx, const double (&column)[8], double rowTerm, int32_t* row,
                      uint32_t cover, int px0, int py, __m128i& acc) const {
    __m128i klo, khi;
    if (ctx.format == DepthFormat::FloatReversed || ctx.format == DepthFormat::Float) {
      floatRowKeys(ctx.format == DepthFormat::FloatReversed, column, rowTerm, klo, khi);
    } else {
      alignas(16) uint32_t k[8];
      planeRowKeys(ctx.format, column, rowTerm, k);
      klo = _mm_load_si128(reinterpret_cast<const __m128i*>(k));
      khi = _mm_load_si128(reinterpret_cast<const __m128i*>(k + 4));
    }
    const __m128i bias = _mm_set1_epi32(int32_t(kBias));
    klo = _mm_xor_si128(klo, bias);
    khi = _mm_xor_si128(khi, bias);
    const __m128i slo = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row));
    const __m128i shi = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + 4));
    __m128i plo = _mm_cmplt_epi32(klo, slo), phi = _mm_cmplt_epi32(khi, shi);
    if (cover != 0xFFu) {
      __m128i clo, chi;
      laneMasks(cover, clo, chi);
      plo = _mm_and_si128(plo, clo);
      phi = _mm_and_si128(phi, chi);
    }
    uint32_t pass = uint32_t(_mm_movemask_ps(_mm_castsi128_ps(plo))) |
                    (uint32_t(_mm_movemask_ps(_mm_castsi128_ps(phi))) << 4);
    if (pass && ctx.alphaTest) {
      const uint32_t kept = ctx.alpha(pass, px0, py);
      if (kept != pass) laneMasks(kept, plo, phi);
      pass = kept;
    }
    const __m128i nlo = select(plo, klo, slo), nhi = select(phi, khi, shi);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(row), nlo);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(row + 4), nhi);
    acc = maxI32(acc, maxI32(nlo, nhi));
    return pass;
  }
  static __m128i start() { return _mm_set1_epi32(INT32_MIN); }
  // Gathers the keys of a row the triangle did not draw.
  static void fold(const int32_t* row, __m128i& acc) {
    acc = maxI32(acc, maxI32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(row)),
                             _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + 4))));
  }
  static int32_t reduce(__m128i acc) {
    acc = maxI32(acc, _mm_shuffle_epi32(acc, _MM_SHUFFLE(1, 0, 3, 2)));
    acc = maxI32(acc, _mm_shuffle_epi32(acc, _MM_SHUFFLE(2, 3, 0, 1)));
    return _mm_cvtsi128_si32(acc);
  }
  static int passCount(uint32_t pass) { return bitCount(pass); }
  static constexpr bool kFullBlock = false;
};
#endif

// The same without SSE2: every row through testRowScalar.
struct ScalarRow {
  using Acc = int32_t;
  static constexpr bool kFullBlock = false;
  static Acc start() { return INT32_MIN; }
  static int32_t reduce(Acc acc) { return acc; }
  static void fold(const int32_t* row, Acc& acc) { acc = std::max(acc, *std::max_element(row, row + B)); }
  uint32_t operator()(const RowContext& ctx, const double (&column)[8], double rowTerm, int32_t* row,
                      uint32_t cover, int px0, int py, Acc& acc) const {
    int32_t m;
    const uint32_t pass = testRowScalar(ctx, column, rowTerm, row, B, cover, px0, py, &m);
    acc = std::max(acc, m);
    return pass;
  }
};

#if defined(__x86_64__) && defined(__GNUC__)
#define RASTRAY_DEPTH_ONLY_AVX2 1
// Eight texels in one AVX2 register, chosen at run time: the double
// arithmetic in four-wide vectors with the SSE2 kernel's operations and
// operand order (VMAXPD/VMINPD/VCVTPD2PS behave as their SSE forms), so
// the same bits. target("avx2") enables no FMA, so nothing is contracted.
struct Avx2Row {
  using Acc = __m256i;
  static constexpr bool kFullBlock = true;
  __attribute__((target("avx2"))) static Acc start() { return _mm256_set1_epi32(INT32_MIN); }
  __attribute__((target("avx2"))) static int32_t reduce(Acc acc) {
    __m128i m = _mm_max_epi32(_mm256_castsi256_si128(acc), _mm256_extracti128_si256(acc, 1));
    m = _mm_max_epi32(m, _mm_shuffle_epi32(m, _MM_SHUFFLE(1, 0, 3, 2)));
    m = _mm_max_epi32(m, _mm_shuffle_epi32(m, _MM_SHUFFLE(2, 3, 0, 1)));
    return _mm_cvtsi128_si32(m);
  }
  __attribute__((target("avx2"))) static void fold(const int32_t* row, Acc& acc) {
    acc = _mm256_max_epi32(acc, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(row)));
  }
  __attribute__((target("avx2"))) static __m256i laneMask(uint32_t bits) {
    const __m256i l = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    return _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(int32_t(bits)), l), l);
  }
  __attribute__((target("avx2"))) uint32_t operator()(const RowContext& ctx, const double (&column)[8],
                                                      double rowTerm, int32_t* row, uint32_t cover, int px0,
                                                      int py, Acc& acc) const {
    __m256i k;
    if (ctx.format == DepthFormat::FloatReversed || ctx.format == DepthFormat::Float) {
      const __m256d r = _mm256_set1_pd(rowTerm), zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0);
      const __m256d z0 = _mm256_add_pd(_mm256_loadu_pd(column), r);
      const __m256d z1 = _mm256_add_pd(_mm256_loadu_pd(column + 4), r);
      const __m128 f0 = _mm256_cvtpd_ps(_mm256_min_pd(one, _mm256_max_pd(zero, z0)));
      const __m128 f1 = _mm256_cvtpd_ps(_mm256_min_pd(one, _mm256_max_pd(zero, z1)));
      const __m256i bits = _mm256_castps_si256(_mm256_insertf128_ps(_mm256_castps128_ps256(f0), f1, 1));
      // Biased reversed key: (0x3F800000 − bits) ^ 2^31 = 0xBF800000 − bits (mod 2^32).
      k = ctx.format == DepthFormat::FloatReversed
              ? _mm256_sub_epi32(_mm256_set1_epi32(int32_t(0xBF800000u)), bits)
              : _mm256_xor_si256(bits, _mm256_set1_epi32(int32_t(kBias)));
    } else {
      alignas(32) uint32_t keys[8];
      planeRowKeys(ctx.format, column, rowTerm, keys);
      k = _mm256_xor_si256(_mm256_load_si256(reinterpret_cast<const __m256i*>(keys)),
                           _mm256_set1_epi32(int32_t(kBias)));
    }
    const __m256i stored = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(row));
    __m256i p = _mm256_cmpgt_epi32(stored, k);
    if (cover != 0xFFu) p = _mm256_and_si256(p, laneMask(cover));
    uint32_t pass = uint32_t(_mm256_movemask_ps(_mm256_castsi256_ps(p)));
    if (pass && ctx.alphaTest) {
      const uint32_t kept = ctx.alpha(pass, px0, py);
      if (kept != pass) p = laneMask(kept);
      pass = kept;
    }
    const __m256i n = _mm256_blendv_epi8(stored, k, p);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(row), n);
    acc = _mm256_max_epi32(acc, n);
    return pass;
  }

  // The smallest and largest key of `plane` over the 8×8 block at (bx, by)
  // (samples at offsetX, offsetY within the texels), float formats, from
  // its four corners; false where the corners cannot prove it (a corner's
  // depth not finite or not above 0). Why the corners suffice: a texel's
  // depth is column[i] + rowTerm(j), and every operation of both terms
  // (planeColumnTerms, planeRowTerm, computed here lane by lane with the
  // same operations) and of the sum is a rounded IEEE operation with one
  // varying operand, monotonic in it; so the depth is monotonic along
  // each row and each column and lies between its corners' values: finite
  // and above 0 (no NaN, no −0). The clamp, the conversion to float and
  // the key are monotonic too, so the keys' extremes are the corners'.
  // The same over the n × n texels at (bx, by) (a block, n = 8, or a tile).
  __attribute__((target("avx2"))) static bool keyRange(bool reversed, const Plane& p, int bx, double offsetX,
                                                       int by, double offsetY, uint32_t* lo, uint32_t* hi,
                                                       int n = B) {
    // Lanes: columns bx and bx + n − 1, rows by and by + n − 1.
    const __m256d at = _mm256_setr_pd(double(bx), double(bx + n - 1), double(by), double(by + n - 1));
    const __m256d offset = _mm256_setr_pd(offsetX, offsetX, offsetY, offsetY);
    const __m256d origin = _mm256_setr_pd(p.x0, p.x0, p.y0, p.y0);
    const __m256d slope = _mm256_setr_pd(p.dx, p.dx, p.dy, p.dy);
    const __m256d terms = _mm256_mul_pd(slope, _mm256_sub_pd(_mm256_add_pd(at, offset), origin));
    const __m128d column = _mm_add_pd(_mm_set1_pd(p.v0), _mm256_castpd256_pd128(terms));  // c0, c7
    const __m128d row = _mm256_extractf128_pd(terms, 1);                                  // r0, r7
    // (c0 + r0, c7 + r0, c0 + r7, c7 + r7)
    const __m256d z = _mm256_add_pd(_mm256_set_m128d(column, column),
                                    _mm256_set_m128d(_mm_unpackhi_pd(row, row), _mm_unpacklo_pd(row, row)));
    const __m256d absZ = _mm256_andnot_pd(_mm256_set1_pd(-0.0), z);
    const __m256d ok = _mm256_and_pd(_mm256_cmp_pd(z, _mm256_setzero_pd(), _CMP_GT_OQ),
                                     _mm256_cmp_pd(absZ, _mm256_set1_pd(HUGE_VAL), _CMP_LT_OQ));
    if (_mm256_movemask_pd(ok) != 0xF) return false;
    // depthKey: clamp (z > 0: the upper bound only), float, key.
    const __m128i bits = _mm_castps_si128(_mm256_cvtpd_ps(_mm256_min_pd(_mm256_set1_pd(1.0), z)));
    const __m128i keys = reversed ? _mm_sub_epi32(_mm_set1_epi32(0x3F800000), bits) : bits;
    __m128i mn = _mm_min_epu32(keys, _mm_shuffle_epi32(keys, _MM_SHUFFLE(1, 0, 3, 2)));
    __m128i mx = _mm_max_epu32(keys, _mm_shuffle_epi32(keys, _MM_SHUFFLE(1, 0, 3, 2)));
    mn = _mm_min_epu32(mn, _mm_shuffle_epi32(mn, _MM_SHUFFLE(2, 3, 0, 1)));
    mx = _mm_max_epu32(mx, _mm_shuffle_epi32(mx, _MM_SHUFFLE(2, 3, 0, 1)));
    *lo = uint32_t(_mm_cvtsi128_si32(mn));
    *hi = uint32_t(_mm_cvtsi128_si32(mx));
    return true;
  }

  // A whole 8×8 block the triangle covers, float formats, no alpha test:
  // each row's keys, test and write as operator() computes them (the same
  // column terms, planeRowTerm, clamp, conversion and compare, so the same
  // bits), without the per-row cover masks, bookkeeping and the alpha
  // test's call that made the general loop keep its values on the stack.
  // Returns the texels written; `maxKey` the block's largest biased key.
  __attribute__((target("avx2"))) static uint32_t fullBlock(bool reversed, const double (&column)[8],
                                                            const Plane& plane, int by, double offsetY,
                                                            int32_t* row, int32_t* maxKey) {
    const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0);
    const __m256d c0 = _mm256_loadu_pd(column), c1 = _mm256_loadu_pd(column + 4);
    const __m256i keyBase = _mm256_set1_epi32(int32_t(0xBF800000u)), bias = _mm256_set1_epi32(int32_t(kBias));
    __m256i acc = _mm256_set1_epi32(INT32_MIN);
    uint64_t passes = 0;  // bit 8j + i: texel i of row j written
    for (int j = 0; j < B; ++j, row += kTileSize) {
      const __m256d r = _mm256_set1_pd(planeRowTerm(plane, by + j, offsetY));
      const __m128 f0 = _mm256_cvtpd_ps(_mm256_min_pd(one, _mm256_max_pd(zero, _mm256_add_pd(c0, r))));
      const __m128 f1 = _mm256_cvtpd_ps(_mm256_min_pd(one, _mm256_max_pd(zero, _mm256_add_pd(c1, r))));
      const __m256i bits = _mm256_castps_si256(_mm256_insertf128_ps(_mm256_castps128_ps256(f0), f1, 1));
      const __m256i k = reversed ? _mm256_sub_epi32(keyBase, bits) : _mm256_xor_si256(bits, bias);
      const __m256i stored = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(row));
      const __m256i p = _mm256_cmpgt_epi32(stored, k);
      passes |= uint64_t(uint32_t(_mm256_movemask_ps(_mm256_castsi256_ps(p)))) << (8 * j);
      const __m256i n = _mm256_min_epi32(stored, k);  // k where it passes (k < stored), else stored
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(row), n);
      acc = _mm256_max_epi32(acc, n);
    }
    *maxKey = reduce(acc);
    return uint32_t(bitCount(passes));
  }
};

// Avx2Row with whole covered blocks in AVX-512 (F, VL): a row's eight
// doubles in one vector, converted to eight floats by one VCVTPD2PS (the
// AVX2 form takes two and an insert), the pass mask from a mask compare.
// The same operations per lane in the same operand order (VMAXPD/VMINPD
// return their second operand when unordered or equal at every width;
// the conversion rounds by MXCSR as the others do), so the same bits.
// target() enables FMA with AVX-512F, but -ffp-contract=off (every source)
// keeps the additions and products apart.
// GCC 12's AVX-512 intrinsics pass _mm512_undefined_pd() as the unused
// merge operand, which -Wmaybe-uninitialized reports: a false positive.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
struct Avx512Row : Avx2Row {
  __attribute__((target("avx2,avx512f,avx512vl"))) static uint32_t fullBlock(bool reversed,
                                                                             const double (&column)[8],
                                                                             const Plane& plane, int by,
                                                                             double offsetY, int32_t* row,
                                                                             int32_t* maxKey) {
    const __m512d zero = _mm512_setzero_pd(), one = _mm512_set1_pd(1.0);
    const __m512d c = _mm512_loadu_pd(column);
    const __m256i keyBase = _mm256_set1_epi32(int32_t(0xBF800000u)), bias = _mm256_set1_epi32(int32_t(kBias));
    __m256i acc = _mm256_set1_epi32(INT32_MIN);
    uint64_t passes = 0;  // bit 8j + i: texel i of row j written
    for (int j = 0; j < B; ++j, row += kTileSize) {
      const __m512d r = _mm512_set1_pd(planeRowTerm(plane, by + j, offsetY));
      const __m256i bits =
          _mm256_castps_si256(_mm512_cvtpd_ps(_mm512_min_pd(one, _mm512_max_pd(zero, _mm512_add_pd(c, r)))));
      const __m256i k = reversed ? _mm256_sub_epi32(keyBase, bits) : _mm256_xor_si256(bits, bias);
      const __m256i stored = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(row));
      passes |= uint64_t(_mm256_cmpgt_epi32_mask(stored, k)) << (8 * j);
      const __m256i n = _mm256_min_epi32(stored, k);
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(row), n);
      acc = _mm256_max_epi32(acc, n);
    }
    *maxKey = reduce(acc);
    return uint32_t(bitCount(passes));
  }
};
#pragma GCC diagnostic pop
#endif

// Computes block hb's keys into the buffer `keys` (rows of kTileSize) from
// its state: the clear key, or its plane's keys at the samples (the bits
// of the kernels' keys: planeRowKeys).
__attribute__((always_inline)) inline void loadBlock(int32_t* keys, const TileRect& rect, int columns,
                                                     DepthOnlyTile::Blocks& state, size_t hb,
                                                     const std::vector<TriangleSetup>& setups,
                                                     DepthFormat format, const glm::dvec2& pos) {
  const int bx = int(hb % size_t(columns)) * B, by = int(hb / size_t(columns)) * B;
  const int rows = std::min(B, rect.y1 - rect.y0 - by);
  int32_t* row = keys + size_t(by) * kTileSize + size_t(bx);
  const uint32_t owner = state.owner[hb];
  if (owner == kBlockClear) {
    for (int j = 0; j < rows; ++j, row += kTileSize) std::fill_n(row, B, kClearBiased);
  } else {
    const Plane& plane = setups[owner].depth;
    double column[8];
    planeColumnTerms(plane, rect.x0 + bx, pos.x, column);
    for (int j = 0; j < rows; ++j, row += kTileSize) {
      uint32_t k[8];
      planeRowKeys(format, column, planeRowTerm(plane, rect.y0 + by + j, pos.y), k);
      for (int i = 0; i < B; ++i) row[i] = int32_t(k[i] ^ kBias);
    }
  }
  state.inBuffer |= uint64_t(1) << hb;
}

// drawFast<Avx2Row> passes AVX vectors between functions compiled without
// AVX, which GCC warns changes the ABI; it is always inlined into drawAvx2
// (AVX2), so no such call exists.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
// The fast walk of the bin over the tile's buffer `keys` (biased, rows of
// kTileSize), rows of full blocks through `kernel`. Inlined into each
// kernel's entry point, so that its ISA covers the whole loop.
template <typename Row>
__attribute__((always_inline)) inline void drawFast(int32_t* keys, DepthOnlyTile::Blocks& state,
                                                    const TileRect& rect,
                                                    const std::vector<TriangleSetup>& setups,
                                                    const std::vector<uint32_t>& bin, const SampleGrid& grid,
                                                    DepthFormat format, const AlphaTestFunction& alphaTest,
                                                    DepthPassCounters* counters, const Row& kernel) {
  const int width = rect.x1 - rect.x0, height = rect.y1 - rect.y0;
  const int columns = (width + B - 1) / B;
  const size_t blocks = size_t(columns) * size_t((height + B - 1) / B);
  // Per block of the rect: the largest key stored (unbiased), exact: the
  // kernels write whole rows, so they see every key of the rows they draw,
  // and the block's other rows are read back (from the cache-resident
  // buffer) after each triangle that draws some.
  uint32_t blockMax[(kTileSize / B) * (kTileSize / B)];
  std::fill_n(blockMax, blocks, kClearDepthKey);
  const glm::dvec2 pos = grid.positions[0];
  const int64_t U = grid.unitsPerPixel;
  CoverageScratch scratch;
  uint64_t mask = 0;
  uint64_t tested = 0, passed = 0;

  // Blocks taken as a plane with a whole tile, whose key range (blockMax,
  // minKey) is computed when a later triangle first meets the block.
  uint64_t rangeUnknown = 0;
  const bool wholeTiles = Row::kFullBlock && !alphaTest && rect.x1 - rect.x0 == kTileSize &&
                          rect.y1 - rect.y0 == kTileSize &&
                          (format == DepthFormat::FloatReversed || format == DepthFormat::Float);

  for (uint32_t index : bin) {
    const TriangleSetup& t = setups[index];
    const PixelBounds r = boundsIn(t, rect);
    if (r.empty()) continue;
    counters->coverageTests += r.samples(1);
    prepareOffsets(t, grid, scratch);
    if constexpr (Row::kFullBlock) {
      // The first triangle drawn covering the whole tile, nearer than the
      // clear key everywhere: every block becomes its plane at once (what
      // the blocks' claims below would do one by one, counters included).
      if (wholeTiles && state.inBuffer == 0 && rangeUnknown == 0 &&
          std::all_of(state.owner, state.owner + kTileBlocks, [](uint32_t o) { return o == kBlockClear; })) {
        int64_t lo[3];
        uint32_t low, high;
        if (classifyBlock(t, scratch, U, PixelBlock{rect.x0, rect.y0, kTileSize, kTileSize}, lo) ==
                BlockClass::Accept &&
            Row::keyRange(format == DepthFormat::FloatReversed, t.depth, rect.x0, pos.x, rect.y0, pos.y, &low,
                          &high, kTileSize) &&
            high < kClearDepthKey) {
          std::fill_n(state.owner, kTileBlocks, index);
          rangeUnknown = ~uint64_t(0);
          tested += uint64_t(kTileSize) * kTileSize;
          passed += uint64_t(kTileSize) * kTileSize;
          continue;
        }
      }
    }
    const uint32_t triangleKey = minKeyOverTriangle(t, format, U);
    const RowContext ctx{format, alphaTest, t, counters};
    for (int by = rect.y0 + (r.y0 - rect.y0) / B * B; by <= r.y1; by += B)
      for (int bx = rect.x0 + (r.x0 - rect.x0) / B * B; bx <= r.x1; bx += B) {
        const int cx0 = std::max(bx, r.x0), cy0 = std::max(by, r.y0);
        const PixelBlock b{cx0, cy0, std::min(bx + B - 1, r.x1) - cx0 + 1,
                           std::min(by + B - 1, r.y1) - cy0 + 1};
        int64_t lo[3];
        const BlockClass c = classifyBlock(t, scratch, U, b, lo);
        if (c == BlockClass::Reject) continue;
        const size_t hb = size_t((by - rect.y0) / B) * size_t(columns) + size_t((bx - rect.x0) / B);
        if constexpr (Row::kFullBlock) {
          if ((rangeUnknown >> hb) & 1u) {
            // The tile's range proved the block's corners finite and above 0.
            uint32_t low = 0, high = 0;
            const bool known =
                Row::keyRange(format == DepthFormat::FloatReversed, setups[state.owner[hb]].depth, bx, pos.x,
                              by, pos.y, &low, &high);
            RASTRAY_CHECK(known, "a block of a tile's plane has its key range");
            state.minKey[hb] = low;
            blockMax[hb] = high;
            rangeUnknown &= ~(uint64_t(1) << hb);
          }
        }
        // Hierarchical test: behind every stored key of the block.
        if (blockMax[hb] != kClearDepthKey &&
            std::max(triangleKey, minKeyOverBlock(t, format, b, pos, pos)) > blockMax[hb])
          continue;
        const uint64_t bit = uint64_t(1) << hb;
        if constexpr (Row::kFullBlock) {
          if (c == BlockClass::Accept && b.x == bx && b.y == by && b.w == B && b.h == B && !alphaTest &&
              (format == DepthFormat::FloatReversed || format == DepthFormat::Float)) {
            tested += uint64_t(B * B);
            if (!(state.inBuffer & bit)) {
              // Clear or another plane, not in the buffer: t takes the
              // block as its plane when its largest key is below the
              // block's smallest (every texel passes and holds t's key).
              uint32_t low, high;
              if (Row::keyRange(format == DepthFormat::FloatReversed, t.depth, bx, pos.x, by, pos.y, &low,
                                &high) &&
                  high < (state.owner[hb] == kBlockClear ? kClearDepthKey : state.minKey[hb])) {
                state.owner[hb] = index;
                state.minKey[hb] = low;
                blockMax[hb] = high;
                passed += uint64_t(B * B);
                continue;
              }
              loadBlock(keys, rect, columns, state, hb, setups, format, pos);
            }
            double column[8];
            planeColumnTerms(t.depth, bx, pos.x, column);
            int32_t* row = keys + size_t(by - rect.y0) * kTileSize + size_t(bx - rect.x0);
            int32_t m;
            const uint32_t n =
                Row::fullBlock(format == DepthFormat::FloatReversed, column, t.depth, by, pos.y, row, &m);
            passed += n;
            blockMax[hb] = uint32_t(m) ^ kBias;
            // Every texel written: the block is t's plane (its keys also in the buffer).
            if (n == uint32_t(B * B))
              state.owner[hb] = index;
            else if (n != 0)
              state.owner[hb] = kBlockKeys;
            continue;
          }
        }
        if (!(state.inBuffer & bit)) loadBlock(keys, rect, columns, state, hb, setups, format, pos);
        if (c == BlockClass::Accept)
          mask = fullBlockMask(b);
        else
          blockMasks(t, scratch, U, 1, b, lo, &mask);
        if (mask == 0) continue;
        tested += uint64_t(bitCount(mask));
        // The block of the rect: bw × bh texels at (bx, by); t's block b
        // starts shiftX columns and j0 rows into it.
        const int bw = std::min(B, rect.x1 - bx), bh = std::min(B, rect.y1 - by);
        const int shiftX = b.x - bx, j0 = b.y - by;
        double column[8];
        planeColumnTerms(t.depth, bx, pos.x, column);
        typename Row::Acc acc = Row::start();
        int32_t narrowMax = INT32_MIN;
        uint32_t drawnRows = 0;  // a row with no covered texel is left as it is
        uint64_t passes = 0;     // bit 8j + i: texel i of row j written
        for (int j = j0; j < j0 + b.h; ++j) {
          const uint32_t cover = uint32_t((mask >> (8 * (j - j0))) & 0xFFu) << shiftX;
          if (cover == 0) continue;
          drawnRows |= 1u << j;
          int32_t* row = keys + size_t(by + j - rect.y0) * kTileSize + size_t(bx - rect.x0);
          const double rowTerm = planeRowTerm(t.depth, by + j, pos.y);
          uint32_t pass;
          if (bw == B) {
            pass = kernel(ctx, column, rowTerm, row, cover, bx, by + j, acc);
          } else {
            int32_t m;
            pass = testRowScalar(ctx, column, rowTerm, row, bw, cover, bx, by + j, &m);
            narrowMax = std::max(narrowMax, m);
          }
          passes |= uint64_t(pass) << (8 * j);
        }
        passed += uint64_t(bitCount(passes));
        if (passes != 0) state.owner[hb] = kBlockKeys;
        // The block's exact largest key: the rows not drawn as well.
        for (int j = 0; j < bh; ++j) {
          if ((drawnRows >> j) & 1u) continue;
          const int32_t* row = keys + size_t(by + j - rect.y0) * kTileSize + size_t(bx - rect.x0);
          if (bw == B)
            Row::fold(row, acc);
          else
            narrowMax = std::max(narrowMax, *std::max_element(row, row + bw));
        }
        blockMax[hb] = uint32_t(std::max(Row::reduce(acc), narrowMax)) ^ kBias;
      }
  }
  counters->samplesTested += tested;
  counters->samplesPassed += passed;
}

#pragma GCC diagnostic pop

#if defined(__SSE2__)
void drawSse2(int32_t* keys, DepthOnlyTile::Blocks& state, const TileRect& rect,
              const std::vector<TriangleSetup>& setups, const std::vector<uint32_t>& bin,
              const SampleGrid& grid, DepthFormat format, const AlphaTestFunction& alphaTest,
              DepthPassCounters* counters) {
  drawFast(keys, state, rect, setups, bin, grid, format, alphaTest, counters, Sse2Row{});
}
#endif

#if defined(RASTRAY_DEPTH_ONLY_AVX2)
__attribute__((target("avx2"))) void drawAvx2(int32_t* keys, DepthOnlyTile::Blocks& state,
                                              const TileRect& rect, const std::vector<TriangleSetup>& setups,
                                              const std::vector<uint32_t>& bin, const SampleGrid& grid,
                                              DepthFormat format, const AlphaTestFunction& alphaTest,
                                              DepthPassCounters* counters) {
  drawFast(keys, state, rect, setups, bin, grid, format, alphaTest, counters, Avx2Row{});
}

bool hasAvx2() {
  static const bool yes = __builtin_cpu_supports("avx2");
  return yes;
}

__attribute__((target("avx2,avx512f,avx512vl"))) void drawAvx512(
    int32_t* keys, DepthOnlyTile::Blocks& state, const TileRect& rect,
    const std::vector<TriangleSetup>& setups, const std::vector<uint32_t>& bin, const SampleGrid& grid,
    DepthFormat format, const AlphaTestFunction& alphaTest, DepthPassCounters* counters) {
  drawFast(keys, state, rect, setups, bin, grid, format, alphaTest, counters, Avx512Row{});
}

bool hasAvx512() {
  static const bool yes = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("avx512f") &&
                          __builtin_cpu_supports("avx512vl");
  return yes;
}

// Streams src[i] ^ kBias into dst for the leading multiple of 8 of
// `width` (dst 32-byte aligned); returns how many were written.
__attribute__((target("avx2"))) int streamRowAvx2(uint32_t* dst, const int32_t* src, int width) {
  const __m256i bias = _mm256_set1_epi32(int32_t(kBias));
  int i = 0;
  for (; i + 8 <= width; i += 8)
    _mm256_stream_si256(reinterpret_cast<__m256i*>(dst + i),
                        _mm256_xor_si256(_mm256_load_si256(reinterpret_cast<const __m256i*>(src + i)), bias));
  return i;
}
#endif

}  // namespace

namespace {

// Kept buffers: (bytes allocated, pointer). Leaked on purpose, so that maps
// freed during static destruction still find it.
struct DepthMapPool {
  std::mutex mutex;
  std::vector<std::pair<size_t, void*>> kept;
};
DepthMapPool& depthMapPool() {
  static DepthMapPool* pool = new DepthMapPool;
  return *pool;
}

}  // namespace

void DepthMapRelease::operator()(uint32_t* keys) const {
  if (!keys) return;
  DepthMapPool& pool = depthMapPool();
  const std::lock_guard<std::mutex> lock(pool.mutex);
  pool.kept.emplace_back(bytes, keys);
}

size_t depthMapPoolBytes() {
  DepthMapPool& pool = depthMapPool();
  const std::lock_guard<std::mutex> lock(pool.mutex);
  size_t total = 0;
  for (const auto& k : pool.kept) total += k.first;
  return total;
}

DepthMap::DepthMap(int w, int h) : width(w), height(h) {
  // Whole 2 MB pages (the huge-page size) and at least cache-line aligned.
  constexpr size_t kPage = size_t(2) << 20;
  const size_t bytes = std::max<size_t>(size_t(w) * size_t(h) * sizeof(uint32_t), 1);
  const size_t align = bytes >= kPage ? kPage : 64;
  const size_t allocated = (bytes + align - 1) / align * align;
  {
    DepthMapPool& pool = depthMapPool();
    const std::lock_guard<std::mutex> lock(pool.mutex);
    for (size_t i = 0; i < pool.kept.size(); ++i)
      if (pool.kept[i].first == allocated) {
        keys = std::unique_ptr<uint32_t[], DepthMapRelease>(static_cast<uint32_t*>(pool.kept[i].second),
                                                            DepthMapRelease{allocated});
        pool.kept[i] = pool.kept.back();
        pool.kept.pop_back();
        return;
      }
    for (const auto& k : pool.kept) std::free(k.second);  // another size: give the memory back first
    pool.kept.clear();
  }
  void* p = std::aligned_alloc(align, allocated);
  if (!p) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  if (align == kPage) madvise(p, allocated, MADV_HUGEPAGE);  // advice only
#endif
  keys = std::unique_ptr<uint32_t[], DepthMapRelease>(static_cast<uint32_t*>(p), DepthMapRelease{allocated});
}

BlockDepthMap::BlockDepthMap(int w, int h, DepthFormat f, const glm::dvec2& samplePosition)
    : width(w),
      height(h),
      blocksX((w + B - 1) / B),
      format(f),
      sample(samplePosition),
      keys(blocksX * B, (h + B - 1) / B * B),
      owner(size_t(blocksX) * size_t((h + B - 1) / B), kBlockClear) {}

void BlockDepthMap::keepPlanes(const std::vector<TriangleSetup>& setups) {
  std::vector<uint32_t> renumbered(setups.size(), kBlockClear);
  planes.clear();
  for (uint32_t& o : owner) {
    if (!isPlane(o)) continue;
    if (renumbered[o] == kBlockClear) {
      renumbered[o] = uint32_t(planes.size());
      planes.push_back(setups[o].depth);
    }
    o = renumbered[o];
  }
}

DepthOnlyTile::DepthOnlyTile(const TileRect& rect) : rect_(rect), columns_((rect.x1 - rect.x0 + B - 1) / B) {
  RASTRAY_CHECK(rect.x1 - rect.x0 <= kTileSize && rect.y1 - rect.y0 <= kTileSize && rect.x0 <= rect.x1 &&
                    rect.y0 <= rect.y1,
                "a depth-only tile is at most " + std::to_string(kTileSize) + " texels square");
  std::fill_n(blocks_.owner, kTileBlocks, kBlockClear);
}

void DepthOnlyTile::render(const std::vector<TriangleSetup>& setups, const std::vector<uint32_t>& bin,
                           const SampleGrid& grid, DepthFormat format, const AlphaTestFunction& alphaTest,
                           DepthPassCounters* counters, CoveragePath path, SimdLevel simd) {
  RASTRAY_CHECK(grid.spp == 1,
                "the depth-only pass takes 1 sample per texel, not " + std::to_string(grid.spp));
  const TileRect& rect = rect_;
  setups_ = &setups;
  format_ = format;
  sample_ = grid.positions[0];
  // Every block starts clear, its keys not in the buffer: the buffer is
  // cleared block by block when a triangle first draws part of a block.
  std::fill_n(blocks_.owner, kTileBlocks, kBlockClear);
  blocks_.inBuffer = 0;
  if (path == CoveragePath::Reference) {
    // The whole buffer cleared, every block held as keys.
    const int height = rect.y1 - rect.y0;
    std::fill_n(keys_, size_t(height) * kTileSize, kClearBiased);
    const int blocks = columns_ * ((height + B - 1) / B);
    std::fill_n(blocks_.owner, blocks, kBlockKeys);
    blocks_.inBuffer = blocks == 64 ? ~uint64_t(0) : (uint64_t(1) << blocks) - 1;
    CoverageScratch scratch;
    for (uint32_t index : bin) {
      const TriangleSetup& t = setups[index];
      counters->coverageTests +=
          forEachCoveredSampleReference(t, grid, rect, scratch, [&](int px, int py, int s) {
            ++counters->samplesTested;
            int32_t& stored = keys_[size_t(py - rect.y0) * kTileSize + size_t(px - rect.x0)];
            const uint32_t key = sampleDepthKey(t, grid, format, px, py, s);
            if (!(key < (uint32_t(stored) ^ kBias))) return;  // keys only: a tie keeps the stored key
            if (alphaTest && !alphaTest(t, px, py, s)) {
              ++counters->alphaRejected;
              return;
            }
            ++counters->samplesPassed;
            stored = int32_t(key ^ kBias);
          });
    }
    return;
  }
#if defined(RASTRAY_DEPTH_ONLY_AVX2)
  if (simd == SimdLevel::Best && hasAvx512()) {
    drawAvx512(keys_, blocks_, rect, setups, bin, grid, format, alphaTest, counters);
    return;
  }
  if (simd != SimdLevel::Baseline && hasAvx2()) {
    drawAvx2(keys_, blocks_, rect, setups, bin, grid, format, alphaTest, counters);
    return;
  }
#endif
  (void)simd;
#if defined(__SSE2__)
  drawSse2(keys_, blocks_, rect, setups, bin, grid, format, alphaTest, counters);
#else
  drawFast(keys_, blocks_, rect, setups, bin, grid, format, alphaTest, counters, ScalarRow{});
#endif
}

void DepthOnlyTile::loadAll() {
  const int blocks = columns_ * ((rect_.y1 - rect_.y0 + B - 1) / B);
  for (int hb = 0; hb < blocks; ++hb)
    if (!((blocks_.inBuffer >> hb) & 1u))
      loadBlock(keys_, rect_, columns_, blocks_, size_t(hb), *setups_, format_, sample_);
}

int DepthOnlyTile::planeBlocks() const {
  const int blocks = columns_ * ((rect_.y1 - rect_.y0 + B - 1) / B);
  int n = 0;
  for (int hb = 0; hb < blocks; ++hb)
    n += blocks_.owner[hb] != kBlockClear && blocks_.owner[hb] != kBlockKeys;
  return n;
}

void DepthOnlyTile::store(DepthMap* map) const {
  // Every block's keys: a copy of the tile with the missing blocks loaded.
  DepthOnlyTile full = *this;
  if (setups_)
    full.loadAll();
  else {
    const int height = rect_.y1 - rect_.y0;
    std::fill_n(full.keys_, size_t(height) * kTileSize, kClearBiased);
  }
  const int width = rect_.x1 - rect_.x0;
  for (int y = rect_.y0; y < rect_.y1; ++y) {
    const int32_t* src = &full.keys_[size_t(y - rect_.y0) * kTileSize];
    uint32_t* dst = &map->keys[map->index(rect_.x0, y)];
    int i = 0;
#if defined(__SSE2__)
    // Streaming stores need 16-byte aligned destinations: the maps' rows
    // are whenever the width is a multiple of 4 (tiles start at multiples
    // of 64 texels).
    const __m128i bias = _mm_set1_epi32(int32_t(kBias));
#if defined(RASTRAY_DEPTH_ONLY_AVX2)
    if ((reinterpret_cast<uintptr_t>(dst) & 31) == 0 && hasAvx2()) i = streamRowAvx2(dst, src, width);
#endif
    if ((reinterpret_cast<uintptr_t>(dst) & 15) == 0)
      for (; i + 4 <= width; i += 4)
        _mm_stream_si128(reinterpret_cast<__m128i*>(dst + i),
                         _mm_xor_si128(_mm_load_si128(reinterpret_cast<const __m128i*>(src + i)), bias));
#endif
    for (; i < width; ++i) dst[i] = uint32_t(src[i]) ^ kBias;
  }
#if defined(__SSE2__)
  _mm_sfence();  // streaming stores are weakly ordered: publish them before the task completes
#endif
}

void DepthOnlyTile::store(BlockDepthMap* map) const {
  const int height = rect_.y1 - rect_.y0;
  const int rowsOfBlocks = (height + B - 1) / B;
  const int blocks = columns_ * rowsOfBlocks;
  int withKeys = 0;
  for (int hb = 0; hb < blocks; ++hb) withKeys += blocks_.owner[hb] == kBlockKeys;
  uint32_t slot = withKeys ? __atomic_fetch_add(&map->slotsUsed, uint32_t(withKeys), __ATOMIC_RELAXED) : 0;
  const size_t first = size_t(rect_.y0 / B) * size_t(map->blocksX) + size_t(rect_.x0 / B);
  for (int j = 0; j < rowsOfBlocks; ++j)
    for (int i = 0; i < columns_; ++i) {
      const size_t hb = size_t(j) * size_t(columns_) + size_t(i);
      uint32_t& owner = map->owner[first + size_t(j) * size_t(map->blocksX) + size_t(i)];
      owner = blocks_.owner[hb];
      if (owner != kBlockKeys) continue;
      owner = kBlockSlot | slot;
      // The block's 64 keys in 256 contiguous bytes: whole cache lines,
      // streamed where the build allows (lanes and rows beyond the rect are
      // never read).
      uint32_t* dst = &map->keys.keys[size_t(slot) * 64];
      const int32_t* src = &keys_[size_t(j * B) * kTileSize + size_t(i * B)];
      const int bh = std::min(B, height - j * B);
      for (int y = 0; y < B; ++y, dst += B) {
        const int32_t* row = src + size_t(std::min(y, bh - 1)) * kTileSize;  // rows below the rect: any
#if defined(__SSE2__)
        const __m128i bias = _mm_set1_epi32(int32_t(kBias));
        _mm_stream_si128(reinterpret_cast<__m128i*>(dst),
                         _mm_xor_si128(_mm_load_si128(reinterpret_cast<const __m128i*>(row)), bias));
        _mm_stream_si128(reinterpret_cast<__m128i*>(dst + 4),
                         _mm_xor_si128(_mm_load_si128(reinterpret_cast<const __m128i*>(row + 4)), bias));
#else
        for (int x = 0; x < B; ++x) dst[x] = uint32_t(row[x]) ^ kBias;
#endif
      }
      ++slot;
    }
#if defined(__SSE2__)
  _mm_sfence();  // streaming stores are weakly ordered: publish them before the task completes
#endif
}

void rasterDepthOnlyPass(const std::vector<TriangleSetup>& setups, const std::vector<uint32_t>& bin,
                         const SampleGrid& grid, const TileRect& rect, DepthFormat format,
                         const AlphaTestFunction& alphaTest, DepthMap* map, DepthPassCounters* counters,
                         CoveragePath path, SimdLevel simd) {
  DepthOnlyTile tile(rect);
  tile.render(setups, bin, grid, format, alphaTest, counters, path, simd);
  tile.store(map);
}

}  // namespace rastray
