// crossval, its report and explain, through the real binary.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "run_command.h"
#include "tests/test_files.h"
#include "tests/test_labels.h"

// Tests here render on 2 or more threads (the ThreadSanitizer stage runs them), except those marked quick.
RASTRAY_TEST_LABELS("threads");

namespace rastray {
namespace {

using nlohmann::json;
using test::runRastray;

std::string scene(const char* name) { return std::string(RASTRAY_SCENES) + "/" + name + ".gltf"; }

using test::slurp;

// Every bundled scene: zero genuine mismatches between the rasterizer and
// the ray caster and between hybrid and the ray caster, and hybrid shades
// exactly like the ray caster wherever their hits agree.
TEST(Crossval, BundledScenesHaveNoGenuineMismatches) {
  std::vector<std::string> args = {"crossval"};
  for (const char* s : {"three-triangles", "interpenetrating", "cyclic-overlap", "cornell-box",
                        "transparent-layers", "textured-plane"})
    args.push_back(scene(s));
  for (const char* a : {"--size", "96", "72", "--spp", "4", "--json", "--shadow-map-size", "512"})
    args.push_back(a);
  const auto r = runRastray(args);
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const json j = json::parse(r.out);
  ASSERT_EQ(j["scenes"].size(), 6u);
  for (const json& s : j["scenes"]) {
    for (const char* pair : {"rasterVsRaytrace", "hybridVsRaytrace"}) {
      EXPECT_EQ(s[pair]["visibility"]["mismatches"]["genuine"], 0) << s["scene"] << " " << pair;
      EXPECT_GT(s[pair]["visibility"]["layers"]["agreeing"].get<double>(),
                0.99 * s[pair]["visibility"]["layers"]["compared"].get<double>())
          << s["scene"] << " " << pair;
    }
    EXPECT_LE(s["hybridVsRaytrace"]["color"]["maxWhereHitsAgree"].get<double>(), 1e-5) << s["scene"];
    // Depth agrees to float precision where the hits agree.
    EXPECT_LT(s["rasterVsRaytrace"]["visibility"]["depthError"]["maxRelative"].get<double>(), 1e-5)
        << s["scene"];
  }
  EXPECT_TRUE(j["failures"].empty());
}

// Transparent layers: the ray caster's front-to-back compositing equals the
// rasterizer's exact per-sample fragment lists (with traced shadows, so
// both see the same light) to 1e-5 wherever the layer lists agree.
TEST(Crossval, ExactTransparencyMatchesTheRayCaster) {
  const auto r =
      runRastray({"crossval", scene("transparent-layers"), "--size", "120", "90", "--spp", "4", "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const json s = json::parse(r.out)["scenes"][0];
  EXPECT_GT(s["hybridVsRaytrace"]["color"]["layersWhereHitsAgree"].get<uint64_t>(), 40000u);
  EXPECT_LE(s["hybridVsRaytrace"]["color"]["maxWhereHitsAgree"].get<double>(), 1e-5);
}

TEST(Crossval, SortedTransparencyIsFlaggedAsWrongOnCyclicOverlap) {
  // The painter's order cannot be right on a cyclic overlap: the layer
  // order it reports disagrees with the ray caster's somewhere.
  const auto r = runRastray({"crossval", scene("cyclic-overlap"), "--size", "120", "90", "--spp", "4",
                             "--transparency", "sorted", "--json"});
  ASSERT_EQ(r.status, 1) << r.out << r.err;
  const json s = json::parse(r.out)["scenes"][0];
  EXPECT_GT(s["rasterVsRaytrace"]["visibility"]["mismatches"]["genuine"].get<int>(), 0);
}

RASTRAY_TEST_LABELS_OF(Crossval, ReportIsSelfContained, "threads", "browser");
TEST(Crossval, ReportIsSelfContained) {
  const std::string dir = test::scratchPath("report");
  const auto r = runRastray({"crossval", scene("cornell-box"), scene("three-triangles"), "--size", "80", "60",
                             "--report", dir, "--shadow-map-size", "256"});
  ASSERT_EQ(r.status, 0) << r.err;
  ASSERT_TRUE(std::filesystem::exists(dir + "/index.html"));
  for (const char* f : {"index.html", "raster.png", "raytrace.png", "hybrid.png", "mismatch.png",
                        "depth-diff.png", "color-diff.png"})
    EXPECT_TRUE(std::filesystem::exists(dir + "/cornell-box/" + f)) << f;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(dir)) {
    if (entry.path().extension() != ".html") continue;
    const std::string html = slurp(entry.path());
    EXPECT_EQ(html.find("http://"), std::string::npos) << entry.path();
    EXPECT_EQ(html.find("https://"), std::string::npos) << entry.path();
    EXPECT_EQ(html.find("<script"), std::string::npos) << entry.path();
  }
  const std::string index = slurp(dir + "/index.html");
  EXPECT_NE(index.find("cornell-box/index.html"), std::string::npos);
  EXPECT_NE(index.find("three-triangles/index.html"), std::string::npos);

  // A real browser renders the page: headless Chromium, which
  // scripts/setup.sh installs; CI runs this check, it never skips it.
  const char* chromium = "/usr/bin/chromium";
  ASSERT_TRUE(std::filesystem::exists(chromium))
      << "Chromium is not installed: run scripts/setup.sh (it installs the Debian package chromium)";
  const std::string shot = std::filesystem::absolute(dir + "/shot.png").string();
  const std::string profile = std::filesystem::absolute(dir + "/profile").string();
  const std::string cmd = std::string(chromium) +
                          " --headless --no-sandbox --disable-gpu --disable-quic --no-first-run "
                          "--disable-background-networking --disable-component-update --disable-sync "
                          "--user-data-dir=" +
                          profile + " --window-size=1200,1600 --screenshot=" + shot + " file://" +
                          std::filesystem::absolute(dir + "/cornell-box/index.html").string() +
                          " >/dev/null 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  ASSERT_TRUE(std::filesystem::exists(shot));
  // A page that rendered its images is far from a blank screenshot.
  EXPECT_GT(std::filesystem::file_size(shot), 20000u);
  std::filesystem::remove_all(dir);
}

RASTRAY_TEST_LABELS_OF(Explain, ShowsBothRenderersAndTheirHits, "quick");
TEST(Explain, ShowsBothRenderersAndTheirHits) {
  const auto r =
      runRastray({"explain", scene("three-triangles"), "40", "40", "--size", "80", "80", "--spp", "4"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("== hits per sample"), std::string::npos);
  EXPECT_NE(r.out.find("== rasterizer"), std::string::npos);
  EXPECT_NE(r.out.find("edge 0 a "), std::string::npos);  // setup event: edge 0 and its a, b, c
  EXPECT_NE(r.out.find("== ray caster"), std::string::npos);
  EXPECT_NE(r.out.find("sample 3"), std::string::npos);
  // Coverage (edge function values at a sample), the depth test, and the ray tree.
  EXPECT_NE(r.out.find("  cover sample 0 instance 0 triangle 0: E0 "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("  depth sample 0 instance 0 triangle 0: key 0x"), std::string::npos) << r.out;
  EXPECT_NE(
      r.out.find("ray tree of pixel (40, 40): 4 rays\nray sample 0 instance 0 triangle 0: kind primary"),
      std::string::npos)
      << r.out;
  EXPECT_EQ(runRastray({"explain", scene("three-triangles"), "80", "0", "--size", "80", "80"}).status, 2);
}

// The lines of `text` between the line starting with `from` and the next
// empty line (or the end).
std::vector<std::string> sectionLines(const std::string& text, const std::string& from) {
  std::vector<std::string> lines;
  std::istringstream in(text.substr(text.find(from)));
  std::string line;
  std::getline(in, line);  // the heading
  while (std::getline(in, line) && !line.empty()) lines.push_back(line);
  return lines;
}

// explain --json carries the same events as the text, one object per line
// of each renderer's section, with the fields programs need.
RASTRAY_TEST_LABELS_OF(Explain, JsonHasTheSameEventsAsTheText, "quick");
TEST(Explain, JsonHasTheSameEventsAsTheText) {
  const std::vector<std::string> args = {
      "explain", scene("cornell-box"), "100", "60", "--size", "160", "120", "--spp", "4"};
  const auto text = runRastray(args);
  ASSERT_EQ(text.status, 0) << text.err;
  std::vector<std::string> jsonArgs = args;
  jsonArgs.push_back("--json");
  const auto r = runRastray(jsonArgs);
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j.at("schema"), "rastray.explain");
  EXPECT_EQ(j.at("version"), 1);
  EXPECT_EQ(j.at("pixel"), json::array({100, 60}));
  EXPECT_EQ(j.at("size"), json::array({160, 120}));
  EXPECT_EQ(j.at("spp"), 4);

  // Hits: one entry per sample, each with at least one layer and a verdict.
  ASSERT_EQ(j.at("samples").size(), 4u);
  for (size_t i = 0; i < 4; ++i) {
    const json& s = j.at("samples")[i];
    EXPECT_EQ(s.at("sample"), i);
    EXPECT_GE(s.at("position")[0].get<double>(), 100.0);
    EXPECT_LT(s.at("position")[0].get<double>(), 101.0);
    ASSERT_FALSE(s.at("layers").empty());
    const json& l = s.at("layers")[0];
    EXPECT_EQ(l.at("raster").at("instance"), l.at("raytrace").at("instance"));
    EXPECT_EQ(l.at("verdict"), "agree");
  }

  // Raster events: as many as lines in the text's rasterizer section, in
  // the same order, each with its stage first on the line.
  const json& raster = j.at("raster").at("events");
  const auto rasterLines = sectionLines(text.out, "== rasterizer");
  ASSERT_EQ(raster.size(), rasterLines.size()) << text.out;
  bool covered = false, depthPass = false;
  for (size_t i = 0; i < raster.size(); ++i) {
    const json& e = raster[i];
    const std::string stage = e.at("stage");
    EXPECT_EQ(rasterLines[i].find_first_not_of(' '), 2 * e.at("depth").get<size_t>()) << rasterLines[i];
    EXPECT_EQ(rasterLines[i].substr(rasterLines[i].find_first_not_of(' '), stage.size()), stage);
    if (!e.at("outcome").get<std::string>().empty()) {
      EXPECT_NE(rasterLines[i].find(" -> " + e.at("outcome").get<std::string>()), std::string::npos);
    }
    for (const auto& [name, value] : e.at("values").items())
      EXPECT_NE(rasterLines[i].find(" " + name + " " + value.get<std::string>()), std::string::npos)
          << rasterLines[i];
    if (stage == "cover") {
      EXPECT_TRUE(e.at("sample").is_number() && e.at("instance").is_number() && e.at("triangle").is_number());
      EXPECT_TRUE(e.at("values").contains("E0") && e.at("values").contains("E2"));
      covered = covered || e.at("outcome") == "covered";
    }
    if (stage == "depth") {
      EXPECT_EQ(e.at("values").at("key").get<std::string>().rfind("0x", 0), 0u);
      depthPass = depthPass || e.at("outcome") == "pass";
    }
  }
  EXPECT_EQ(raster.front().at("stage"), "tile");
  EXPECT_TRUE(raster.front().at("sample").is_null());
  EXPECT_TRUE(covered);
  EXPECT_TRUE(depthPass);

  // Ray caster events: the ray tree, one event per ray line; a primary ray
  // per sample, each hitting the floor the raster hits.
  const json& rays = j.at("raytrace").at("events");
  const auto rayLines = sectionLines(text.out, "ray tree of pixel (100, 60): ");
  ASSERT_EQ(rays.size(), rayLines.size()) << text.out;
  EXPECT_NE(text.out.find("ray tree of pixel (100, 60): " + std::to_string(rays.size()) + " rays"),
            std::string::npos);
  int primaries = 0;
  for (const json& e : rays) {
    EXPECT_EQ(e.at("stage"), "ray");
    if (e.at("values").at("kind") != "primary") continue;
    EXPECT_EQ(e.at("sample"), primaries);
    EXPECT_EQ(e.at("outcome"), "hit");
    EXPECT_EQ(e.at("instance"),
              j.at("samples")[size_t(primaries)].at("layers")[0].at("raster").at("instance"));
    ++primaries;
  }
  EXPECT_EQ(primaries, 4);
}

// --debug-pixel: the rasterizer records, the command prints the events to
// stderr after the render; without it nothing reaches stderr.
RASTRAY_TEST_LABELS_OF(DebugPixel, RenderPrintsTheRasterTraceOnStderr, "quick");
TEST(DebugPixel, RenderPrintsTheRasterTraceOnStderr) {
  const std::string png = test::scratchPath("debug-pixel.png");
  const auto traced = runRastray({"render", scene("three-triangles"), "--size", "80", "80", "--spp", "4",
                                  "--debug-pixel", "40", "40", "-o", png});
  ASSERT_EQ(traced.status, 0) << traced.err;
  EXPECT_EQ(traced.err.rfind("tile: rect [0, 64) x [0, 64)", 0), 0u) << traced.err;
  EXPECT_NE(traced.err.find("  setup: edge 0 a "), std::string::npos) << traced.err;
  EXPECT_NE(traced.err.find("  depth sample 0 instance 1 triangle 0: key 0x"), std::string::npos)
      << traced.err;
  EXPECT_NE(traced.err.find("  final sample 3: color ("), std::string::npos) << traced.err;
  const auto plain = runRastray({"render", scene("three-triangles"), "--size", "80", "80", "-o", png});
  ASSERT_EQ(plain.status, 0) << plain.err;
  EXPECT_EQ(plain.err, "");
  std::filesystem::remove(png);
}

}  // namespace
}  // namespace rastray
