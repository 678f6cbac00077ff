#include <gtest/gtest.h>

#include <algorithm>

#include "common/gltf/loader.h"
#include "raster/rasterizer.h"
#include "raster/resolve.h"
#include "raster_test_util.h"

#include "tests/test_labels.h"

// Tests here render on 2 or more threads (the ThreadSanitizer stage runs them), except those marked quick.
RASTRAY_TEST_LABELS("threads");

namespace rastray {
namespace {

using test::addMesh;
using test::colored;

RASTRAY_TEST_LABELS_OF(Over, PremultipliedRedOverRedAndNotCommutative, "quick");
TEST(Over, PremultipliedRedOverRedAndNotCommutative) {
  const glm::vec4 red(0.5f, 0.0f, 0.0f, 0.5f);  // 50 % bright red, premultiplied
  EXPECT_EQ(over(red, red), glm::vec4(0.75f, 0.0f, 0.0f, 0.75f));
  const glm::vec4 blue(0.0f, 0.0f, 1.0f, 1.0f);
  EXPECT_NE(over(red, blue), over(blue, red));
  EXPECT_EQ(over(red, blue), glm::vec4(0.5f, 0.0f, 0.5f, 1.0f));
}

Scene twoRedSheets() {
  Scene scene;
  const std::vector<glm::uvec3> quad = {{0, 1, 2}, {0, 2, 3}};
  for (float z : {-1.0f, -2.0f})
    addMesh(scene, {{-1, -1, z}, {1, -1, z}, {1, 1, z}, {-1, 1, z}}, quad,
            colored(glm::vec4(1, 0, 0, 0.5f), AlphaMode::Blend, true));
  return scene;
}

TEST(Transparency, FiftyPercentRedOverFiftyPercentRedRenders075) {
  const Scene scene = twoRedSheets();
  const Camera camera = test::orthoCamera(8, 2.0, 0.0, 10.0);
  for (TransparencyMode mode : {TransparencyMode::Exact, TransparencyMode::Sorted, TransparencyMode::Peel}) {
    RasterOptions o;
    o.transparency = mode;
    o.spp = 4;
    o.keepSamples = true;
    const RenderOutput out = test::render(scene, camera, o);
    // The eye light faces the sheets head on: each layer is (0.5, 0, 0, 0.5).
    const glm::vec4 c = out.image.color[out.image.index(4, 4)];
    EXPECT_NEAR(c.r, 0.75f, 1e-6f);
    EXPECT_EQ(c.g, 0.0f);
    EXPECT_NEAR(c.a, 0.75f, 1e-6f);
    // Deep: two layers per sample, front (instance 0, depth 1) first.
    const size_t p = out.image.index(4, 4);
    ASSERT_EQ(out.samples.offsets[p + 1] - out.samples.offsets[p], 8u);
    const DeepSample& first = out.samples.samples[out.samples.offsets[p]];
    EXPECT_EQ(first.instance, 0u);
    EXPECT_FLOAT_EQ(first.depth, 1.0f);
    EXPECT_EQ(out.image.instance[p], 0u);  // Z/ids: the front-most layer
    EXPECT_GT(out.counters.get("raster.fragments_transparent"), 0u);
  }
}

TEST(Transparency, SortedIsWrongOnCyclicOverlapWhileExactIsRight) {
  const Scene scene = loadScene(test::scenePath("cyclic-overlap.gltf"));
  const Camera camera = makeCamera(scene, CameraOverrides{}, 96, 96);
  RasterOptions o;
  o.keepSamples = true;
  size_t wrongSorted = 0, wrongExact = 0, multi = 0, colourDiffs = 0;
  o.transparency = TransparencyMode::Exact;
  const RenderOutput exact = test::render(scene, camera, o);
  o.transparency = TransparencyMode::Sorted;
  const RenderOutput sorted = test::render(scene, camera, o);
  o.transparency = TransparencyMode::Peel;
  o.peelLayers = 3;
  const RenderOutput peel = test::render(scene, camera, o);
  const auto misordered = [](const DeepImage& d, size_t p) {
    for (uint64_t k = d.offsets[p] + 1; k < d.offsets[p + 1]; ++k)
      if (d.samples[k].sample == d.samples[k - 1].sample && d.samples[k].depth < d.samples[k - 1].depth)
        return true;
    return false;
  };
  for (size_t p = 0; p < exact.image.color.size(); ++p) {
    multi += exact.samples.offsets[p + 1] - exact.samples.offsets[p] > 1;
    wrongExact += misordered(exact.samples, p);
    wrongSorted += misordered(sorted.samples, p);
    colourDiffs += glm::length(exact.image.color[p] - sorted.image.color[p]) > 0.05f;
    EXPECT_EQ(exact.image.color[p], peel.image.color[p]) << p;  // 3 layers suffice here
  }
  EXPECT_GT(multi, 20u);
  EXPECT_EQ(wrongExact, 0u);
  EXPECT_GT(wrongSorted, 0u);
  EXPECT_GT(colourDiffs, 0u);
}

TEST(Transparency, PeelingWithFewLayersDropsTheBackOnes) {
  const Scene scene = twoRedSheets();
  const Camera camera = test::orthoCamera(8, 2.0, 0.0, 10.0);
  RasterOptions o;
  o.transparency = TransparencyMode::Peel;
  o.peelLayers = 1;
  const RenderOutput out = test::render(scene, camera, o);
  EXPECT_NEAR(out.image.color[out.image.index(4, 4)].a, 0.5f, 1e-6f);
}

TEST(Transparency, BlendBehindOpaqueIsHiddenAndOpaqueComesLastInDeep) {
  Scene scene = twoRedSheets();
  addMesh(scene, {{-1, -1, -1.5f}, {1, -1, -1.5f}, {1, 1, -1.5f}, {-1, 1, -1.5f}}, {{0, 1, 2}, {0, 2, 3}},
          colored(glm::vec4(0, 0, 1, 1)));
  const Camera camera = test::orthoCamera(8, 2.0, 0.0, 10.0);
  RasterOptions o;
  o.keepSamples = true;
  const RenderOutput out = test::render(scene, camera, o);
  const size_t p = out.image.index(4, 4);
  EXPECT_NEAR(out.image.color[p].r, 0.5f, 1e-6f);
  EXPECT_NEAR(out.image.color[p].b, 0.5f, 1e-6f);
  EXPECT_EQ(out.image.color[p].a, 1.0f);
  ASSERT_EQ(out.samples.offsets[p + 1] - out.samples.offsets[p], 2u);
  EXPECT_EQ(out.samples.samples[out.samples.offsets[p]].instance, 0u);
  EXPECT_EQ(out.samples.samples[out.samples.offsets[p] + 1].instance, 2u);
}

}  // namespace
}  // namespace rastray
