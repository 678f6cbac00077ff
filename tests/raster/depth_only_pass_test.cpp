// The shadow maps' depth-only pass (raster/depth_only_pass.h) and the SIMD
// row keys (raster/depth_keys.h) against the scalar reference: the fast
// pass, its reference walk and the keys-only rasterDepthPass that the maps
// used before must leave identical keys, on seeded random scenes (ties,
// slivers, huge triangles, a MASK-like alpha test), in every depth format,
// through ortho, perspective and cube-face cameras, at sizes that are not
// multiples of the block or tile size.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "raster/bin.h"
#include "raster/coverage.h"
#include "raster/depth_keys.h"
#include "raster/depth_only_pass.h"
#include "raster/setup.h"
#include "raster/shadow_map.h"
#include "raster_test_util.h"

namespace rastray {
namespace {

double bitsToDouble(uint64_t u) {
  double d;
  std::memcpy(&d, &u, sizeof d);
  return d;
}

TEST(DepthKeys, RowKeysMatchTheScalarKeyBitForBit) {
  std::mt19937_64 rng(7);
  const double inf = std::numeric_limits<double>::infinity(), nan = std::numeric_limits<double>::quiet_NaN();
  // Values around every edge of the clamp and the float rounding.
  const double special[] = {0.0,           -0.0,  1.0,   -1.0,   0.5,  1.0 + 1e-16, -1e-300,
                            1e-300,        1e-45, 1e-38, inf,    -inf, nan,         -nan,
                            0.99999999999, 2.0,   1e300, -1e300, 0.1,  1.0 / 3.0};
  const DepthFormat formats[] = {DepthFormat::FloatReversed, DepthFormat::Float, DepthFormat::Unorm24,
                                 DepthFormat::Unorm16};
  for (int round = 0; round < 20000; ++round) {
    double column[8];
    double row;
    for (double& c : column) {
      switch (rng() % 4) {
        case 0:
          c = special[rng() % (sizeof special / sizeof special[0])];
          break;
        case 1:
          c = bitsToDouble(rng());  // any bit pattern: NaN payloads, denormals, both signs
          break;
        default:
          c = std::uniform_real_distribution<double>(-0.5, 1.5)(rng);
      }
    }
    row = rng() % 3 == 0 ? special[rng() % (sizeof special / sizeof special[0])]
                         : std::uniform_real_distribution<double>(-0.5, 0.5)(rng);
    // NaN + NaN returns one of the two operands' NaN, whichever the
    // compiler put first (addition commutes), so the scalar key itself is
    // not defined bit for bit there (depth_keys.h).
    if (std::isnan(row))
      for (double& c : column)
        if (std::isnan(c)) c = 0.25;
    for (DepthFormat format : formats) {
      uint32_t keys[8];
      planeRowKeys(format, column, row, keys);
      for (int i = 0; i < 8; ++i)
        ASSERT_EQ(keys[i], depthKey(format, column[i] + row))
            << toString(format) << " column " << column[i] << " row " << row;
    }
  }
}

// A depth plane of a few thousand pixels' range with v0 in [lowest, highest).
Plane randomPlane(std::mt19937& rng, double lowest, double highest) {
  const auto u = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  Plane p;
  p.v0 = u(lowest, highest);
  p.dx = u(-1e-2, 1e-2);
  p.dy = u(-1e-2, 1e-2);
  p.x0 = u(-100, 3000);
  p.y0 = u(-100, 3000);
  return p;
}

TEST(DepthKeys, RowTermsAreThePlaneAtTheSample) {
  std::mt19937 rng(3);
  const auto u = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  for (int round = 0; round < 2000; ++round) {
    const Plane p = randomPlane(rng, -2, 2);
    const int px0 = int(rng() % 2048), py = int(rng() % 2048);
    const double ox = u(0, 1), oy = u(0, 1);
    double column[8];
    planeColumnTerms(p, px0, ox, column);
    const double row = planeRowTerm(p, py, oy);
    for (int i = 0; i < 8; ++i) {
      const double expected = p.at(double(px0 + i) + ox, double(py) + oy);
      const double z = column[i] + row;
      ASSERT_EQ(std::memcmp(&expected, &z, sizeof z), 0) << round << " " << i;
    }
  }
}

#if defined(__SSE2__)
// The lanes of a pixel's four samples that the depth pass tests from masks
// at 4, 8 and 16 spp (pixelSampleKeys) against depthKey(format, p.at(x, y))
// at the same positions, planes that leave [0, 1] included (the clamp).
TEST(DepthKeys, PixelSampleKeysAreTheScalarKeyAtEachSample) {
  std::mt19937 rng(5);
  const auto u = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  for (int round = 0; round < 4000; ++round) {
    const Plane p = randomPlane(rng, -0.5, 1.5);
    const int px = int(rng() % 2048), py = int(rng() % 2048);
    double qx[4], qy[4];
    for (int k = 0; k < 4; ++k) {
      qx[k] = u(0, 1);
      qy[k] = u(0, 1);
    }
    for (const DepthFormat format : {DepthFormat::FloatReversed, DepthFormat::Float}) {
      alignas(16) uint32_t keys[4];
      _mm_store_si128(reinterpret_cast<__m128i*>(keys),
                      pixelSampleKeys(format == DepthFormat::FloatReversed, p, px, py, qx, qy));
      for (int k = 0; k < 4; ++k)
        ASSERT_EQ(keys[k], depthKey(format, p.at(double(px) + qx[k], double(py) + qy[k])))
            << toString(format) << " round " << round << " sample " << k;
    }
  }
}
#endif

// One world unit per pixel for orthoCamera(size, size / 2).
glm::vec3 world(int size, double x, double y, double z) {
  return glm::vec3(float(x - size / 2.0), float(size / 2.0 - y), float(z));
}

// Random triangles over the image (tiny, slivers, huge, off-screen, coplanar
// copies for key ties), in front of an ortho camera at the origin, z in
// [−9, −1].
Scene randomScene(uint32_t seed, int count, int size) {
  std::mt19937 rng(seed);
  const auto uniform = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  const auto snap = [](double v) { return std::round(v * 16.0) / 16.0; };
  const auto depth = [&]() { return -uniform(1.0, 9.0); };
  Scene scene;
  for (int i = 0; i < count; ++i) {
    std::vector<glm::vec3> p;
    std::vector<glm::uvec3> t = {{0, 1, 2}};
    const double cx = snap(uniform(-20.0, size + 20.0)), cy = snap(uniform(-20.0, size + 20.0));
    switch (rng() % 6) {
      case 0:  // tiny
        for (int k = 0; k < 3; ++k)
          p.push_back(world(size, cx + snap(uniform(-2, 2)), cy + snap(uniform(-2, 2)), depth()));
        break;
      case 1: {  // sliver
        const double ex = snap(uniform(-size, size)), ey = snap(uniform(-size, size));
        p = {world(size, cx, cy, depth()), world(size, cx + ex, cy + ey, depth()),
             world(size, cx + ex / 2 + 1.0 / 16, cy + ey / 2, depth())};
        break;
      }
      case 2:  // huge: beyond the image, the int64 coverage fallback
        for (int k = 0; k < 3; ++k)
          p.push_back(world(size, snap(uniform(-6000, 6000)), snap(uniform(-6000, 6000)), depth()));
        break;
      case 3: {  // a quad in one plane and a coplanar copy: key ties
        const double w = snap(uniform(1, 70)), h = snap(uniform(1, 70));
        const double z0 = depth(), z1 = depth();
        p = {world(size, cx, cy, z0), world(size, cx + w, cy, z0), world(size, cx + w, cy + h, z1),
             world(size, cx, cy + h, z1)};
        t = {{0, 1, 2}, {0, 2, 3}};
        test::addMesh(scene, p, t);
        break;
      }
      default:  // medium
        for (int k = 0; k < 3; ++k)
          p.push_back(world(size, cx + snap(uniform(-50, 50)), cy + snap(uniform(-50, 50)), depth()));
        break;
    }
    test::addMesh(scene, p, t);
  }
  return scene;
}

// Odd instances drop a hashed fifth of their samples.
const AlphaTestFunction kAlpha = [](const TriangleSetup& t, int x, int y, int s) {
  return t.instance % 2 == 0 ||
         ((uint32_t(x) * 73856093u) ^ (uint32_t(y) * 19349663u) ^ uint32_t(s) ^ t.triangle) % 5 != 0;
};

struct Maps {
  std::vector<uint32_t> keys;
  std::vector<uint32_t> blockKeys;  // the same tiles stored by blocks (BlockDepthMap::key)
  int planeBlocks = 0;              // blocks the tiles held as a plane
  DepthPassCounters counters;
};

std::vector<TriangleSetup> setupFor(const Scene& scene, const Camera& camera, const SampleGrid& grid,
                                    DepthFormat format, double biasSlope, double biasConstant,
                                    const TriangleFilter& filter) {
  const ClipSpace space = makeClipSpace(camera, grid.guardPixels);
  const DepthSettings ds{format, camera.projection, camera.znear, camera.zfar, biasSlope, biasConstant};
  SetupCounters n;
  return prepareTriangles(scene, space, grid, ds, CullMode::None, filter, &n);
}

// The depth-only pass over every tile of a map filled with garbage first
// (the pass must write every texel), stored texel by texel and by blocks
// (whose keys are garbage too where no block of keys was stored).
Maps depthOnly(const std::vector<TriangleSetup>& setups, const SampleGrid& grid, int w, int h,
               DepthFormat format, const AlphaTestFunction& alpha, CoveragePath path,
               SimdLevel simd = SimdLevel::Best) {
  DepthMap map(w, h);
  std::fill_n(map.keys.get(), size_t(w) * size_t(h), 0x5A5A5A5Au);
  BlockDepthMap blocks(w, h, format, grid.positions[0]);
  std::fill_n(blocks.keys.keys.get(), size_t(w) * size_t(h), 0x5A5A5A5Au);
  const TileGrid tiles(w, h);
  const auto bins = binTriangles(tiles, grid, setups, [](const TriangleSetup&) { return true; });
  Maps out;
  for (int tile = 0; tile < tiles.count(); ++tile) {
    DepthOnlyTile t(tiles.rect(tile));
    t.render(setups, bins[size_t(tile)], grid, format, alpha, &out.counters, path, simd);
    t.store(&map);
    t.store(&blocks);
    out.planeBlocks += t.planeBlocks();
  }
  blocks.keepPlanes(setups);
  out.keys.assign(map.keys.get(), map.keys.get() + size_t(w) * size_t(h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) out.blockKeys.push_back(blocks.key(x, y));
  return out;
}

// What the shadow maps ran before: a cleared keys-only DepthTarget and the
// camera pass's rasterDepthPass with Less.
Maps keysOnlyDepthPass(const std::vector<TriangleSetup>& setups, const SampleGrid& grid, int w, int h,
                       DepthFormat format, const AlphaTestFunction& alpha, CoveragePath path) {
  DepthTarget target(w, h, 1, true);
  const TileGrid tiles(w, h);
  const auto bins = binTriangles(tiles, grid, setups, [](const TriangleSetup&) { return true; });
  Maps out;
  for (int tile = 0; tile < tiles.count(); ++tile)
    rasterDepthPass(setups, bins[size_t(tile)], grid, tiles.rect(tile), format, DepthFunc::Less, alpha,
                    TraceRequest{}, &target, &out.counters, path);
  out.keys = target.keys;
  return out;
}

// Fast and reference depth-only passes and both walks of the keys-only
// rasterDepthPass agree on every key and on the counters that do not
// depend on the hierarchical test.
void expectSameMaps(const std::vector<TriangleSetup>& setups, const SampleGrid& grid, int w, int h,
                    DepthFormat format, const std::string& what) {
  for (const AlphaTestFunction* alpha : {static_cast<const AlphaTestFunction*>(nullptr), &kAlpha}) {
    const AlphaTestFunction none;
    const AlphaTestFunction& a = alpha ? *alpha : none;
    const std::string label = what + (alpha ? " with alpha test" : "");
    const Maps fast = depthOnly(setups, grid, w, h, format, a, CoveragePath::Fast);
    const Maps avx2 = depthOnly(setups, grid, w, h, format, a, CoveragePath::Fast, SimdLevel::Avx2);
    const Maps baseline = depthOnly(setups, grid, w, h, format, a, CoveragePath::Fast, SimdLevel::Baseline);
    const Maps slow = depthOnly(setups, grid, w, h, format, a, CoveragePath::Reference);
    const Maps before = keysOnlyDepthPass(setups, grid, w, h, format, a, CoveragePath::Fast);
    const Maps beforeSlow = keysOnlyDepthPass(setups, grid, w, h, format, a, CoveragePath::Reference);
    ASSERT_EQ(fast.keys, slow.keys) << label;
    ASSERT_EQ(avx2.keys, slow.keys) << label;
    ASSERT_EQ(baseline.keys, slow.keys) << label;
    for (const Maps* m : {&fast, &avx2, &baseline, &slow}) ASSERT_EQ(m->blockKeys, slow.keys) << label;
    // Whole covered blocks taken as planes where the kernels have a
    // whole-block path (AVX2 and up, float formats, no alpha test).
    if (!alpha && (format == DepthFormat::FloatReversed || format == DepthFormat::Float)) {
      EXPECT_GT(fast.planeBlocks, 0) << label;
      EXPECT_GT(avx2.planeBlocks, 0) << label;
    }
    EXPECT_EQ(slow.planeBlocks, 0) << label;
    EXPECT_EQ(avx2.counters.samplesTested, fast.counters.samplesTested) << label;
    EXPECT_EQ(avx2.counters.samplesPassed, fast.counters.samplesPassed) << label;
    EXPECT_EQ(baseline.counters.samplesTested, fast.counters.samplesTested) << label;
    EXPECT_EQ(baseline.counters.samplesPassed, fast.counters.samplesPassed) << label;
    ASSERT_EQ(fast.keys, before.keys) << label;
    ASSERT_EQ(fast.keys, beforeSlow.keys) << label;
    EXPECT_EQ(fast.counters.coverageTests, slow.counters.coverageTests) << label;
    EXPECT_EQ(fast.counters.samplesPassed, slow.counters.samplesPassed) << label;
    EXPECT_EQ(fast.counters.alphaRejected, slow.counters.alphaRejected) << label;
    EXPECT_EQ(slow.counters.samplesTested, beforeSlow.counters.samplesTested) << label;
    EXPECT_EQ(slow.counters.samplesPassed, beforeSlow.counters.samplesPassed) << label;
    EXPECT_LE(fast.counters.samplesTested, slow.counters.samplesTested) << label;
    // Not vacuous: something was drawn, and some of it hidden.
    EXPECT_GT(fast.counters.samplesPassed, 0u) << label;
    EXPECT_LT(fast.counters.samplesPassed, slow.counters.samplesTested) << label;
  }
}

TEST(DepthOnlyPass, FastPassWritesTheReferenceKeysOnOrthoAndPerspectiveViews) {
  const int size = 150;  // not a multiple of the block or tile size
  const Camera ortho = test::orthoCamera(size, size / 2.0, 0.0, 10.0);
  const Camera persp = test::perspectiveCamera(size, size, 1.2, glm::dvec3(0, 0, 70), glm::dvec3(0), 0.5);
  const DepthFormat formats[] = {DepthFormat::FloatReversed, DepthFormat::Float, DepthFormat::Unorm24,
                                 DepthFormat::Unorm16};
  for (uint32_t seed = 31; seed <= 33; ++seed) {
    const Scene scene = randomScene(seed, 160, size);
    const SampleGrid grid = makeSampleGrid(1, size, size);
    for (DepthFormat format : formats)
      for (const Camera* camera : {&ortho, &persp})
        for (double bias : {0.0, 1.0}) {  // the shadow maps' polygon offset moves v0 only
          const auto setups = setupFor(scene, *camera, grid, format, bias, bias, {});
          ASSERT_GT(setups.size(), 80u);
          expectSameMaps(setups, grid, size, size, format,
                         "seed " + std::to_string(seed) + " " + toString(format) +
                             (camera == &ortho ? " ortho" : " perspective") + " bias " +
                             std::to_string(bias));
        }
  }
}

TEST(DepthOnlyPass, FastPassWritesTheReferenceKeysOnCubeFaces) {
  // Random triangles all around a point light, its six faces set up as
  // ShadowMaps does (face candidates, bias), at an odd map size.
  std::mt19937 rng(5);
  const auto u = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  Scene scene;
  for (int i = 0; i < 400; ++i) {
    const glm::dvec3 c(u(-4, 4), u(-4, 4), u(-4, 4));
    const double r = rng() % 4 == 0 ? u(1, 4) : u(0.02, 0.5);
    std::vector<glm::vec3> p;
    for (int k = 0; k < 3; ++k) p.push_back(glm::vec3(c + glm::dvec3(u(-r, r), u(-r, r), u(-r, r))));
    test::addMesh(scene, p, {{0, 1, 2}});
  }
  const glm::dvec3 eye(0.1, 0.2, -0.3);
  for (int size : {97, 128}) {
    const SampleGrid grid = makeSampleGrid(1, size, size);
    const std::vector<Camera> faces = cubeFaceCameras(eye, size, 1e-3);
    const ClipSpace first = makeClipSpace(faces[0], grid.guardPixels);
    const std::vector<uint8_t> candidates = cubeFaceCandidates(scene, eye, first.scale.x, size);
    for (int f = 0; f < kCubeFaces; ++f) {
      const TriangleFilter filter{true, true, &candidates, uint8_t(1u << f)};
      const auto setups =
          setupFor(scene, faces[size_t(f)], grid, DepthFormat::FloatReversed, 1.0, 1.0, filter);
      ASSERT_GT(setups.size(), 20u);
      expectSameMaps(setups, grid, size, size, DepthFormat::FloatReversed,
                     "size " + std::to_string(size) + " face " + std::to_string(f));
    }
  }
}

TEST(DepthOnlyPass, HierarchicalTestSkipsHiddenBlocks) {
  // A full-map quad in front, then triangles behind it: after the quad, no
  // sample behind it reaches the per-texel test.
  const int size = 128;
  Scene scene;
  test::addMesh(scene,
                {world(size, -1, -1, -1), world(size, size + 1, -1, -1), world(size, size + 1, size + 1, -1),
                 world(size, -1, size + 1, -1)},
                {{0, 1, 2}, {0, 2, 3}});
  const Scene behind = randomScene(9, 100, size);
  test::addPushedBehind(scene, behind, -2.0f);
  const Camera camera = test::orthoCamera(size, size / 2.0, 0.0, 10.0);
  const SampleGrid grid = makeSampleGrid(1, size, size);
  const auto setups = setupFor(scene, camera, grid, DepthFormat::FloatReversed, 0, 0, {});
  const Maps fast = depthOnly(setups, grid, size, size, DepthFormat::FloatReversed, {}, CoveragePath::Fast);
  const Maps slow =
      depthOnly(setups, grid, size, size, DepthFormat::FloatReversed, {}, CoveragePath::Reference);
  ASSERT_EQ(fast.keys, slow.keys);
  EXPECT_EQ(fast.counters.samplesTested, uint64_t(size) * size);  // the quad's own texels only
  EXPECT_GT(slow.counters.samplesTested, 2 * fast.counters.samplesTested);
}

TEST(DepthOnlyPass, EmptyTilesAreCleared) {
  const int size = 100;
  const SampleGrid grid = makeSampleGrid(1, size, size);
  const Maps m = depthOnly({}, grid, size, size, DepthFormat::FloatReversed, {}, CoveragePath::Fast);
  EXPECT_EQ(m.keys, std::vector<uint32_t>(size_t(size) * size, kClearDepthKey));
}

// DepthMap storage is kept for the next map of its size (no fresh pages
// to zero each frame) and given back when a map of another size comes.
TEST(DepthMapPool, AFreedMapIsReusedForItsSizeAndGivenBackForAnother) {
  const uint32_t* first = nullptr;
  {
    const DepthMap a(300, 200);
    first = a.keys.get();
  }
  EXPECT_EQ(depthMapPoolBytes(), size_t(300 * 200 * 4));  // 240,000 B: a multiple of 64
  {
    const DepthMap b(300, 200);
    EXPECT_EQ(b.keys.get(), first);
    EXPECT_EQ(depthMapPoolBytes(), 0u);
  }
  EXPECT_EQ(depthMapPoolBytes(), size_t(300 * 200 * 4));
  {
    const DepthMap c(100, 100);
    EXPECT_EQ(depthMapPoolBytes(), 0u);  // the 300 × 200 buffer went back to the system
  }
  EXPECT_EQ(depthMapPoolBytes(), size_t(100 * 100 * 4));
}

}  // namespace
}  // namespace rastray
