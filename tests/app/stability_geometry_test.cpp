// The stability study's geometry cases (app/studies/stability_cases_geometry.cpp)
// run in process: each case's every row must hold its property. Plus the
// exact top-left reference the tiling case checks the rasterizer against,
// on hand-made ties, and the generators' determinism.
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "app/studies/stability.h"
#include "app/studies/stability_coverage.h"
#include "app/studies/stability_geometry_scenes.h"

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

// Writes the case's scene to a temp folder, runs every variant (not the
// --quick subset) and checks every row.
void runCase(const std::string& name) {
  const Case c = findCase(name);
  ASSERT_TRUE(c.build && c.run);
  const auto dir = std::filesystem::temp_directory_path() / ("rastray-geometry-" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / (c.name + ".gltf")).string();
  c.build().write(path);
  CaseContext ctx;
  ctx.sceneDir = dir.string();
  ctx.threads = 2;
  ctx.progress = [](const std::string& line) { std::printf("  %s\n", line.c_str()); };
  const std::vector<Row> rows = c.run(ctx, path);
  std::filesystem::remove_all(dir);
  ASSERT_FALSE(rows.empty());
  for (const Row& r : rows) {
    std::printf("%s | %s | agree %.6f genuine %lld nan/inf %llu | %s = %g | %.2f s\n", r.caseName.c_str(),
                r.variant.c_str(), r.agreement, (long long)r.genuine, (unsigned long long)r.nanInf,
                r.metricName.c_str(), r.metric, r.seconds);
    EXPECT_TRUE(r.pass) << r.caseName << " / " << r.variant << ": " << r.property << " (" << r.metricName
                        << " = " << r.metric << ", genuine " << r.genuine << ", NaN/Inf " << r.nanInf << ")";
  }
}

TEST(StabilityGeometry, SubpixelTrianglesAgreeWithTheRayCaster) { runCase("subpixel-sphere-dust"); }
TEST(StabilityGeometry, SliverFanIsWatertightUpToAspect1e6) { runCase("sliver-fan-aspect-1e6"); }
TEST(StabilityGeometry, PixelAlignedTilingFollowsTheTopLeftRule) { runCase("pixel-aligned-tiling"); }
TEST(StabilityGeometry, GrazingTexturedPlaneHasFiniteFootprints) { runCase("grazing-textured-89.9"); }
TEST(StabilityGeometry, GrazingLitPlaneAgreesWithTheRayCaster) { runCase("grazing-lit-89.9"); }
TEST(StabilityGeometry, SceneAt1e4RendersLikeTheUnitScene) { runCase("scale-1e4"); }
TEST(StabilityGeometry, SceneAt1eMinus4RendersLikeTheUnitScene) { runCase("scale-1e-4"); }

// The reference itself, on ties decided by hand (image y down; the frame's
// world y is up): a right triangle with a horizontal top edge and a
// vertical left edge owns samples on those, not on its hypotenuse.
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

TEST(StabilityGeometry, GeneratorsAreDeterministic) {
  EXPECT_EQ(subpixelScene(64, 100, 9).toJson(), subpixelScene(64, 100, 9).toJson());
  EXPECT_NE(subpixelScene(64, 100, 9).toJson(), subpixelScene(64, 100, 10).toJson());
  TilingLayout a, b;
  EXPECT_EQ(pixelAlignedScene(&a, 3).toJson(), pixelAlignedScene(&b, 3).toJson());
}

}  // namespace
}  // namespace rastray::stability
