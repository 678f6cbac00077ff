// Render options that do not apply to the chosen renderer are refused
// (exit 2), not ignored: the render-option table in app/engine/render_setup.cpp
// against an independent list of where each option applies, enforced by
// RenderSettings::finish() and by the real binary.
#ifdef RASTRAY_HAVE_RENDERERS

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "app/engine/render_setup.h"
#include "common/error.h"
#include "run_command.h"
#include "tests/test_files.h"

namespace rastray {
namespace {

using test::runRastray;
using Args = std::vector<std::string>;

constexpr RendererKind kKinds[] = {RendererKind::Raster, RendererKind::Raytrace, RendererKind::Hybrid};
constexpr RendererSet kRaster = rendererBit(RendererKind::Raster);
constexpr RendererSet kRaytrace = rendererBit(RendererKind::Raytrace);
constexpr RendererSet kHybrid = rendererBit(RendererKind::Hybrid);

const std::string kScene = std::string(RASTRAY_SCENES) + "/three-triangles.gltf";

// Where each option applies (issue 8, README `rastray render`), written
// out apart from the table so that a wrong row fails; with a value each
// renderer it applies to accepts.
struct Expected {
  const char* name;
  RendererSet renderers;
  OptionCondition condition;
  Args value;
};

const std::vector<Expected> kExpected = {
    {"--camera", kAllRenderers, OptionCondition::Always, {"0"}},
    {"--eye", kAllRenderers, OptionCondition::Always, {"0", "0", "3"}},
    {"--target", kAllRenderers, OptionCondition::Always, {"0", "0", "0"}},
    {"--up", kAllRenderers, OptionCondition::Always, {"0", "1", "0"}},
    {"--yfov", kAllRenderers, OptionCondition::Always, {"40"}},
    {"--znear", kAllRenderers, OptionCondition::Always, {"0.1"}},
    {"--zfar", kAllRenderers, OptionCondition::Always, {"100"}},
    {"--size", kAllRenderers, OptionCondition::Always, {"8", "6"}},
    {"--time", kAllRenderers, OptionCondition::Always, {"0.5"}},
    {"--animation", kAllRenderers, OptionCondition::Always, {"0"}},  // value: see valueFor
    {"--spp", kAllRenderers, OptionCondition::Always, {"4"}},
    {"--exposure", kAllRenderers, OptionCondition::Always, {"1.5"}},
    {"--threads", kAllRenderers, OptionCondition::Always, {"1"}},
    {"--debug-pixel", kAllRenderers, OptionCondition::Always, {"1", "1"}},
    {"--max-memory", kAllRenderers, OptionCondition::Always, {"8G"}},
    {"--texture-filter", kAllRenderers, OptionCondition::Always, {"nearest"}},
    {"--origin", kAllRenderers, OptionCondition::Always, {"world"}},
    {"--lights", kAllRenderers, OptionCondition::Always, {"none"}},
    {"--cull", kAllRenderers, OptionCondition::Always, {"back"}},
    {"--shadows", kAllRenderers, OptionCondition::Always, {}},  // value: see valueFor
    {"--depth-format", kRaster | kHybrid, OptionCondition::Always, {"float"}},
    {"--depth-func", kRaster | kHybrid, OptionCondition::Always, {"lequal"}},
    {"--polygon-offset", kRaster | kHybrid, OptionCondition::Always, {"1", "1"}},
    {"--transparency", kRaster | kHybrid, OptionCondition::Always, {"sorted"}},
    {"--shading-rate", kRaster | kHybrid, OptionCondition::Always, {"pixel"}},
    {"--wireframe", kRaster | kHybrid, OptionCondition::Always, {}},
    {"--halo", kRaster | kHybrid, OptionCondition::Wireframe, {}},
    {"--shadow-map-size", kRaster | kHybrid, OptionCondition::ShadowMaps, {"64"}},
    {"--shadow-bias", kRaster | kHybrid, OptionCondition::ShadowMaps, {"1", "1"}},
    {"--max-depth", kRaytrace | kHybrid, OptionCondition::Always, {"2"}},
    {"--no-reflection", kRaytrace | kHybrid, OptionCondition::Always, {}},
    {"--no-refraction", kRaytrace | kHybrid, OptionCondition::Always, {}},
    {"--transparency-cutoff", kRaytrace | kHybrid, OptionCondition::Always, {"0.01"}},
    {"--ray-offset", kRaytrace | kHybrid, OptionCondition::Always, {"float-ulps"}},
    {"--terminator", kRaytrace | kHybrid, OptionCondition::Always, {"none"}},
    {"--no-packets", kRaytrace, OptionCondition::Always, {}},
    {"--no-shadow-packets", kRaytrace | kHybrid, OptionCondition::Always, {}},
};

const Expected& expected(const std::string& name) {
  for (const Expected& e : kExpected)
    if (name == e.name) return e;
  throw std::runtime_error(name + ": not in the test's list of options");
}

// The option and a value `kind` accepts.
Args valueFor(const std::string& name, RendererKind kind) {
  Args args = {name};
  if (name == "--shadows") {
    args.push_back(kind == RendererKind::Raster ? "none" : "rays");
  } else if (name == "--animation") {
    args = {"--time", "0.5", "--animation", "0"};  // it chooses what --time plays
  } else {
    const Args& v = expected(name).value;
    args.insert(args.end(), v.begin(), v.end());
  }
  return args;
}

// What makes a conditional option apply, and what makes it not apply.
Args conditionMet(OptionCondition c) {
  switch (c) {
    case OptionCondition::Always:
      return {};
    case OptionCondition::ShadowMaps:
      return {"--shadows", "map"};
    case OptionCondition::Wireframe:
      return {"--wireframe"};
  }
  return {};
}

Args conditionUnmet(OptionCondition c) {
  return c == OptionCondition::ShadowMaps ? Args{"--shadows", "none"} : Args{};
}

Args operator+(Args a, const Args& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// Parses `args` as `render` (withRenderer) or crossval/explain would
// (renderSettingsFrom, which runs finish()): the InputError it threw, if any.
std::optional<InputError> finishWith(const Args& args, bool withRenderer = true,
                                     RenderSettings* out = nullptr) {
  try {
    RenderSettings settings = renderSettingsFrom(args, /*allRenderers=*/!withRenderer);
    if (out) *out = settings;
  } catch (const InputError& e) {
    return e;
  }
  return std::nullopt;
}

Args withRenderer(RendererKind kind, const Args& args) { return Args{"--renderer", toString(kind)} + args; }

std::string joined(const Args& args) {
  std::string s;
  for (const std::string& a : args) s += " " + a;
  return s;
}

TEST(RenderOptionTable, SaysWhereEachOptionApplies) {
  const auto& table = renderOptionTable();
  EXPECT_EQ(table.size(), kExpected.size());
  for (const Expected& e : kExpected) {
    const auto row = std::find_if(table.begin(), table.end(), [&](const RenderOptionSpec& spec) {
      return spec.name == std::string(e.name);
    });
    ASSERT_NE(row, table.end()) << e.name << " has no row";
    EXPECT_EQ(row->renderers, e.renderers) << e.name << ": table says " << describeWhereApplies(*row);
    EXPECT_EQ(row->condition, e.condition) << e.name << ": table says " << describeWhereApplies(*row);
  }
}

// The CLI registers one option per row (cli/render_options_cli.cpp), and
// --help says where each applies.
TEST(RenderOptionTable, DrivesTheRegistration) {
  const auto r = runRastray({"render", "--help"});
  ASSERT_EQ(r.status, 0) << r.err;
  for (const RenderOptionSpec& spec : renderOptionTable())
    EXPECT_NE(r.out.find(std::string(spec.name) + " "), std::string::npos) << spec.name << "\n" << r.out;
  EXPECT_NE(r.out.find("[raster and hybrid with --shadows map]"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("[raytrace]"), std::string::npos) << r.out;
}

TEST(RenderOptions, RefusedForRenderersTheyDoNotApplyTo) {
  int refusals = 0;
  for (const RenderOptionSpec& spec : renderOptionTable())
    for (RendererKind kind : kKinds) {
      if (spec.renderers & rendererBit(kind)) continue;
      const Args args = withRenderer(kind, valueFor(spec.name, kind));
      const auto error = finishWith(args);
      ASSERT_TRUE(error) << "accepted:" << joined(args);
      EXPECT_EQ(error->element(), spec.name) << error->what();
      EXPECT_EQ(error->message(),
                "applies to " + describeWhereApplies(spec) + ", not to --renderer " + toString(kind));
      ++refusals;
    }
  EXPECT_GE(refusals, 12);
}

TEST(RenderOptions, RefusedWhereTheirConditionDoesNotHold) {
  int refusals = 0;
  for (const RenderOptionSpec& spec : renderOptionTable()) {
    if (spec.condition == OptionCondition::Always) continue;
    for (RendererKind kind : kKinds) {
      if (!(spec.renderers & rendererBit(kind))) continue;
      const Args args = withRenderer(kind, conditionUnmet(spec.condition) + valueFor(spec.name, kind));
      const auto error = finishWith(args);
      ASSERT_TRUE(error) << "accepted:" << joined(args);
      EXPECT_EQ(error->element(), spec.name) << error->what();
      EXPECT_NE(error->message().find(std::string("not to --renderer ") + toString(kind)), std::string::npos)
          << error->what();
      ++refusals;
    }
  }
  EXPECT_EQ(refusals, 6);
  // Hybrid traces shadow rays unless told otherwise: no shadow maps.
  const auto error = finishWith({"--renderer", "hybrid", "--shadow-bias", "1", "1"});
  ASSERT_TRUE(error);
  EXPECT_EQ(std::string(error->what()),
            "command line: --shadow-bias: applies to raster and hybrid with --shadows map, not to --renderer "
            "hybrid with --shadows rays");
  // The rasterizer uses shadow maps unless told otherwise.
  EXPECT_FALSE(finishWith({"--renderer", "raster", "--shadow-map-size", "64"}));
}

TEST(RenderOptions, AcceptedWhereTheyApply) {
  for (const RenderOptionSpec& spec : renderOptionTable())
    for (RendererKind kind : kKinds) {
      if (!(spec.renderers & rendererBit(kind))) continue;
      const Args args = withRenderer(kind, conditionMet(spec.condition) + valueFor(spec.name, kind));
      const auto error = finishWith(args);
      EXPECT_FALSE(error) << joined(args) << ": " << error->what();
    }
}

// Given means given: the default value to the wrong renderer is refused.
TEST(RenderOptions, DefaultValueGivenToTheWrongRendererIsRefused) {
  for (const Args& args : {Args{"--renderer", "raytrace", "--depth-format", "float-reversed"},
                           Args{"--renderer", "raytrace", "--transparency", "exact"},
                           Args{"--renderer", "raster", "--max-depth", "8"},
                           Args{"--renderer", "raster", "--transparency-cutoff", "0.0001"},
                           Args{"--renderer", "hybrid", "--shadow-map-size", "2048"}}) {
    const auto error = finishWith(args);
    ASSERT_TRUE(error) << "accepted:" << joined(args);
    EXPECT_EQ(error->element(), args[2]);
  }
}

TEST(RenderOptions, ShadowTechniquesPerRenderer) {
  struct Case {
    const char* renderer;
    const char* shadows;
    bool accepted;
  };
  for (const Case& c :
       {Case{"raster", "map", true}, Case{"raster", "none", true}, Case{"raster", "rays", false},
        Case{"raytrace", "rays", true}, Case{"raytrace", "map", false}, Case{"raytrace", "none", true},
        Case{"hybrid", "map", true}, Case{"hybrid", "none", true}, Case{"hybrid", "rays", true}}) {
    RenderSettings s;
    const auto error = finishWith({"--renderer", c.renderer, "--shadows", c.shadows}, true, &s);
    EXPECT_EQ(!error, c.accepted) << c.renderer << " " << c.shadows;
    // none reaches the ray caster too (hybrid's secondary hits, raytrace's every hit).
    if (!error) {
      EXPECT_EQ(s.ray.shadows, std::string(c.shadows) != "none") << c.renderer << " " << c.shadows;
    }
    if (error) {
      EXPECT_EQ(error->element(), "--shadows");
    }
  }
}

// crossval and explain run every renderer: an option applies when it
// applies to one of them, and goes to those it applies to.
TEST(RenderOptions, AllRenderersAcceptWhatAppliesToOne) {
  for (const RenderOptionSpec& spec : renderOptionTable()) {
    const RendererKind kind = (spec.renderers & kRaster) ? RendererKind::Raster : RendererKind::Raytrace;
    const Args args = conditionMet(spec.condition) + valueFor(spec.name, kind);
    const auto error = finishWith(args, /*withRenderer=*/false);
    EXPECT_FALSE(error) << joined(args) << ": " << error->what();
  }
  RenderSettings s;
  ASSERT_FALSE(finishWith({"--shadows", "rays", "--no-packets"}, false, &s));
  EXPECT_EQ(s.raster.shadows, RasterShadows::Map);  // the rasterizer alone has no rays
  EXPECT_EQ(s.shadowModeFor(RendererKind::Hybrid), ShadowMode::Rays);
  EXPECT_FALSE(s.ray.packets);
  ASSERT_FALSE(finishWith({"--shadows", "none"}, false, &s));
  EXPECT_EQ(s.raster.shadows, RasterShadows::None);
  EXPECT_FALSE(s.ray.shadows);  // crossval: no renderer shadows
  EXPECT_EQ(s.shadowModeFor(RendererKind::Raytrace), ShadowMode::None);
  EXPECT_EQ(s.shadowModeFor(RendererKind::Hybrid), ShadowMode::None);

  // Refused only when it applies to none of them.
  auto error = finishWith({"--shadows", "none", "--shadow-map-size", "64"}, false);
  ASSERT_TRUE(error);
  EXPECT_EQ(error->element(), "--shadow-map-size");
  error = finishWith({"--halo"}, false);
  ASSERT_TRUE(error);
  EXPECT_EQ(error->element(), "--halo");
}

// --animation chooses what --time plays: alone it would do nothing.
TEST(RenderOptions, AnimationNeedsTime) {
  const auto error = finishWith({"--animation", "1"}, false);
  ASSERT_TRUE(error);
  EXPECT_EQ(std::string(error->what()),
            "command line: --animation: chooses what --time plays: give --time too");
  RenderSettings s;
  ASSERT_FALSE(finishWith({"--time", "1.5", "--animation", "all"}, false, &s));
  EXPECT_EQ(s.pose.time, 1.5);
  EXPECT_EQ(s.pose.animation, -1);
  ASSERT_FALSE(finishWith({"--time", "-2", "--animation", "3"}, false, &s));
  EXPECT_EQ(s.pose.time, -2.0);
  EXPECT_EQ(s.pose.animation, 3);
  EXPECT_TRUE(finishWith({"--time", "nan"}, false));
  EXPECT_TRUE(finishWith({"--time", "inf"}, false));
}

// Through the real binary: refused before the scene is read, exit 2 and
// one line naming the option.
TEST(RenderOptionsCommand, RefusedWhereTheyDoNotApply) {
  for (const RenderOptionSpec& spec : renderOptionTable())
    for (RendererKind kind : kKinds) {
      if (spec.renderers & rendererBit(kind)) continue;
      const Args args =
          Args{"render", kScene, "-o", "never-written.png"} + withRenderer(kind, valueFor(spec.name, kind));
      const auto r = runRastray(args);
      EXPECT_EQ(r.status, 2) << joined(args) << "\n" << r.err;
      EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
      EXPECT_EQ(r.err.rfind(std::string("command line: ") + spec.name + ": applies to ", 0), 0u) << r.err;
    }
  const auto r = runRastray(
      {"render", kScene, "-o", "never-written.png", "--renderer", "raytrace", "--shadow-map-size", "64"});
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(
      r.err,
      "command line: --shadow-map-size: applies to raster and hybrid with --shadows map, not to --renderer "
      "raytrace\n");
}

TEST(RenderOptionsCommand, AcceptedWhereTheyApply) {
  for (const Args& args : {Args{"--renderer", "raytrace", "--cull", "back", "--no-packets", "--max-depth",
                                "2", "--shadows", "rays"},
                           Args{"--renderer", "hybrid", "--shadows", "map", "--shadow-map-size", "64",
                                "--transparency-cutoff", "0.1"},
                           Args{"--renderer", "raster", "--wireframe", "--halo", "--shadow-bias", "1", "1",
                                "--depth-func", "lequal"}}) {
    const auto r = runRastray(
        Args{"render", kScene, "-o", test::scratchPath("render-options.png"), "--size", "16", "12"} + args);
    EXPECT_EQ(r.status, 0) << joined(args) << "\n" << r.err;
  }
  const auto r = runRastray({"crossval", kScene, "--size", "16", "12", "--no-packets", "--shadow-map-size",
                             "64", "--depth-format", "float", "--max-depth", "2"});
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  const auto e = runRastray({"explain", kScene, "1", "1", "--size", "16", "12", "--halo"});
  EXPECT_EQ(e.status, 2) << e.err;
  EXPECT_EQ(e.err.rfind("command line: --halo: ", 0), 0u) << e.err;
}

// toArgs writes back what renderSettingsFrom read: every row's formatter
// is its parser's inverse (the same values, bit for bit, floats included).
TEST(RenderOptions, ToArgsGivesTheSameSettingsBack) {
  const Args args = {"--renderer",
                     "hybrid",
                     "--size",
                     "33",
                     "17",
                     "--spp",
                     "4",
                     "--eye",
                     "0.1",
                     "-2.5e-7",
                     "3",
                     "--yfov",
                     "41.3",
                     "--zfar",
                     "inf",
                     "--lights",
                     "2,0",
                     "--polygon-offset",
                     "0.3",
                     "-1",
                     "--shadows",
                     "map",
                     "--shadow-bias",
                     "0.001",
                     "2",
                     "--transparency",
                     "peel:3",
                     "--transparency-cutoff",
                     "0.0001",
                     "--max-memory",
                     "3G",
                     "--cull",
                     "front",
                     "--halo",
                     "--wireframe"};
  const RenderSettings a = renderSettingsFrom(args);
  const Args written = toArgs(a);
  const RenderSettings b = renderSettingsFrom(written);
  EXPECT_EQ(toArgs(b), written);
  EXPECT_EQ(b.camera.eye, a.camera.eye);
  EXPECT_EQ(b.camera.yfov, a.camera.yfov);
  EXPECT_EQ(b.raster.polygonOffsetFactor, a.raster.polygonOffsetFactor);
  EXPECT_EQ(b.raster.shadowBiasConstant, a.raster.shadowBiasConstant);
  EXPECT_EQ(b.ray.transparencyCutoff, a.ray.transparencyCutoff);
  EXPECT_EQ(b.raster.peelLayers, 3);
  EXPECT_EQ(b.memory.bytes, 3ull << 30);
  EXPECT_EQ(*b.keptLights, (std::vector<size_t>{0, 2}));
  EXPECT_EQ(
      joined(toArgs(a, {"--max-memory"})),
      " --renderer hybrid --eye 0.1 -2.5e-07 3 --yfov 41.3 --zfar inf --size 33 17 --spp 4 --lights 0,2 "
      "--cull front --shadows map --polygon-offset 0.3 -1 --transparency peel:3 --wireframe --halo "
      "--shadow-bias 0.001 2 --transparency-cutoff 0.0001");
  // Given twice, or not a render option: refused, naming it.
  auto error = finishWith({"--spp", "4", "--spp", "8"});
  ASSERT_TRUE(error);
  EXPECT_EQ(std::string(error->what()), "command line: --spp: given more than once");
  error = finishWith({"--spp", "four"});
  ASSERT_TRUE(error);
  EXPECT_EQ(std::string(error->what()), "command line: --spp: 'four' is not an integer");
}

// docs/OPTIONS.md holds the table as renderOptionsMarkdown() writes it,
// between two marker lines; RASTRAY_UPDATE_DOCS=1 rewrites it.
TEST(RenderOptionTable, DocsOptionsPageHoldsTheTable) {
  const std::string path = std::string(RASTRAY_SCENES) + "/../docs/OPTIONS.md";
  std::ifstream in(path);
  ASSERT_TRUE(in) << path;
  std::stringstream buffer;
  buffer << in.rdbuf();
  std::string text = buffer.str();
  const std::string begin = "<!-- options table: begin -->\n", end = "<!-- options table: end -->";
  const size_t from = text.find(begin), to = text.find(end);
  ASSERT_NE(from, std::string::npos) << path;
  ASSERT_NE(to, std::string::npos) << path;
  const std::string table = renderOptionsMarkdown();
  if (std::getenv("RASTRAY_UPDATE_DOCS")) {
    text.replace(from + begin.size(), to - from - begin.size(), table);
    std::ofstream(path) << text;
    return;
  }
  EXPECT_EQ(text.substr(from + begin.size(), to - from - begin.size()), table)
      << "docs/OPTIONS.md is stale: run RASTRAY_UPDATE_DOCS=1 ./build/tests/app_tests "
         "--gtest_filter='RenderOptionTable.DocsOptionsPageHoldsTheTable'";
}

}  // namespace
}  // namespace rastray

#endif  // RASTRAY_HAVE_RENDERERS
