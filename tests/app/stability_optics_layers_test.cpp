// The stability study's glass and layer cases (app/studies/stability_cases_optics.cpp,
// app/studies/stability_cases_layers.cpp) run in process: every row of each case is
// held to the bounds written here, and to the study's own verdict (the TIR band within a pixel of its
// analytic position, nested glass within its energy and on-axis bounds, trapped rays ending at
// --max-depth, stacked layers matching the analytic composite, clipped and
// degenerate triangles), and the generators are deterministic.

#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>

#include <gtest/gtest.h>

#include "app/studies/stability.h"
#include "tests/app/stability_bounds.h"

#include "tests/test_files.h"
#include "tests/test_labels.h"

// Each case renders its variants on 2 threads for seconds (threads, slow), except those marked quick.
RASTRAY_TEST_LABELS("threads", "slow");

namespace rastray::stability {
namespace {

Case findCase(const std::string& name) {
  std::vector<Case> cases;
  appendOpticsCases(cases);
  appendLayerCases(cases);
  for (const Case& c : cases)
    if (c.name == name) return c;
  ADD_FAILURE() << "no case " << name;
  return {};
}

using test::expectNoGenuine;
using test::isVariant;
using test::measure;
using test::where;

// Writes the case's scene to a temp folder, runs it (every variant, or the
// --quick subset) and holds every row to `bounds` (stability_bounds.h).
void runCase(const std::string& name, const std::function<void(const Row&)>& bounds, bool quick = false) {
  const Case c = findCase(name);
  ASSERT_TRUE(c.build && c.run);
  const std::filesystem::path dir = rastray::test::scratchDir();
  const std::string path = (dir / (c.name + ".gltf")).string();
  c.build().write(path);
  CaseContext ctx;
  ctx.sceneDir = dir.string();
  ctx.quick = quick;
  ctx.threads = 2;
  ctx.progress = [](const std::string& line) { std::printf("  %s\n", line.c_str()); };
  const std::vector<Row> rows = c.run(ctx, path);
  for (const Row& r : rows)
    std::printf("%s | %s | agree %.6f genuine %lld nan/inf %llu | %s = %.9g | %.2f s\n", r.caseName.c_str(),
                r.variant.c_str(), r.agreement, (long long)r.genuine, (unsigned long long)r.nanInf,
                r.metricName.c_str(), r.metric, r.seconds);
  test::expectRows(rows, bounds);
}

// Within one pixel of the analytic band, and a band at all.
TEST(StabilityOptics, TirBandOfABubbleLiesWithinAPixelOfItsAnalyticPosition) {
  runCase("glass-tir-bubble", [](const Row& r) {
    EXPECT_GT(measure(r, "TIR pixels"), 0.0) << where(r);
    EXPECT_LE(r.metric, 1.0) << where(r) << ": " << r.metricName;
    EXPECT_LE(measure(r, "silhouette offset (px)"), 1.0) << where(r);
  });
}

// A white furnace: no pixel brighter than white (float sums of weights
// that partition unity, a few ULPs above 1 at most), the centre pixel
// between its on-axis lower bound and 1, and the ray caster's centre rays
// undeviated through at least 4 refractions.
TEST(StabilityOptics, NestedGlassStaysInItsEnergyAndOnAxisBounds) {
  runCase("glass-nested", [](const Row& r) {
    EXPECT_LE(measure(r, "brightest channel"), 1.0 + 1e-5) << where(r);
    const double lower = measure(r, "on-axis lower bound");
    EXPECT_GT(lower, 0.0) << where(r);
    EXPECT_GE(measure(r, "centre pixel darkest channel"), lower - 1e-5) << where(r);
    EXPECT_LE(measure(r, "centre pixel brightest channel"), 1.0 + 1e-5) << where(r);
    if (r.variant == "raytrace") {
      EXPECT_LT(measure(r, "centre ray deviation (rad)"), 1e-5) << where(r);
      EXPECT_GE(measure(r, "centre ray refractions"), 4.0) << where(r);
    }
  });
}

// Every ray reflects until --max-depth and ends there, black.
TEST(StabilityOptics, RaysTrappedByTotalInternalReflectionEndAtMaxDepth) {
  runCase("glass-trapped-tir", [](const Row& r) {
    EXPECT_EQ(measure(r, "rays.reflection"), measure(r, "primary rays x max depth")) << where(r);
    EXPECT_EQ(measure(r, "rays.refraction"), 0.0) << where(r);
    EXPECT_EQ(measure(r, "brightest channel"), 0.0) << where(r);
  });
}

// A stack against its analytic composite, every layer kept; the ray
// caster's default cutoff is shown, not held.
std::function<void(const Row&)> matchesTheComposite(double tolerance) {
  return [tolerance](const Row& r) {
    if (isVariant(r, "raytrace cutoff 1e-4")) return;
    EXPECT_LE(r.metric, tolerance) << where(r) << ": " << r.metricName;
    EXPECT_EQ(measure(r, "pixels with fewer layers than the stack"), 0.0) << where(r);
  };
}

// The ray caster composites 1,000 layers per ray in about 4 ms (its
// crossing merge compares every pair of hits): the quick size keeps this
// test at a few seconds.
TEST(StabilityLayers, ThousandLayersMatchTheAnalyticCompositeTo1e5) {
  runCase("layers-1000", matchesTheComposite(1e-5), true);
}
TEST(StabilityLayers, LayersOfAlpha1e6KeepEveryLayer) {
  runCase("layers-alpha-1e-6", matchesTheComposite(1e-4));
}
TEST(StabilityLayers, LayersOfAlphaOneMinus1e6KeepEveryLayer) {
  runCase("layers-alpha-1-1e-6", matchesTheComposite(1e-4));
}
TEST(StabilityLayers, TrianglesThroughTheNearPlaneAndWZeroAgree) {
  runCase("clip-near-w0", [](const Row& r) {
    if (r.variant != "raytrace") expectNoGenuine(r);
  });
}
TEST(StabilityLayers, DegenerateTrianglesCoverNothing) {
  runCase("degenerate", [](const Row& r) {
    if (r.variant != "raytrace") expectNoGenuine(r);
    EXPECT_EQ(measure(r, "samples showing a degenerate triangle"), 0.0) << where(r);
    if (r.measures.count("raster.degenerate")) EXPECT_EQ(r.measures.at("raster.degenerate"), 5.0) << where(r);
    if (r.variant != "raytrace") EXPECT_EQ(r.measures.count("raster.degenerate"), 1u) << where(r);
  });
}

RASTRAY_TEST_LABELS_OF(StabilityLayers, GeneratorsAreDeterministic, "quick");
TEST(StabilityLayers, GeneratorsAreDeterministic) {
  std::vector<Case> cases;
  appendOpticsCases(cases);
  appendLayerCases(cases);
  ASSERT_EQ(cases.size(), 8u);
  for (const Case& c : cases) EXPECT_EQ(c.build().toJson(), c.build().toJson()) << c.name;
}

}  // namespace
}  // namespace rastray::stability
