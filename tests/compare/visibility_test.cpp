// Visibility agreement over whole frames: counts, fractions, classes and
// depth statistics on known differences, flat and deep, with and without
// the scene.
#include "compare/visibility.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/error.h"
#include "common/gltf/loader.h"
#include "frames.h"

namespace rastray {
namespace {

using test::setEmpty;
using test::setHit;
using test::threeTrianglesFrame;

class ThreeTriangles : public ::testing::Test {
 protected:
  void SetUp() override {
    scene = loadScene(test::scenePath("three-triangles.gltf"));
    camera = makeCamera(scene, {}, 8, 8);
    geometric.scene = &scene;
    geometric.camera = &camera;
    geometric.planes = {true, camera.projection, camera.znear, camera.zfar};
  }
  Scene scene;
  Camera camera;
  ClassifierSettings geometric;
};

uint64_t hitCount(const FlatImage& f) {
  uint64_t n = 0;
  for (uint32_t id : f.instance) n += id != kNoId;
  return n;
}

TEST_F(ThreeTriangles, IdenticalFramesAgreeEverywhere) {
  const FlatImage a = threeTrianglesFrame();
  const VisibilityReport r = compareVisibility(a, a, 1, geometric);
  EXPECT_EQ(r.samples.compared, 64u);
  EXPECT_EQ(r.samples.agreeing, 64u);
  EXPECT_EQ(r.samples.bothEmpty, 64u - hitCount(a));
  EXPECT_DOUBLE_EQ(r.samples.agreement(), 1.0);
  EXPECT_EQ(r.depth.count, hitCount(a));
  EXPECT_EQ(r.depth.maxAbsolute, 0.0);
  EXPECT_TRUE(r.geometric);
}

TEST_F(ThreeTriangles, EachClassCountedAtItsPixel) {
  const FlatImage a = threeTrianglesFrame();
  FlatImage b = a;
  ASSERT_EQ(a.instance[a.index(4, 4)], 0u);                             // yellow, ≥ 0.22 px from every edge
  ASSERT_EQ(a.instance[a.index(5, 5)], 0u);                             // yellow, on its bottom edge
  setHit(b, 5, 5, 1, 0, 0.75f);                                         // silhouette edge
  setHit(b, 4, 4, 2, 0, 0.25f);                                         // genuine: red is not in front there
  setHit(b, 3, 4, 1, 0, std::nextafter(a.depth[a.index(3, 4)], 1.0f));  // depth tie with red
  setEmpty(b, 4, 3);  // …and A claims near plane at (4, 3) below
  FlatImage a2 = a;
  setHit(a2, 4, 3, 0, 0, 0.125f);
  const VisibilityReport r = compareVisibility(a2, b, 1, geometric);
  EXPECT_EQ(r.samples.compared, 64u);
  EXPECT_EQ(r.samples.mismatching(), 4u);
  EXPECT_DOUBLE_EQ(r.samples.agreement(), 60.0 / 64.0);
  EXPECT_EQ(r.samples.count(MismatchClass::SilhouetteEdge), 1u);
  EXPECT_EQ(r.samples.count(MismatchClass::Genuine), 1u);
  EXPECT_EQ(r.samples.count(MismatchClass::DepthTie), 1u);
  EXPECT_EQ(r.samples.count(MismatchClass::NearFarPlane), 1u);
  EXPECT_EQ(r.samples.count(MismatchClass::SharedEdgeTie), 0u);
  EXPECT_DOUBLE_EQ(r.samples.fraction(MismatchClass::Genuine), 1.0 / 64.0);
  ASSERT_TRUE(r.examples[size_t(MismatchClass::Genuine)]);
  EXPECT_EQ(r.examples[size_t(MismatchClass::Genuine)]->x, 4);
  EXPECT_EQ(r.examples[size_t(MismatchClass::Genuine)]->y, 4);
  EXPECT_EQ(r.examples[size_t(MismatchClass::Genuine)]->sample, 0);
  EXPECT_EQ(r.pixels[a.index(4, 4)], PixelVisibility::Genuine);
  EXPECT_EQ(r.pixels[a.index(5, 5)], PixelVisibility::SilhouetteEdge);
  EXPECT_EQ(r.pixels[a.index(0, 0)], PixelVisibility::BothEmpty);
  EXPECT_EQ(r.pixels[a.index(2, 5)], PixelVisibility::Agree);
}

TEST_F(ThreeTriangles, CentreSampleOfTheGivenPatternIsUsed) {
  // At 2 spp the sample nearest the centre is (0.75, 0.75): ¼ px right and
  // down of the centre. Pixel (5, 5)'s centre lies on yellow's bottom edge;
  // its 2-spp centre sample lies ¼ px below it: beyond 1/16 px, genuine.
  const FlatImage a = threeTrianglesFrame();
  FlatImage b = a;
  setHit(b, 5, 5, 1, 0, 0.75f);
  EXPECT_EQ(compareVisibility(a, b, 1, geometric).samples.count(MismatchClass::SilhouetteEdge), 1u);
  EXPECT_EQ(compareVisibility(a, b, 2, geometric).samples.count(MismatchClass::Genuine), 1u);
}

TEST_F(ThreeTriangles, DepthErrorStatistics) {
  const FlatImage a = threeTrianglesFrame();
  FlatImage b = a;
  const size_t i = a.index(4, 4);  // yellow at depth 0.5
  b.depth[i] = 0.5f + 0.03125f;    // exact in float: |ΔZ| = 1/32
  const VisibilityReport r = compareVisibility(a, b, 1, geometric);
  EXPECT_EQ(r.samples.mismatching(), 0u);
  EXPECT_EQ(r.depth.maxAbsolute, 0.03125);
  EXPECT_EQ(r.depth.maxAbsoluteX, 4);
  EXPECT_EQ(r.depth.maxAbsoluteY, 4);
  EXPECT_DOUBLE_EQ(r.depth.meanAbsolute, 0.03125 / double(hitCount(a)));
  EXPECT_DOUBLE_EQ(r.depth.maxRelative, 0.03125 / 0.53125);
  EXPECT_DOUBLE_EQ(r.depth.meanRelative, 0.03125 / 0.53125 / double(hitCount(a)));
  EXPECT_FLOAT_EQ(r.pixelDepthError[i], 0.03125f);
}

TEST_F(ThreeTriangles, ScenesRequireTheSampleCountAndMatchingIds) {
  const FlatImage a = threeTrianglesFrame();
  EXPECT_THROW(compareVisibility(a, a, 0, geometric), InputError);
  EXPECT_THROW(compareVisibility(a, a, 3, geometric), InputError);
  FlatImage bad = a;
  setHit(bad, 4, 4, 7, 0, 0.5f);
  try {
    compareVisibility(a, bad, 1, geometric, {"a.exr", "b.exr"});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), "b.exr");
    EXPECT_EQ(e.element(), "pixel (4, 4)");
  }
  FlatImage small(4, 4);
  EXPECT_THROW(compareVisibility(a, small, 1, ClassifierSettings{}), InputError);
}

