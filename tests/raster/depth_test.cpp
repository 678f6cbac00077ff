#include "raster/depth.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>

#include "raster/bin.h"
#include "raster/coverage.h"
#include "raster/setup.h"
#include "raster_test_util.h"

#include "tests/test_labels.h"

namespace rastray {
namespace {

constexpr DepthFormat kFormats[] = {DepthFormat::FloatReversed, DepthFormat::Float, DepthFormat::Unorm24,
                                    DepthFormat::Unorm16};

// Distinct keys among 1024 evenly spaced view depths in [d, d + 1]
// (perspective, znear 0.1, infinite far): how finely the format tells
// surfaces apart there.
size_t distinctKeys(DepthFormat f, double d) {
  std::vector<uint32_t> keys;
  for (int i = 0; i < 1024; ++i)
    keys.push_back(depthKey(f, windowDepth(f, Projection::Perspective, 0.1, INFINITY, d + i / 1024.0)));
  std::sort(keys.begin(), keys.end());
  return size_t(std::unique(keys.begin(), keys.end()) - keys.begin());
}

TEST(DepthFormats, KeysOrderNearBeforeFarInEveryFormat) {
  for (DepthFormat f : kFormats) {
    for (Projection p : {Projection::Perspective, Projection::Orthographic}) {
      const double zfar = 1000.0;
      uint32_t previous = 0;
      for (double d : {0.1, 0.5, 1.0, 10.0, 100.0, 999.0}) {
        const uint32_t k = depthKey(f, windowDepth(f, p, 0.1, zfar, d));
        EXPECT_GE(k, previous) << toString(f) << " " << d;
        EXPECT_LT(k, kClearDepthKey);
        previous = k;
      }
    }
  }
}

TEST(DepthFormats, PrecisionOrderingFarFromTheCamera) {
  // At 100 units, znear 0.1: z = 1 − n/d changes by ≈ 1e-5 per unit of d.
  // unorm16 (step 2^-16 ≈ 1.5e-5) sees ~1 level per unit, unorm24 and float
  // (step 2^-24 near z = 1) ~170, float-reversed (z ≈ 1e-3, relative
  // 2^-24) every one of the 1024 depths.
  const size_t rev = distinctKeys(DepthFormat::FloatReversed, 100.0);
  const size_t flt = distinctKeys(DepthFormat::Float, 100.0);
  const size_t u24 = distinctKeys(DepthFormat::Unorm24, 100.0);
  const size_t u16 = distinctKeys(DepthFormat::Unorm16, 100.0);
  EXPECT_EQ(rev, 1024u);
  EXPECT_GT(u24, 100u);
  EXPECT_LT(u24, 300u);
  EXPECT_GT(flt, 100u);
  EXPECT_LT(flt, 300u);
  EXPECT_LE(u16, 3u);
}

TEST(DepthFormats, MinimumResolvableDifference) {
  EXPECT_EQ(minimumResolvableDifference(DepthFormat::Unorm16, 0.5), std::ldexp(1.0, -16));
  EXPECT_EQ(minimumResolvableDifference(DepthFormat::Unorm24, 0.5), std::ldexp(1.0, -24));
  EXPECT_EQ(minimumResolvableDifference(DepthFormat::Float, 0.75), std::ldexp(1.0, -24));   // exponent −1
  EXPECT_EQ(minimumResolvableDifference(DepthFormat::Float, 0.001), std::ldexp(1.0, -33));  // exponent −10
  EXPECT_EQ(polygonOffset(DepthFormat::Unorm24, 2.0, 3.0, 0.25, 0.5), 0.5 + 3.0 * std::ldexp(1.0, -24));
}

TEST(DepthTest, TiesResolveByIdNotBySubmissionOrder) {
  const uint32_t key = 1234;
  const uint64_t lo = packId(0, 5), hi = packId(1, 0);
  // Less: the lower id keeps the sample whichever came first.
  EXPECT_TRUE(passesDepthTest(DepthFunc::Less, key, lo, key, hi));
  EXPECT_FALSE(passesDepthTest(DepthFunc::Less, key, hi, key, lo));
  // LEqual: the higher id (the later in canonical order) wins.
  EXPECT_TRUE(passesDepthTest(DepthFunc::LEqual, key, hi, key, lo));
  EXPECT_FALSE(passesDepthTest(DepthFunc::LEqual, key, lo, key, hi));
  EXPECT_TRUE(passesDepthTest(DepthFunc::Less, key - 1, hi, key, lo));
  EXPECT_FALSE(passesDepthTest(DepthFunc::LEqual, key + 1, hi, key, lo));
}

struct Prepared {
  Camera camera;
  SampleGrid grid;
  std::vector<TriangleSetup> setups;
};

// Coplanar and crossing quads at view depth ~2, 32×32, 4 spp.
Prepared prepare(const Scene& scene, DepthFormat format, double factor, double units) {
  Prepared p{test::perspectiveCamera(32, 32, 1.0, glm::dvec3(0), glm::dvec3(0, 0, -1), 0.1), {}, {}};
  p.grid = makeSampleGrid(4, 32, 32);
  const ClipSpace space = makeClipSpace(p.camera, p.grid.guardPixels);
  const DepthSettings ds{format, p.camera.projection, p.camera.znear, p.camera.zfar, factor, units};
  SetupCounters n;
  p.setups = prepareTriangles(scene, space, p.grid, ds, CullMode::None, {}, &n);
  return p;
}

DepthTarget rasterize(const Prepared& p, std::vector<uint32_t> order, DepthFunc func, DepthFormat format) {
  DepthTarget target(32, 32, 4);
  DepthPassCounters n;
  rasterDepthPass(p.setups, order, p.grid, TileRect{0, 0, 32, 32}, format, func, {}, TraceRequest{}, &target,
                  &n);
  return target;
}

Scene overlappingScene() {
  Scene scene;
  // Instance 0 and 1: the same tilted quad (exact depth ties); instance 2 crosses them.
  const std::vector<glm::vec3> quad = {{-2, -2, -1.5}, {2, -2, -1.5}, {2, 2, -2.5}, {-2, 2, -2.5}};
  const std::vector<glm::uvec3> two = {{0, 1, 2}, {0, 2, 3}};
  test::addMesh(scene, quad, two, test::colored(glm::vec4(1, 0, 0, 1)));
  test::addMesh(scene, quad, two, test::colored(glm::vec4(0, 1, 0, 1)));
  test::addMesh(scene, {{-2, -2, -2.5}, {2, -2, -2.5}, {2, 2, -1.5}, {-2, 2, -1.5}}, two,
                test::colored(glm::vec4(0, 0, 1, 1)));
  return scene;
}

RASTRAY_TEST_LABELS_OF(DepthTest, RandomSubmissionOrdersGiveIdenticalBuffers, "threads");
TEST(DepthTest, RandomSubmissionOrdersGiveIdenticalBuffers) {
  const Scene scene = overlappingScene();
  std::mt19937 rng(11);
  for (DepthFormat format : kFormats)
    for (DepthFunc func : {DepthFunc::Less, DepthFunc::LEqual}) {
      const Prepared p = prepare(scene, format, 0, 0);
      std::vector<uint32_t> order(p.setups.size());
      std::iota(order.begin(), order.end(), 0u);
      const DepthTarget ref = rasterize(p, order, func, format);
      for (int trial = 0; trial < 6; ++trial) {
        std::shuffle(order.begin(), order.end(), rng);
        const DepthTarget t = rasterize(p, order, func, format);
        ASSERT_EQ(t.keys, ref.keys);
        ASSERT_EQ(t.winners, ref.winners) << toString(format) << " " << toString(func);
      }
      // The tie between instances 0 and 1 goes by the rule.
      bool sawTie = false;
      for (uint32_t w : ref.winners)
        if (w != kNoSetup && p.setups[w].instance != 2) {
          EXPECT_EQ(p.setups[w].instance, func == DepthFunc::Less ? 0u : 1u);
          sawTie = true;
        }
      EXPECT_TRUE(sawTie);
    }
}

RASTRAY_TEST_LABELS_OF(PolygonOffset, UnitsAndFactorMoveCoplanarSurfaces, "threads");
TEST(PolygonOffset, UnitsAndFactorMoveCoplanarSurfaces) {
  // Instance 0 alone, then instance 1 set up with an offset: negative pulls
  // it in front of its coplanar twin, positive pushes it behind.
  Scene a, b;
  const std::vector<glm::vec3> quad = {{-2, -2, -1.5}, {2, -2, -1.5}, {2, 2, -2.5}, {-2, 2, -2.5}};
  test::addMesh(a, quad, {{0, 1, 2}, {0, 2, 3}});
  for (DepthFormat format : kFormats) {
    const Prepared base = prepare(a, format, 0, 0);
    for (double units : {-1.0, 1.0}) {
      const Prepared off = prepare(a, format, 0, units);
      const Prepared slope = prepare(a, format, units, 0);
      ASSERT_EQ(base.setups.size(), off.setups.size());
      for (size_t i = 0; i < base.setups.size(); ++i) {
        const double z = base.setups[i].depth.v0, zo = off.setups[i].depth.v0, zs = slope.setups[i].depth.v0;
        const double away = isReversed(format) ? z - zo : zo - z;  // > 0: pushed away from the viewer
        const double maxZ = std::max({z, base.setups[i].depth.at(0, 0), base.setups[i].depth.at(32, 32)});
        (void)maxZ;
        EXPECT_GT(away * units, 0.0) << toString(format);
        EXPECT_NEAR(std::abs(isReversed(format) ? z - zs : zs - z), base.setups[i].maxDepthSlope(), 1e-15);
      }
      // Rasterized against the un-offset copy: offset −1 unit wins every sample, +1 none.
      std::vector<TriangleSetup> both = base.setups;
      for (TriangleSetup t : off.setups) {
        t.instance = 1;
        both.push_back(t);
      }
      Prepared combined{base.camera, base.grid, both};
      std::vector<uint32_t> order(both.size());
      std::iota(order.begin(), order.end(), 0u);
      const DepthTarget t = rasterize(combined, order, DepthFunc::Less, format);
      size_t covered = 0, won = 0;
      for (uint32_t w : t.winners) {
        if (w == kNoSetup) continue;
        ++covered;
        won += combined.setups[w].instance == 1;
      }
      ASSERT_GT(covered, 0u);
      EXPECT_EQ(won, units < 0 ? covered : size_t(0)) << toString(format);
    }
  }
}

}  // namespace
}  // namespace rastray
