// The stability study's geometry cases (app/studies/stability_cases_geometry.cpp)
// run in process: every row is held to the bounds written here (and to the
// study's own verdict). Plus the
// exact top-left reference the tiling case checks the rasterizer against,
// on hand-made ties, and the generators' determinism.

#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>

#include <gtest/gtest.h>

#include "app/studies/stability.h"
#include "app/studies/stability_coverage.h"
#include "app/studies/stability_geometry_scenes.h"
#include "tests/app/stability_bounds.h"

#include "tests/test_files.h"
#include "tests/test_labels.h"

// Each case renders its variants on 2 threads for seconds (threads, slow), except those marked quick.
RASTRAY_TEST_LABELS("threads", "slow");

namespace rastray::stability {
namespace {

Case findCase(const std::string& name) {
  std::vector<Case> cases;
  appendGeometryCases(cases);
  for (const Case& c : cases)
    if (c.name == name) return c;
  ADD_FAILURE() << "no case " << name;
  return {};
}

using test::expectNoGenuine;
using test::expectShadowBound;
using test::isVariant;
using test::measure;
using test::where;

// Writes the case's scene to a temp folder, runs every variant (not the
// --quick subset) and holds every row to `bounds` (stability_bounds.h).
void runCase(const std::string& name, const std::function<void(const Row&)>& bounds) {
  const Case c = findCase(name);
  ASSERT_TRUE(c.build && c.run);
  const std::filesystem::path dir = rastray::test::scratchDir();
  const std::string path = (dir / (c.name + ".gltf")).string();
  c.build().write(path);
  CaseContext ctx;
  ctx.sceneDir = dir.string();
  ctx.threads = 2;
  ctx.progress = [](const std::string& line) { std::printf("  %s\n", line.c_str()); };
  const std::vector<Row> rows = c.run(ctx, path);
  for (const Row& r : rows)
    std::printf("%s | %s | agree %.6f genuine %lld nan/inf %llu | %s = %g | %.2f s\n", r.caseName.c_str(),
                r.variant.c_str(), r.agreement, (long long)r.genuine, (unsigned long long)r.nanInf,
                r.metricName.c_str(), r.metric, r.seconds);
  test::expectRows(rows, bounds);
}

// Hybrid shades with the ray caster's inputs where hits agree: its colour
// there is the ray caster's to 1e-5 (crossval's --max-hybrid-error).
void expectHybridColour(const Row& r) {
  if (isVariant(r, "hybrid vs raytrace")) {
    EXPECT_LE(r.metric, 1e-5) << where(r);
  }
}

TEST(StabilityGeometry, SubpixelTrianglesAgreeWithTheRayCaster) {
  runCase("subpixel-sphere-dust", expectNoGenuine);
}

TEST(StabilityGeometry, SliverFanIsWatertightUpToAspect1e6) {
  runCase("sliver-fan-aspect-1e6", [](const Row& r) {
    expectNoGenuine(r);
    EXPECT_EQ(r.metric, 0.0) << where(r) << ": " << r.metricName;  // holes + double coverage, both renderers
  });
}

TEST(StabilityGeometry, PixelAlignedTilingFollowsTheTopLeftRule) {
  runCase("pixel-aligned-tiling", [](const Row& r) {
    // The ray caster's own tie decisions are shown, not held (SPEC lets it
    // pick either triangle of a shared edge).
    if (isVariant(r, "raytrace ties")) return;
    expectNoGenuine(r);
    EXPECT_EQ(r.metric, 0.0) << where(r) << ": " << r.metricName;  // owner differs from the top-left one
    EXPECT_EQ(measure(r, "interior samples not covered once (this renderer)"), 0.0) << where(r);
    EXPECT_EQ(measure(r, "interior samples not covered once (ray caster)"), 0.0) << where(r);
  });
}

TEST(StabilityGeometry, GrazingTexturedPlaneHasFiniteFootprints) {
  runCase("grazing-textured-89.9", [](const Row& r) {
    expectNoGenuine(r);
    expectHybridColour(r);
    if (isVariant(r, "raster vs raytrace")) {
      EXPECT_EQ(measure(r, "non-finite texture LODs"), 0.0) << where(r);
    }
  });
}

TEST(StabilityGeometry, GrazingLitPlaneAgreesWithTheRayCaster) {
  runCase("grazing-lit-89.9", [](const Row& r) {
    expectNoGenuine(r);
    expectHybridColour(r);
    // The plain view, both renderers: both lights' shadows against the
    // double reference, with the grazing light's shadow kept.
    if (r.variant == "raster vs raytrace" || r.variant == "hybrid vs raytrace") {
      expectShadowBound(r);
      EXPECT_EQ(measure(r, "lights checked"), 2.0) << where(r);
      EXPECT_GE(measure(r, "samples checked in the grazing light's shadow"), 1000.0) << where(r);
    }
  });
}

// The scaled scene renders like the unit one: fewer than 1e-3 of its pixels
// off by more than 0.1, and shadow maps within their bias bound at every
// scale. The RTG offset's absolute constants are not scale-free: that row
// is shown, not held.
void expectLikeTheUnitScene(const Row& r) {
  if (isVariant(r, "raytrace ray-offset=float-ulps")) return;
  expectNoGenuine(r);
  EXPECT_LT(r.metric, 1e-3) << where(r) << ": " << r.metricName;
  if (isVariant(r, "raster")) expectShadowBound(r);
}

TEST(StabilityGeometry, SceneAt1e4RendersLikeTheUnitScene) { runCase("scale-1e4", expectLikeTheUnitScene); }
TEST(StabilityGeometry, SceneAt1eMinus4RendersLikeTheUnitScene) {
  runCase("scale-1e-4", expectLikeTheUnitScene);
}

// The reference itself, on ties decided by hand (image y down; the frame's
// world y is up): a right triangle with a horizontal top edge and a
// vertical left edge owns samples on those, not on its hypotenuse.
RASTRAY_TEST_LABELS_OF(StabilityGeometry, TopLeftReferenceOnHandMadeTies, "quick");
TEST(StabilityGeometry, TopLeftReferenceOnHandMadeTies) {
  const PixelFrame frame{8, 8};
  // Image corners (2, 2), (6, 2), (2, 6): top edge y = 2, left edge x = 2,
  // hypotenuse x + y = 8 (a bottom-right edge).
  const std::array<glm::dvec2, 3> t = {frame.world({2, 2}), frame.world({6, 2}), frame.world({2, 6})};
  const std::array<glm::dvec2, 3> reversed = {t[0], t[2], t[1]};
  for (const auto& tri : {t, reversed}) {
    EXPECT_TRUE(ownsByTopLeft(frame, tri, frame.world({3, 2})));     // top edge
    EXPECT_TRUE(ownsByTopLeft(frame, tri, frame.world({2, 3})));     // left edge
    EXPECT_TRUE(ownsByTopLeft(frame, tri, frame.world({2, 2})));     // top-left vertex
    EXPECT_FALSE(ownsByTopLeft(frame, tri, frame.world({4, 4})));    // hypotenuse
    EXPECT_FALSE(ownsByTopLeft(frame, tri, frame.world({6, 2})));    // vertex on top and hypotenuse
    EXPECT_TRUE(ownsByTopLeft(frame, tri, frame.world({3, 3})));     // inside
    EXPECT_FALSE(ownsByTopLeft(frame, tri, frame.world({1.5, 3})));  // outside
  }
  // The other half of the square owns the hypotenuse: bottom and right edges
  // are not its own, so a sample there is owned exactly once.
  const std::array<glm::dvec2, 3> other = {frame.world({6, 2}), frame.world({6, 6}), frame.world({2, 6})};
  EXPECT_TRUE(ownsByTopLeft(frame, other, frame.world({4, 4})));
  EXPECT_FALSE(ownsByTopLeft(frame, other, frame.world({6, 4})));  // right edge
  EXPECT_FALSE(ownsByTopLeft(frame, other, frame.world({4, 6})));  // bottom edge
}

RASTRAY_TEST_LABELS_OF(StabilityGeometry, GeneratorsAreDeterministic, "quick");
TEST(StabilityGeometry, GeneratorsAreDeterministic) {
  EXPECT_EQ(subpixelScene(64, 100, 9).toJson(), subpixelScene(64, 100, 9).toJson());
  EXPECT_NE(subpixelScene(64, 100, 9).toJson(), subpixelScene(64, 100, 10).toJson());
  TilingLayout a, b;
  EXPECT_EQ(pixelAlignedScene(&a, 3).toJson(), pixelAlignedScene(&b, 3).toJson());
}

}  // namespace
}  // namespace rastray::stability
