// The fast coverage walk and depth pass (block classification, int32/SSE2
// masks, hierarchical depth) against the scalar reference, on seeded
// random scenes built to hit the corner cases: tiny, sliver, huge (the
// int64 fallback), off-screen triangles, vertices on sample positions,
// shared edges (fill-rule ties) and coplanar duplicates (depth-key ties).
#include <gtest/gtest.h>

#include <hwy/targets.h>
#include <random>
#include <tuple>

#include "raster/bin.h"
#include "raster/coverage.h"
#include "raster/setup.h"
#include "raster_test_util.h"

#include "tests/test_labels.h"

// Tests here render on 2 or more threads (the ThreadSanitizer stage runs them), except those marked quick.
RASTRAY_TEST_LABELS("threads");

namespace rastray {
namespace {

constexpr int kSize = 150;  // not a multiple of the tile or block size

// Image position (x, y) → world for orthoCamera(kSize, kSize / 2): one
// world unit per pixel, so a 1/16-pixel grid is exact in float.
glm::vec3 world(double x, double y, double z) {
  return glm::vec3(float(x - kSize / 2.0), float(kSize / 2.0 - y), float(z));
}

// A random scene of `count` triangles of mixed kinds.
// Two triangles per cell of a cells × cells grid whose (cells + 1)²
// vertices are numbered row by row.
std::vector<glm::uvec3> gridTriangles(int cells) {
  std::vector<glm::uvec3> t;
  for (int y = 0; y < cells; ++y)
    for (int x = 0; x < cells; ++x) {
      const uint32_t a = uint32_t(y * (cells + 1) + x);
      t.push_back({a, a + 1, a + uint32_t(cells) + 2});
      t.push_back({a, a + uint32_t(cells) + 2, a + uint32_t(cells) + 1});
    }
  return t;
}

Scene randomScene(uint32_t seed, int count) {
  std::mt19937 rng(seed);
  const auto uniform = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  // On the 1/16-pixel grid: the 4 and 16 spp patterns' sample positions lie on it.
  const auto snap = [](double v) { return std::round(v * 16.0) / 16.0; };
  const auto depth = [&]() { return -uniform(1.0, 9.0); };
  Scene scene;
  for (int i = 0; i < count; ++i) {
    const int kind = int(rng() % 7);
    std::vector<glm::vec3> p;
    std::vector<glm::uvec3> t = {{0, 1, 2}};
    const double cx = snap(uniform(-20.0, kSize + 20.0)), cy = snap(uniform(-20.0, kSize + 20.0));
    switch (kind) {
      case 0:  // tiny
        for (int k = 0; k < 3; ++k)
          p.push_back(world(cx + snap(uniform(-2, 2)), cy + snap(uniform(-2, 2)), depth()));
        break;
      case 1: {  // sliver: the third vertex 1/16 px off the long edge
        const double ex = snap(uniform(-kSize, kSize)), ey = snap(uniform(-kSize, kSize));
        p = {world(cx, cy, depth()), world(cx + ex, cy + ey, depth()),
             world(cx + ex / 2 + 1.0 / 16, cy + ey / 2, depth())};
        break;
      }
      case 2:  // huge: far beyond the image (large edge coefficients)
        for (int k = 0; k < 3; ++k)
          p.push_back(world(snap(uniform(-6000, 6000)), snap(uniform(-6000, 6000)), depth()));
        break;
      case 3:  // off-screen
        for (int k = 0; k < 3; ++k)
          p.push_back(world(kSize + 50 + uniform(0, 30), uniform(0, kSize), depth()));
        break;
      case 4: {  // a fan of shared edges around a centre on a pixel-centre position
        const double r = uniform(3, 40);
        const double z = depth();
        p.push_back(world(std::floor(cx) + 0.5, std::floor(cy) + 0.5, z));
        const int n = 3 + int(rng() % 6);
        for (int k = 0; k <= n; ++k) {
          const double a = 2.0 * kPi * k / n;
          p.push_back(world(std::floor(cx + r * std::cos(a)) + 0.5, std::floor(cy + r * std::sin(a)) + 0.5,
                            z + uniform(-0.5, 0.5)));
        }
        t.clear();
        for (int k = 1; k <= n; ++k) t.push_back({0u, uint32_t(k), uint32_t(k + 1)});
        break;
      }
      case 5: {  // a quad split along its diagonal, both halves in one plane, and a coplanar copy
        const double w = snap(uniform(1, 60)), h = snap(uniform(1, 60));
        const double z0 = depth(), z1 = depth();
        p = {world(cx, cy, z0), world(cx + w, cy, z0), world(cx + w, cy + h, z1), world(cx, cy + h, z1)};
        t = {{0, 1, 2}, {0, 2, 3}};
        test::addMesh(scene, p, t);  // the copy: exact key ties, decided by id
        break;
      }
      default:  // medium
        for (int k = 0; k < 3; ++k)
          p.push_back(world(cx + snap(uniform(-40, 40)), cy + snap(uniform(-40, 40)), depth()));
        break;
    }
    test::addMesh(scene, p, t);
  }
  return scene;
}

std::vector<TriangleSetup> setupScene(const Scene& scene, const Camera& camera, const SampleGrid& grid,
                                      DepthFormat format) {
  const ClipSpace space = makeClipSpace(camera, grid.guardPixels);
  const DepthSettings ds{format, camera.projection, camera.znear, camera.zfar, 0, 0};
  SetupCounters n;
  return prepareTriangles(scene, space, grid, ds, CullMode::None, {}, &n);
}

using Sample = std::tuple<int, int, int>;

RASTRAY_TEST_LABELS_OF(CoverageEquivalence, BlockWalkVisitsTheReferenceSamplesInOrder, "slow");
TEST(CoverageEquivalence, BlockWalkVisitsTheReferenceSamplesInOrder) {
  const Camera camera = test::orthoCamera(kSize, kSize / 2.0, 0.0, 10.0);
  for (uint32_t seed = 1; seed <= 6; ++seed) {
    const Scene scene = randomScene(seed, 120);
    for (int spp : {1, 4, 16, 25}) {
      const SampleGrid grid = makeSampleGrid(spp, kSize, kSize);
      const auto setups = setupScene(scene, camera, grid, DepthFormat::FloatReversed);
      ASSERT_GT(setups.size(), 60u);
      std::mt19937 rng(seed * 100 + uint32_t(spp));
      std::vector<TileRect> rects = {TileRect{0, 0, kSize, kSize}, TileRect{64, 64, 128, 128},
                                     TileRect{128, 128, kSize, kSize}};
      for (int k = 0; k < 3; ++k) {  // unaligned rects
        const int x0 = int(rng() % kSize), y0 = int(rng() % kSize);
        rects.push_back(TileRect{x0, y0, x0 + 1 + int(rng() % uint32_t(kSize - x0)),
                                 y0 + 1 + int(rng() % uint32_t(kSize - y0))});
      }
      CoverageScratch scratch;
      for (const TriangleSetup& t : setups)
        for (const TileRect& r : rects) {
          std::vector<Sample> fast, slow;
          const uint64_t nf = forEachCoveredSample(t, grid, r, scratch,
                                                   [&](int x, int y, int s) { fast.emplace_back(x, y, s); });
          const uint64_t ns = forEachCoveredSampleReference(
              t, grid, r, scratch, [&](int x, int y, int s) { slow.emplace_back(x, y, s); });
          ASSERT_EQ(nf, ns);
          ASSERT_EQ(fast, slow) << "seed " << seed << " spp " << spp << " triangle " << t.instance << "/"
                                << t.triangle << " rect " << r.x0 << "," << r.y0 << "-" << r.x1 << ","
                                << r.y1;
        }
    }
  }
}

struct PassResult {
  DepthTarget target;
  DepthPassCounters counters;
};

// Two depth passes over every tile (the first half of the setups, then the
// rest, so the second starts from a filled target), with a MASK-like
// alpha test that drops a hashed subset of the samples of odd instances
// (unless `mask` is false).
PassResult depthPass(const std::vector<TriangleSetup>& setups, const SampleGrid& grid, DepthFormat format,
                     DepthFunc func, bool keysOnly, CoveragePath path, bool mask = true) {
  PassResult r{DepthTarget(kSize, kSize, grid.spp, keysOnly), {}};
  std::function<bool(const TriangleSetup&, int, int, int)> alpha;
  if (mask)
    alpha = [](const TriangleSetup& t, int x, int y, int s) {
      return t.instance % 2 == 0 ||
             ((uint32_t(x) * 73856093u) ^ (uint32_t(y) * 19349663u) ^ uint32_t(s) ^ t.triangle) % 5 != 0;
    };
  const TileGrid tiles(kSize, kSize);
  const size_t half = setups.size() / 2;
  for (const auto& [from, to] : {std::pair<size_t, size_t>{0, half}, {half, setups.size()}}) {
    std::vector<uint32_t> bin;
    for (size_t i = from; i < to; ++i) bin.push_back(uint32_t(i));
    for (int tile = 0; tile < tiles.count(); ++tile)
      rasterDepthPass(setups, bin, grid, tiles.rect(tile), format, func, alpha, TraceRequest{}, &r.target,
                      &r.counters, path);
  }
  return r;
}

// The fast walk's target and counters are the reference walk's; the
// hierarchical depth test only skips samples that would fail.
void expectSamePass(const PassResult& fast, const PassResult& slow, const std::string& what) {
  ASSERT_EQ(fast.target.keys, slow.target.keys) << what;
  ASSERT_EQ(fast.target.winners, slow.target.winners) << what;
  EXPECT_EQ(fast.counters.coverageTests, slow.counters.coverageTests) << what;
  EXPECT_EQ(fast.counters.samplesPassed, slow.counters.samplesPassed) << what;
  EXPECT_EQ(fast.counters.alphaRejected, slow.counters.alphaRejected) << what;
  EXPECT_LE(fast.counters.samplesTested, slow.counters.samplesTested) << what;
}

RASTRAY_TEST_LABELS_OF(CoverageEquivalence, FastDepthPassWritesTheReferenceKeysAndWinners, "slow");
TEST(CoverageEquivalence, FastDepthPassWritesTheReferenceKeysAndWinners) {
  const Camera ortho = test::orthoCamera(kSize, kSize / 2.0, 0.0, 10.0);
  const Camera persp =
      test::perspectiveCamera(kSize, kSize, 1.2, glm::dvec3(0, 0, 70), glm::dvec3(0, 0, 0), 0.5);
  const DepthFormat formats[] = {DepthFormat::FloatReversed, DepthFormat::Float, DepthFormat::Unorm24,
                                 DepthFormat::Unorm16};
  for (uint32_t seed = 11; seed <= 12; ++seed) {
    const Scene scene = randomScene(seed, 150);
    for (int spp : {1, 4, 16})
      for (DepthFormat format : formats)
        for (const Camera* camera : {&ortho, &persp}) {
          const SampleGrid grid = makeSampleGrid(spp, kSize, kSize);
          const auto setups = setupScene(scene, *camera, grid, format);
          ASSERT_GT(setups.size(), 50u);
          for (DepthFunc func : {DepthFunc::Less, DepthFunc::LEqual})
            for (int mode = 0; mode < (func == DepthFunc::Less ? 2 : 1); ++mode) {  // keys only: no function
              const bool keysOnly = mode == 1;
              const PassResult fast = depthPass(setups, grid, format, func, keysOnly, CoveragePath::Fast);
              const PassResult slow =
                  depthPass(setups, grid, format, func, keysOnly, CoveragePath::Reference);
              const std::string what = "seed " + std::to_string(seed) + " spp " + std::to_string(spp) + " " +
                                       toString(format) + " " + toString(func) +
                                       (keysOnly ? " keys only" : "") +
                                       (camera == &ortho ? " ortho" : " perspective");
              ASSERT_NO_FATAL_FAILURE(expectSamePass(fast, slow, what));
            }
        }
  }
}

// The depth pass's lanes (depth_lanes.h: blocks eight pixels wide, whole
// or partial, at float formats without MASK) against the reference walk
// on every Highway target the build has: large random triangles among
// small ones, and two tilted quads over the whole image each with a
// coplanar copy (exact key ties over whole blocks, decided by id: the
// lanes hand those vectors back), at 1, 4 and 8 spp (partial blocks take
// the lanes up to 8 spp), both float formats, both functions, keys only.
RASTRAY_TEST_LABELS_OF(CoverageEquivalence, BlockLanesWriteTheReferenceKeysAndWinners, "quick");
TEST(CoverageEquivalence, BlockLanesWriteTheReferenceKeysAndWinners) {
  Scene scene = randomScene(23, 40);
  for (const double z : {-4.0, -6.0}) {
    const std::vector<glm::vec3> p = {world(-3, -2, z - 1.5), world(kSize + 4, -2, z),
                                      world(kSize + 4, kSize + 3, z + 1.0), world(-3, kSize + 3, z - 0.5)};
    for (int copy = 0; copy < 2; ++copy) test::addMesh(scene, p, {{0, 1, 2}, {0, 2, 3}});
  }
  const Camera persp =
      test::perspectiveCamera(kSize, kSize, 1.2, glm::dvec3(2, -1, 70), glm::dvec3(0, 0, 0), 0.5);
  for (const int spp : {1, 4, 8}) {
    // Both float formats over the three rates (the keys' form is the
    // same at every rate).
    const DepthFormat format = spp == 4 ? DepthFormat::Float : DepthFormat::FloatReversed;
    const SampleGrid grid = makeSampleGrid(spp, kSize, kSize);
    const auto setups = setupScene(scene, persp, grid, format);
    for (const DepthFunc func : {DepthFunc::Less, DepthFunc::LEqual})
      for (const bool keysOnly : {false, true}) {
        if (keysOnly && func == DepthFunc::LEqual) continue;
        const PassResult slow =
            depthPass(setups, grid, format, func, keysOnly, CoveragePath::Reference, false);
        for (const int64_t simd : hwy::SupportedAndGeneratedTargets()) {
          hwy::SetSupportedTargetsForTest(simd);
          const PassResult fast = depthPass(setups, grid, format, func, keysOnly, CoveragePath::Fast, false);
          const std::string what = "spp " + std::to_string(spp) + " " + toString(format) + " " +
                                   toString(func) + (keysOnly ? " keys only " : " ") + hwy::TargetName(simd);
          ASSERT_NO_FATAL_FAILURE(expectSamePass(fast, slow, what));
        }
        hwy::SetSupportedTargetsForTest(0);
      }
  }
}

TEST(CoverageEquivalence, HierarchicalDepthSkipsOccludedBlocks) {
  // A full-screen quad in front, then many triangles behind it: after the
  // quad, no sample behind it reaches the per-sample test.
  Scene scene;
  test::addMesh(scene,
                {world(-1, -1, -1), world(kSize + 1, -1, -1), world(kSize + 1, kSize + 1, -1),
                 world(-1, kSize + 1, -1)},
                {{0, 1, 2}, {0, 2, 3}});
  const Scene behind = randomScene(3, 100);
  test::addPushedBehind(scene, behind, -2.0f);
  const Camera camera = test::orthoCamera(kSize, kSize / 2.0, 0.0, 10.0);
  const SampleGrid grid = makeSampleGrid(4, kSize, kSize);
  const auto setups = setupScene(scene, camera, grid, DepthFormat::FloatReversed);
  const PassResult fast =
      depthPass(setups, grid, DepthFormat::FloatReversed, DepthFunc::Less, false, CoveragePath::Fast);
  const PassResult slow =
      depthPass(setups, grid, DepthFormat::FloatReversed, DepthFunc::Less, false, CoveragePath::Reference);
  ASSERT_EQ(fast.target.winners, slow.target.winners);
  // The quad's own samples, and nothing behind it.
  EXPECT_EQ(fast.counters.samplesTested, uint64_t(kSize) * kSize * 4);
  EXPECT_GT(slow.counters.samplesTested, 2 * fast.counters.samplesTested);
}

// rasterDepthPass told that each tile's rect starts cleared (the camera
// pass: the hierarchical test then skips reading the keys of blocks not
// yet fully written) writes the same keys and winners and counts the same
// tests as without, one pass per tile on a fresh target: small triangles
// over the whole image (each block written by many, each written sample
// counted) in front of random triangles behind them (culled where the
// blocks are written), with and without MASK, at 1 and 4 spp.
TEST(CoverageEquivalence, ClearedRectsGiveTheSameTargetAndCounters) {
  Scene scene;
  // A 60 × 60 grid of quads, two triangles each, about 2.5 pixels a
  // triangle, in front of the random scene's triangles.
  std::vector<glm::vec3> p;
  constexpr int kCells = 60;
  const double cell = double(kSize) / kCells;
  for (int y = 0; y <= kCells; ++y)
    for (int x = 0; x <= kCells; ++x)
      p.push_back(world(x * cell, y * cell, -1.0 - 0.001 * ((x * 7 + y * 3) % 11)));
  const std::vector<glm::uvec3> t = gridTriangles(kCells);
  test::addMesh(scene, p, t);
  const Scene behind = randomScene(5, 60);
  test::addPushedBehind(scene, behind, -2.0f);
  const Camera camera = test::orthoCamera(kSize, kSize / 2.0, 0.0, 10.0);
  for (const int spp : {1, 4}) {
    const SampleGrid grid = makeSampleGrid(spp, kSize, kSize);
    const auto setups = setupScene(scene, camera, grid, DepthFormat::FloatReversed);
    std::vector<uint32_t> bin;
    for (uint32_t i = 0; i < setups.size(); ++i) bin.push_back(i);
    for (const bool mask : {false, true}) {
      SCOPED_TRACE("spp " + std::to_string(spp) + (mask ? ", MASK" : ""));
      std::function<bool(const TriangleSetup&, int, int, int)> alpha;
      if (mask)
        alpha = [](const TriangleSetup& tri, int x, int y, int s) {
          return ((uint32_t(x) * 73856093u) ^ (uint32_t(y) * 19349663u) ^ uint32_t(s) ^ tri.triangle) % 7 !=
                 0;
        };
      PassResult plain{DepthTarget(kSize, kSize, spp), {}}, cleared{DepthTarget(kSize, kSize, spp), {}};
      const TileGrid tiles(kSize, kSize);
      for (int tile = 0; tile < tiles.count(); ++tile) {
        rasterDepthPass(setups, bin, grid, tiles.rect(tile), DepthFormat::FloatReversed, DepthFunc::Less,
                        alpha, TraceRequest{}, &plain.target, &plain.counters, CoveragePath::Fast, false);
        rasterDepthPass(setups, bin, grid, tiles.rect(tile), DepthFormat::FloatReversed, DepthFunc::Less,
                        alpha, TraceRequest{}, &cleared.target, &cleared.counters, CoveragePath::Fast, true);
      }
      EXPECT_EQ(plain.target.keys, cleared.target.keys);
      EXPECT_EQ(plain.target.winners, cleared.target.winners);
      EXPECT_EQ(plain.counters.coverageTests, cleared.counters.coverageTests);
      EXPECT_EQ(plain.counters.samplesTested, cleared.counters.samplesTested);
      EXPECT_EQ(plain.counters.samplesPassed, cleared.counters.samplesPassed);
      EXPECT_EQ(plain.counters.alphaRejected, cleared.counters.alphaRejected);
    }
  }
}

// The depth pass's small-triangle path (pixels within one block, at most
// 16 samples: masks straight from the edge functions) against the
// reference walk: a grid of sub-pixel to 3-pixel triangles over the image
// with a coplanar copy of part of it (exact key ties, decided by id), tiny
// random triangles on the 1/16-pixel grid (edges through sample
// positions: the fill rule), at 1, 4 and 16 spp, two depth formats, both
// functions, keys only, MASK, orthographic and perspective.
TEST(CoverageEquivalence, SmallTrianglePathWritesTheReferenceKeysAndWinners) {
  Scene scene;
  std::mt19937 rng(17);
  const auto uniform = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  for (const double cell : {1.1, 2.3}) {
    const int cells = int(kSize / cell);
    std::vector<glm::vec3> p;
    for (int y = 0; y <= cells; ++y)
      for (int x = 0; x <= cells; ++x)
        p.push_back(world(x * cell + 0.3, y * cell + 0.1, -1.0 - uniform(0.0, 0.05)));
    std::vector<glm::uvec3> t = gridTriangles(cells);
    test::addMesh(scene, p, t);
    t.resize(t.size() / 3);
    test::addMesh(scene, p, t);  // the copy: exact ties
  }
  std::vector<glm::vec3> p;
  std::vector<glm::uvec3> t;
  const auto snap = [](double v) { return std::round(v * 16.0) / 16.0; };
  for (uint32_t k = 0; k < 1500; ++k) {
    const double cx = snap(uniform(-2.0, kSize + 2.0)), cy = snap(uniform(-2.0, kSize + 2.0));
    const double z = -uniform(0.5, 1.2);
    for (int v = 0; v < 3; ++v)
      p.push_back(world(cx + snap(uniform(-1.5, 1.5)), cy + snap(uniform(-1.5, 1.5)), z));
    t.push_back({3 * k, 3 * k + 1, 3 * k + 2});
  }
  test::addMesh(scene, p, t);
  const Camera ortho = test::orthoCamera(kSize, kSize / 2.0, 0.0, 10.0);
  const Camera persp =
      test::perspectiveCamera(kSize, kSize, 1.2, glm::dvec3(3, -2, 70), glm::dvec3(0, 0, 0), 0.5);
  for (const int spp : {1, 4, 16})
    for (const Camera* camera : {&ortho, &persp}) {
      const DepthFormat format = camera == &ortho ? DepthFormat::FloatReversed : DepthFormat::Unorm16;
      const SampleGrid grid = makeSampleGrid(spp, kSize, kSize);
      const auto setups = setupScene(scene, *camera, grid, format);
      for (const DepthFunc func : {DepthFunc::Less, DepthFunc::LEqual})
        for (const bool keysOnly : {false, true}) {
          if (keysOnly && func == DepthFunc::LEqual) continue;
          const PassResult fast = depthPass(setups, grid, format, func, keysOnly, CoveragePath::Fast);
          const PassResult slow = depthPass(setups, grid, format, func, keysOnly, CoveragePath::Reference);
          const std::string what = "spp " + std::to_string(spp) + " " + toString(format) + " " +
                                   toString(func) + (keysOnly ? " keys only" : "") +
                                   (camera == &ortho ? " ortho" : " perspective");
          ASSERT_NO_FATAL_FAILURE(expectSamePass(fast, slow, what));
        }
    }
}

// The small-triangle path over several blocks (bounds within the tile of
// at most 8 × 8 pixels and 64 samples: masks over the bounds, split per
// block of the tile) against the reference walk, on each tile as the
// camera pass runs it (a cleared rect: the hierarchical test's count of
// samples left per block): grids of 3.7- and 6.1-pixel cells (bounds of
// 4 to 8 pixels, most across a block edge or corner) with a coplanar copy
// of part of one (exact key ties, decided by id), then random triangles
// behind them (blocks culled once written) and tiny ones in front, at 1,
// 2, 4, 8, 16 and 25 spp (at 4, 8, 16, samples tested from masks take a
// pixel's four samples as one vector, ties included; 25: an odd grid,
// 1280 units a pixel), both float formats, both functions, keys only and MASK.
RASTRAY_TEST_LABELS_OF(CoverageEquivalence, SmallTrianglesAcrossBlocksWriteTheReferenceKeysAndWinners,
                       "quick");
TEST(CoverageEquivalence, SmallTrianglesAcrossBlocksWriteTheReferenceKeysAndWinners) {
  Scene scene;
  std::mt19937 rng(29);
  const auto uniform = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  for (const double cell : {3.7, 6.1}) {
    const int cells = int(kSize / cell) + 1;
    std::vector<glm::vec3> p;
    for (int y = 0; y <= cells; ++y)
      for (int x = 0; x <= cells; ++x)
        p.push_back(world(x * cell - 0.4, y * cell + 0.2, -1.0 - uniform(0.0, 0.05)));
    std::vector<glm::uvec3> t = gridTriangles(cells);
    test::addMesh(scene, p, t);
    if (cell < 4.0) {
      t.resize(t.size() / 3);
      test::addMesh(scene, p, t);  // the copy: exact ties
    }
  }
  const Scene behind = randomScene(31, 60);
  test::addPushedBehind(scene, behind, -2.0f);
  std::vector<glm::vec3> p;
  std::vector<glm::uvec3> t;
  for (uint32_t k = 0; k < 400; ++k) {
    const double cx = uniform(0.0, kSize), cy = uniform(0.0, kSize);
    for (int v = 0; v < 3; ++v) p.push_back(world(cx + uniform(-3.0, 3.0), cy + uniform(-3.0, 3.0), -0.5));
    t.push_back({3 * k, 3 * k + 1, 3 * k + 2});
  }
  test::addMesh(scene, p, t);
  const Camera ortho = test::orthoCamera(kSize, kSize / 2.0, 0.0, 10.0);
  const Camera persp =
      test::perspectiveCamera(kSize, kSize, 1.2, glm::dvec3(2, 3, 70), glm::dvec3(0, 0, 0), 0.5);
  const std::function<bool(const TriangleSetup&, int, int, int)> alpha = [](const TriangleSetup& tri, int x,
                                                                            int y, int s) {
    return ((uint32_t(x) * 73856093u) ^ (uint32_t(y) * 19349663u) ^ uint32_t(s) ^ tri.triangle) % 5 != 0;
  };
  const TileGrid tiles(kSize, kSize);
  for (const int spp : {1, 2, 4, 8, 16, 25})
    for (const Camera* camera : {&ortho, &persp}) {
      const DepthFormat format = camera == &ortho ? DepthFormat::FloatReversed : DepthFormat::Float;
      const SampleGrid grid = makeSampleGrid(spp, kSize, kSize);
      const auto setups = setupScene(scene, *camera, grid, format);
      std::vector<uint32_t> bin;
      size_t acrossBlocks = 0;
      for (uint32_t i = 0; i < setups.size(); ++i) {
        bin.push_back(i);
        const TriangleSetup& s = setups[i];
        const int w = s.pixelMax.x - s.pixelMin.x + 1, h = s.pixelMax.y - s.pixelMin.y + 1;
        if (w <= 8 && h <= 8 && w * h * spp <= 64 &&
            (s.pixelMin.x / 8 != s.pixelMax.x / 8 || s.pixelMin.y / 8 != s.pixelMax.y / 8))
          ++acrossBlocks;
      }
      if (spp <= 4) {  // bounds of at most 8 or 4 pixels are few
        ASSERT_GT(acrossBlocks, 40u) << "spp " << spp;
      }
      for (const DepthFunc func : {DepthFunc::Less, DepthFunc::LEqual})
        for (int mode = 0; mode < 3; ++mode) {  // 0 plain, 1 keys only, 2 MASK
          if (mode == 1 && func == DepthFunc::LEqual) continue;
          const bool keysOnly = mode == 1;
          PassResult fast{DepthTarget(kSize, kSize, spp, keysOnly), {}};
          PassResult slow{DepthTarget(kSize, kSize, spp, keysOnly), {}};
          for (int tile = 0; tile < tiles.count(); ++tile) {
            rasterDepthPass(setups, bin, grid, tiles.rect(tile), format, func, mode == 2 ? alpha : nullptr,
                            TraceRequest{}, &fast.target, &fast.counters, CoveragePath::Fast, true);
            rasterDepthPass(setups, bin, grid, tiles.rect(tile), format, func, mode == 2 ? alpha : nullptr,
                            TraceRequest{}, &slow.target, &slow.counters, CoveragePath::Reference, true);
          }
          const std::string what = "spp " + std::to_string(spp) + " " + toString(format) + " " +
                                   toString(func) + " mode " + std::to_string(mode);
          ASSERT_NO_FATAL_FAILURE(expectSamePass(fast, slow, what));
          // Blocks written whole by the grids cull the triangles behind them.
          EXPECT_LT(fast.counters.samplesTested, slow.counters.samplesTested) << what;
        }
    }
}

TEST(CoverageEquivalence, RendersMatchTheReferenceWalkWithMaskAndBlend) {
  Scene scene = randomScene(21, 120);
  // Every third instance MASK with a constant alpha below the cutoff on
  // half of them, every fifth BLEND: the alpha test and the transparency
  // pass's walk.
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    Material& m = scene.materials[i];
    m.baseColorFactor = glm::vec4(float(i % 7) / 7.0f, float(i % 3) / 3.0f, 0.5f, 1.0f);
    if (i % 3 == 1) {
      m.alphaMode = AlphaMode::Mask;
      m.alphaCutoff = 0.5f;
      m.baseColorFactor.a = i % 2 ? 0.25f : 0.75f;
    } else if (i % 5 == 2) {
      m.alphaMode = AlphaMode::Blend;
      m.baseColorFactor.a = 0.5f;
    }
  }
  const Camera camera = test::orthoCamera(kSize, kSize / 2.0, 0.0, 10.0);
  for (int spp : {1, 4}) {
    RasterOptions options;
    options.spp = spp;
    options.shadows = RasterShadows::None;
    const RenderOutput fast = test::render(scene, camera, options);
    options.referenceCoverage = true;
    const RenderOutput slow = test::render(scene, camera, options);
    EXPECT_EQ(fast.image.color, slow.image.color) << spp;
    EXPECT_EQ(fast.image.depth, slow.image.depth) << spp;
    EXPECT_EQ(fast.image.instance, slow.image.instance) << spp;
    EXPECT_EQ(fast.image.triangle, slow.image.triangle) << spp;
    EXPECT_GT(fast.counters.get("raster.fragments_transparent"), 0u);
    EXPECT_GT(fast.counters.get("raster.alpha_rejected"), 0u);
  }
}

}  // namespace
}  // namespace rastray