TEST(ImageSpace, EdgeShiftIsSilhouetteSpeckleIsGenuine) {
  // A: left half instance 0, right half empty; B: the boundary one pixel
  // further right (a silhouette shift), plus a lone speckle of instance 5.
  FlatImage a(8, 8);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 4; ++x) setHit(a, x, y, 0, 0, 0.5f);
  FlatImage b = a;
  for (int y = 0; y < 8; ++y) setHit(b, 4, y, 0, 0, 0.5f);
  setHit(b, 1, 1, 5, 0, 0.4f);
  const VisibilityReport r = compareVisibility(a, b, 0, ClassifierSettings{});
  EXPECT_FALSE(r.geometric);
  EXPECT_EQ(r.samples.count(MismatchClass::SilhouetteEdge), 8u);
  EXPECT_EQ(r.samples.count(MismatchClass::Genuine), 1u);
  EXPECT_EQ(r.examples[size_t(MismatchClass::Genuine)]->x, 1);
}

TEST(ImageSpace, SameInstanceEdgeIsSharedEdgeTie) {
  // Triangles 0 and 1 of instance 0 meet between columns 3 and 4; B moves
  // the boundary by one column.
  FlatImage a(8, 8);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) setHit(a, x, y, 0, x < 4 ? 0 : 1, 0.5f + 0.01f * float(x));
  FlatImage b = a;
  for (int y = 0; y < 8; ++y) setHit(b, 4, y, 0, 0, 0.54f);
  const VisibilityReport r = compareVisibility(a, b, 0, ClassifierSettings{});
  EXPECT_EQ(r.samples.count(MismatchClass::SharedEdgeTie), 8u);
  EXPECT_EQ(r.samples.mismatching(), 8u);
}

