// --no-reflection and --no-refraction through the real binary: each stops
// its own kind of secondary ray at every depth (counted zero, said in the
// passes left out) and keeps the other; both together are --max-depth 0.
#ifdef RASTRAY_HAVE_RENDERERS

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/image.h"
#include "run_command.h"
#include "tests/test_files.h"

namespace rastray {
namespace {

using nlohmann::json;
using Args = std::vector<std::string>;

// The Cornell box: a mirror box and a glass sphere (Fresnel reflection and
// refraction), so each kind of ray has work.
struct Render {
  FlatImage image;
  json report;
};

Render render(const std::string& renderer, const Args& extra) {
  static int count = 0;
  const std::string out = test::scratchPath(renderer + "-" + std::to_string(count++) + ".exr");
  Args args = {"render",     test::scenePath("cornell-box.gltf"),
               "--renderer", renderer,
               "--size",     "48",
               "36",         "--spp",
               "4",          "--float",
               "--json",     "-o",
               out};
  args.insert(args.end(), extra.begin(), extra.end());
  const auto r = test::runRastray(args);
  EXPECT_EQ(r.status, 0) << r.err;
  if (r.status != 0) return {};
  return {readExr(out), json::parse(r.out)};
}

uint64_t rays(const Render& r, const std::string& kind) {
  return r.report["counters"].value("rays." + kind, uint64_t(0));
}

bool leftOut(const Render& r, const std::string& text) {
  for (const json& p : r.report["passesLeftOut"])
    if (p.get<std::string>() == text) return true;
  return false;
}

TEST(SecondaryRays, EachKindIsSwitchedOffAlone) {
  for (const std::string renderer : {"raytrace", "hybrid"}) {
    SCOPED_TRACE(renderer);
    const Render all = render(renderer, {});
    const Render noReflection = render(renderer, {"--no-reflection"});
    const Render noRefraction = render(renderer, {"--no-refraction"});
    ASSERT_GT(rays(all, "reflection"), 0u);
    ASSERT_GT(rays(all, "refraction"), 0u);

    EXPECT_EQ(rays(noReflection, "reflection"), 0u);
    EXPECT_GT(rays(noReflection, "refraction"), 0u);
    EXPECT_TRUE(leftOut(noReflection, "reflection rays: --no-reflection"))
        << noReflection.report["passesLeftOut"].dump();
    EXPECT_FALSE(noReflection.image.color == all.image.color);

    EXPECT_EQ(rays(noRefraction, "refraction"), 0u);
    EXPECT_GT(rays(noRefraction, "reflection"), 0u);  // the mirror, and the glass's Fresnel part
    EXPECT_TRUE(leftOut(noRefraction, "refraction rays: --no-refraction"))
        << noRefraction.report["passesLeftOut"].dump();
    EXPECT_FALSE(noRefraction.image.color == all.image.color);
    EXPECT_FALSE(noRefraction.image.color == noReflection.image.color);
    // Visibility does not change: the same surfaces at every sample.
    EXPECT_TRUE(noReflection.image.instance == all.image.instance);
    EXPECT_TRUE(noRefraction.image.depth == all.image.depth);
  }
}

TEST(SecondaryRays, BothOffIsMaxDepthZero) {
  for (const std::string renderer : {"raytrace", "hybrid"}) {
    const Render both = render(renderer, {"--no-reflection", "--no-refraction"});
    const Render depthZero = render(renderer, {"--max-depth", "0"});
    EXPECT_TRUE(both.image.color == depthZero.image.color) << renderer;
    EXPECT_EQ(rays(both, "reflection") + rays(both, "refraction"), 0u) << renderer;
  }
}

TEST(SecondaryRays, TheRasterizerAloneRefusesThem) {
  for (const char* flag : {"--no-reflection", "--no-refraction"}) {
    const auto r = test::runRastray({"render", test::scenePath("cornell-box.gltf"), "--renderer", "raster",
                                     flag, "-o", test::scratchPath("raster.png")});
    EXPECT_EQ(r.status, 2) << flag;
    EXPECT_NE(r.err.find(flag), std::string::npos) << r.err;
  }
}

}  // namespace
}  // namespace rastray

#endif  // RASTRAY_HAVE_RENDERERS
