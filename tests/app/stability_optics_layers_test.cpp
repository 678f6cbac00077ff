// The stability study's glass and layer cases (app/studies/stability_cases_optics.cpp,
// app/studies/stability_cases_layers.cpp) run in process: every row of each case must
// hold its property (the TIR band within a pixel of its analytic position,
// nested glass within its energy and on-axis bounds, trapped rays ending at
// --max-depth, stacked layers matching the analytic composite, clipped and
// degenerate triangles), and the generators are deterministic.
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "app/studies/stability.h"

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

// Writes the case's scene to a temp folder, runs it (every variant, or the
// --quick subset) and checks every row.
void runCase(const std::string& name, bool quick = false) {
  const Case c = findCase(name);
  ASSERT_TRUE(c.build && c.run);
  const auto dir =
      std::filesystem::temp_directory_path() / ("rastray-optics-layers-" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / (c.name + ".gltf")).string();
  c.build().write(path);
  CaseContext ctx;
  ctx.sceneDir = dir.string();
  ctx.quick = quick;
  ctx.threads = 2;
  ctx.progress = [](const std::string& line) { std::printf("  %s\n", line.c_str()); };
  const std::vector<Row> rows = c.run(ctx, path);
  std::filesystem::remove_all(dir);
  ASSERT_FALSE(rows.empty());
  int asserted = 0;
  for (const Row& r : rows) {
    std::printf("%s | %s | agree %.6f genuine %lld nan/inf %llu | %s = %.9g | %.2f s\n", r.caseName.c_str(),
                r.variant.c_str(), r.agreement, (long long)r.genuine, (unsigned long long)r.nanInf,
                r.metricName.c_str(), r.metric, r.seconds);
    if (!r.property.empty()) ++asserted;
    EXPECT_TRUE(r.pass) << r.caseName << " / " << r.variant << ": " << r.property << " (" << r.metricName
                        << " = " << r.metric << ", genuine " << r.genuine << ", NaN/Inf " << r.nanInf << ")";
  }
  EXPECT_GT(asserted, 0) << name << ": no row asserts anything";
}

TEST(StabilityOptics, TirBandOfABubbleLiesWithinAPixelOfItsAnalyticPosition) { runCase("glass-tir-bubble"); }
TEST(StabilityOptics, NestedGlassStaysInItsEnergyAndOnAxisBounds) { runCase("glass-nested"); }
TEST(StabilityOptics, RaysTrappedByTotalInternalReflectionEndAtMaxDepth) { runCase("glass-trapped-tir"); }
// The ray caster composites 1,000 layers per ray in about 4 ms (its
// crossing merge compares every pair of hits): the quick size keeps this
// test at a few seconds.
TEST(StabilityLayers, ThousandLayersMatchTheAnalyticCompositeTo1e5) { runCase("layers-1000", true); }
TEST(StabilityLayers, LayersOfAlpha1e6KeepEveryLayer) { runCase("layers-alpha-1e-6"); }
TEST(StabilityLayers, LayersOfAlphaOneMinus1e6KeepEveryLayer) { runCase("layers-alpha-1-1e-6"); }
TEST(StabilityLayers, TrianglesThroughTheNearPlaneAndWZeroAgree) { runCase("clip-near-w0"); }
TEST(StabilityLayers, DegenerateTrianglesCoverNothing) { runCase("degenerate"); }

TEST(StabilityLayers, GeneratorsAreDeterministic) {
  std::vector<Case> cases;
  appendOpticsCases(cases);
  appendLayerCases(cases);
  ASSERT_EQ(cases.size(), 8u);
  for (const Case& c : cases) EXPECT_EQ(c.build().toJson(), c.build().toJson()) << c.name;
}

}  // namespace
}  // namespace rastray::stability