DeepImage deepFrame(int width, int height, const std::vector<std::vector<DeepSample>>& pixels) {
  DeepImage d;
  d.width = width;
  d.height = height;
  d.offsets.push_back(0);
  for (const auto& p : pixels) {
    for (const DeepSample& s : p) d.samples.push_back(s);
    d.offsets.push_back(uint32_t(d.samples.size()));
  }
  return d;
}

DeepSample layer(uint32_t sample, uint32_t instance, float depth) {
  DeepSample s;
  s.sample = sample;
  s.instance = instance;
  s.triangle = 0;
  s.depth = depth;
  s.color = {0.25f, 0.25f, 0.25f, 0.5f};
  return s;
}

TEST(Deep, SamplesAndLayersCountedSeparately) {
  // 2×1 pixels at 4 spp. Pixel 0: sample 0 two layers in A, one in B (the
  // back one missing); sample 1 agrees; samples 2, 3 empty in both (B lists
  // sample 3 as a background entry, which is not a layer).
  // Pixel 1: sample 0 front layer differs; others empty.
  DeepSample background = layer(3, kNoId, std::numeric_limits<float>::infinity());
  background.triangle = kNoId;
  const DeepImage a =
      deepFrame(2, 1, {{layer(0, 0, 0.3f), layer(0, 1, 0.6f), layer(1, 0, 0.3f)}, {layer(0, 0, 0.3f)}});
  const DeepImage b =
      deepFrame(2, 1, {{layer(0, 0, 0.3f), layer(1, 0, 0.3f), background}, {layer(0, 2, 0.7f)}});
  const VisibilityReport r = compareVisibility(a, b, 4, ClassifierSettings{});
  EXPECT_TRUE(r.deep);
  EXPECT_EQ(r.spp, 4);
  EXPECT_EQ(r.samples.compared, 8u);
  EXPECT_EQ(r.samples.agreeing, 7u);  // pixel 1 sample 0 differs
  EXPECT_EQ(r.samples.bothEmpty, 5u);
  // Layers: pixel 0 sample 0 has 2 (one mismatch), every other sample 1.
  EXPECT_EQ(r.layers.compared, 9u);
  EXPECT_EQ(r.layers.agreeing, 7u);
  ASSERT_TRUE(r.examples[size_t(MismatchClass::Genuine)] ||
              r.examples[size_t(MismatchClass::SilhouetteEdge)]);
  bool sawBackLayer = false;
  for (const auto& e : r.examples)
    if (e && e->x == 0) sawBackLayer = e->layer == 1 && e->sample == 0 && e->a.instance == 1 && !e->b.isHit();
  EXPECT_TRUE(sawBackLayer);
  // Inferred spp: largest index 3 → 4.
  EXPECT_EQ(compareVisibility(a, b, 0, ClassifierSettings{}).spp, 4);
  // An index beyond the given spp is bad input.
  EXPECT_THROW(compareVisibility(a, b, 2, ClassifierSettings{}), InputError);
}

TEST_F(ThreeTriangles, DeepSamplesUseTheirOwnPositions) {
  // 8×8 at 4 spp; only pixel (5, 5) holds samples. Its sample positions
  // (D3D 4x: (0.375, 0.125), (0.875, 0.375), (0.125, 0.625), (0.625, 0.875))
  // lie 3/8, 1/8, 1/8 and 3/8 px from row 5's centre line y = 5.5, where
  // yellow's bottom edge runs: all beyond 1/16 px, so mismatches there are
  // genuine; an edge distance of 0.2 px makes samples 1 and 2 edge cases.
  std::vector<std::vector<DeepSample>> pa(64), pb(64);
  for (uint32_t s = 0; s < 4; ++s) {
    pa[5 * 8 + 5].push_back(layer(s, 0, 0.5f));
    pb[5 * 8 + 5].push_back(layer(s, 1, 0.75f));
  }
  const DeepImage a = deepFrame(8, 8, pa), b = deepFrame(8, 8, pb);
  EXPECT_EQ(compareVisibility(a, b, 4, geometric).samples.count(MismatchClass::Genuine), 4u);
  ClassifierSettings wide = geometric;
  wide.edgeDistance = 0.2;
  const VisibilityReport r = compareVisibility(a, b, 4, wide);
  EXPECT_EQ(r.samples.count(MismatchClass::SilhouetteEdge), 2u);
  EXPECT_EQ(r.samples.count(MismatchClass::Genuine), 2u);
  EXPECT_THROW(compareVisibility(a, b, 0, geometric), InputError);  // a scene needs --spp
}

}  // namespace
}  // namespace rastray
