// Animation frames through the commands (issue 22 item 3): Debian's
// skinned and morphing glTF samples change with --time and cross-validate
// at several times; info lists animations; sweep varies time; bad
// animation data is exit 2 with one line.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <thread>

#include <httplib.h>

#include "app/engine/render_setup.h"
#include "app/serve/serve_server.h"
#include "run_command.h"
#include "tests/test_files.h"

namespace rastray {
namespace {

using json = nlohmann::json;
using test::runRastray;

const std::string kSkin = "/usr/share/assimp/models/glTF2/simple_skin/simple_skin.gltf";
const std::string kMorph =
    "/usr/share/assimp/models/glTF2/glTF-Sample-Models/AnimatedMorphCube-glTF/AnimatedMorphCube.gltf";

#define REQUIRE_FILE(path)            \
  if (!std::filesystem::exists(path)) \
  GTEST_SKIP() << path << " is not installed (apt-get install assimp-testmodels)"

// A fixed camera on the rest pose's bounds, so that only the pose moves.
std::vector<std::string> fixedCamera(const std::string& path) {
  const Scene rest = loadScene(path);
  const glm::dvec3 c = (rest.bounds.lo + rest.bounds.hi) * 0.5;
  const double size = glm::length(rest.bounds.hi - rest.bounds.lo);
  const auto text = [](double v) { return std::to_string(v); };
  return {"--eye",
          text(c.x + 0.8 * size),
          text(c.y + 0.5 * size),
          text(c.z + 2.0 * size),
          "--target",
          text(c.x),
          text(c.y),
          text(c.z)};
}

FlatImage renderAt(const std::string& path, const std::string& time) {
  std::vector<std::string> args = {"--renderer", "raster", "--size", "64", "48", "--time", time};
  const std::vector<std::string> camera = fixedCamera(path);
  args.insert(args.end(), camera.begin(), camera.end());
  const RenderSettings settings = renderSettingsFrom(args);
  return renderScene(loadSceneForRender(path, settings), settings).output.image;
}

// Pixels whose coverage or colour differ between two frames.
size_t changedPixels(const FlatImage& a, const FlatImage& b) {
  size_t changed = 0;
  for (size_t i = 0; i < a.color.size(); ++i)
    changed += a.instance[i] != b.instance[i] || glm::length(a.color[i] - b.color[i]) > 1e-3f;
  return changed;
}

TEST(AnimationFrames, PicturesChangeWithTime) {
  REQUIRE_FILE(kSkin);
  REQUIRE_FILE(kMorph);
  for (const std::string& path : {kSkin, kMorph}) {
    const FlatImage first = renderAt(path, "0");
    const FlatImage later = renderAt(path, path == kSkin ? "2" : "1.5");
    EXPECT_GT(changedPixels(first, later), first.color.size() / 50) << path;
    // The same time twice is the same picture.
    EXPECT_EQ(changedPixels(first, renderAt(path, "0")), 0u) << path;
  }
}

// crossval at three times: no genuine mismatch in either pair and hybrid
// shading bit-identical to the ray caster's (hybrid d = 0).
TEST(AnimationFrames, CrossvalIsCleanAtThreeTimes) {
  REQUIRE_FILE(kSkin);
  REQUIRE_FILE(kMorph);
  for (const char* time : {"0.4", "1.3", "3.1"}) {
    const auto r =
        runRastray({"crossval", kSkin, kMorph, "--size", "96", "72", "--spp", "4", "--time", time, "--json"});
    ASSERT_EQ(r.status, 0) << r.out << r.err;
    const json j = json::parse(r.out);
    ASSERT_EQ(j["scenes"].size(), 2u);
    for (const json& s : j["scenes"]) {
      for (const char* pair : {"rasterVsRaytrace", "hybridVsRaytrace"})
        EXPECT_EQ(s[pair]["visibility"]["mismatches"]["genuine"], 0)
            << s["scene"] << " " << pair << " t=" << time;
      EXPECT_EQ(s["hybridVsRaytrace"]["color"]["maxWhereHitsAgree"].get<double>(), 0.0)
          << s["scene"] << " t=" << time;
    }
  }
}

TEST(AnimationFrames, InfoListsAnimationsWithDurations) {
  REQUIRE_FILE(kMorph);
  const auto text = runRastray({"info", kMorph});
  ASSERT_EQ(text.status, 0) << text.err;
  EXPECT_NE(text.out.find("animations 1 (--time plays them; without it none plays)\n"
                          "  animation 0   'Square': 1 channel, 1 sampler, keys 0 .. 4.2 s\n"),
            std::string::npos)
      << text.out;
  EXPECT_EQ(text.out.find("ignored"), std::string::npos) << text.out;  // morph targets and animations play
  const auto r = runRastray({"info", kMorph, "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const json a = json::parse(r.out)["animations"];
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(a[0]["name"], "Square");
  EXPECT_EQ(a[0]["channels"], 1);
  EXPECT_NEAR(a[0]["duration"].get<double>(), 4.2, 1e-5);
}

TEST(AnimationFrames, SweepVariesTime) {
  REQUIRE_FILE(kMorph);
  const std::string report = test::scratchPath("sweep");
  const auto r = runRastray({"sweep", kMorph, "--vary", "time=0,1.5,3", "--renderer", "raster", "--size",
                             "32", "24", "--repeat", "1", "--report", report});
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const json j = json::parse(test::slurp(report + "/sweep.json"));
  ASSERT_EQ(j["rows"].size(), 3u) << j.dump();
  for (size_t i = 0; i < 3; ++i) {
    const json& row = j["rows"][i];
    EXPECT_EQ(row["settings"]["time"], std::vector<std::string>({"0", "1.5", "3"})[i]);
    // The auto reference renders the same frame: only edges disagree (at
    // t = 3 the cube has moved; against the rest pose 8 % of pixels would).
    EXPECT_LT(row["errors"]["visibility"].get<double>(), 0.01) << row.dump();
  }
}

// serve: /api/scene gives the explorer the animations and the slider's
// range; a frame at another time is another picture.
TEST(AnimationFrames, ServeTellsTheDurationAndRendersAnyTime) {
  REQUIRE_FILE(kMorph);
  serve::ServeOptions options;
  options.scenes = {kMorph};
  options.port = 0;
  serve::ExplorerServer server(options);
  const int port = server.bind();
  std::thread thread([&] { server.run(); });
  httplib::Client client("127.0.0.1", port);
  client.set_read_timeout(120, 0);
  const std::string scene = "scene=" + httplib::detail::encode_query_param(kMorph);
  const auto info = client.Get(("/api/scene?" + scene).c_str());
  const auto at0 = client.Get(("/api/image?" + scene + "&size=48,36&time=0").c_str());
  const auto at2 = client.Get(("/api/image?" + scene + "&size=48,36&time=2").c_str());
  const auto page = client.Get("/explorer.js");
  server.stop();
  thread.join();
  ASSERT_TRUE(info && at0 && at2 && page);
  ASSERT_EQ(info->status, 200) << info->body;
  const json j = json::parse(info->body);
  ASSERT_EQ(j["animations"].size(), 1u);
  EXPECT_EQ(j["animations"][0]["name"], "Square");
  EXPECT_NEAR(j["duration"].get<double>(), 4.2, 1e-5);
  ASSERT_EQ(at0->status, 200) << at0->body;
  ASSERT_EQ(at2->status, 200) << at2->body;
  EXPECT_NE(at0->body, at2->body);
  EXPECT_NE(page->body.find("writeTimeSlider"), std::string::npos);
}

// Bad animation data through the binary: exit 2, one line naming the
// file and the element, no output file.
TEST(AnimationFrames, BadAnimationDataIsExitTwoWithOneLine) {
  REQUIRE_FILE(kMorph);
  const std::string folder = test::scratchPath("bad");
  std::filesystem::create_directories(folder);
  std::filesystem::copy_file(std::filesystem::path(kMorph).parent_path() / "AnimatedMorphCube.bin",
                             folder + "/AnimatedMorphCube.bin");
  json doc = json::parse(test::slurp(kMorph));
  doc["animations"][0]["samplers"][0]["interpolation"] = "BEZIER";
  const std::string path = folder + "/bad.gltf";
  std::ofstream(path) << doc.dump();
  const std::string out = folder + "/never-written.png";
  const auto r = runRastray({"render", path, "--time", "1", "-o", out});
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(
      r.err,
      path + ": animation 0 sampler 0: \"interpolation\" \"BEZIER\" is not STEP, LINEAR or CUBICSPLINE\n");
  EXPECT_FALSE(std::filesystem::exists(out));
  const auto index = runRastray({"render", kMorph, "--time", "1", "--animation", "2", "-o", out});
  EXPECT_EQ(index.status, 2);
  EXPECT_EQ(index.err,
            "command line: --animation: animation 2 does not exist: " + kMorph + " has 1 animation\n");
}

}  // namespace
}  // namespace rastray
