// --lights (which of the scene's lights a render keeps) and --camera (which
// of the file's camera nodes it views from), through the real binary.
#ifdef RASTRAY_HAVE_RENDERERS

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/image.h"
#include "run_command.h"
#include "tests/test_files.h"

namespace rastray {
namespace {

using nlohmann::json;
using test::runRastray;
using Args = std::vector<std::string>;

Args operator+(Args a, const Args& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

const std::string kCornell = std::string(RASTRAY_SCENES) + "/cornell-box.gltf";

json readJson(const std::string& path) {
  std::ifstream in(path);
  return json::parse(in);
}

std::string writeScene(const json& doc, const std::string& name) {
  const std::string path = test::scratchPath(name);
  std::ofstream(path) << doc.dump();
  return path;
}

// The Cornell box with its light node's light taken away: a scene without
// lights, otherwise the same file.
std::string cornellWithoutLights() {
  json doc = readJson(kCornell);
  for (json& node : doc["nodes"])
    if (node.contains("extensions")) node["extensions"].erase("KHR_lights_punctual");
  return writeScene(doc, "cornell-no-lights.gltf");
}

// The Cornell box with a second camera node after the first in walk order:
// eye (0.5, 0.2, 3), looking down -Z, yfov 0.6 rad (a camera of its own).
constexpr double kSecondYfov = 0.6;
std::string cornellWithTwoCameras() {
  json doc = readJson(kCornell);
  doc["cameras"].push_back(
      {{"name", "Side"}, {"type", "perspective"}, {"perspective", {{"yfov", kSecondYfov}, {"znear", 0.1}}}});
  doc["nodes"].push_back(
      {{"name", "SideCamera"}, {"translation", {0.5, 0.2, 3.0}}, {"camera", doc["cameras"].size() - 1}});
  doc["scenes"][doc.value("scene", 0)]["nodes"].push_back(doc["nodes"].size() - 1);
  return writeScene(doc, "cornell-two-cameras.gltf");
}

FlatImage render(const std::string& scene, const std::string& name, const Args& extra,
                 json* report = nullptr) {
  const std::string out = test::scratchPath("lights-camera-" + name + ".exr");
  Args args = {"render", scene, "--size", "40", "30", "--spp", "4", "-o", out};
  args.insert(args.end(), extra.begin(), extra.end());
  if (report) args.push_back("--json");
  const auto r = runRastray(args);
  EXPECT_EQ(r.status, 0) << name << ": " << r.err;
  if (report && r.status == 0) *report = json::parse(r.out);
  return readExr(out);
}

void expectSame(const FlatImage& a, const FlatImage& b, const std::string& what) {
  ASSERT_EQ(a.width, b.width) << what;
  ASSERT_EQ(a.height, b.height) << what;
  EXPECT_TRUE(a.color == b.color) << what;
  EXPECT_TRUE(a.depth == b.depth) << what;
  EXPECT_TRUE(a.instance == b.instance) << what;
  EXPECT_TRUE(a.triangle == b.triangle) << what;
}

bool hasShadowWork(const json& report) {
  for (const auto& [name, value] : report["counters"].items())
    if (name.find("shadow") != std::string::npos && value.get<uint64_t>() != 0) return true;
  return false;
}

bool leftOut(const json& report, const std::string& word) {
  for (const json& p : report["passesLeftOut"])
    if (p.get<std::string>().find(word) != std::string::npos) return true;
  return false;
}

TEST(Lights, NoneRendersAsTheSceneWithoutLights) {
  const std::string bare = cornellWithoutLights();
  for (const std::string renderer : {"raster", "raytrace", "hybrid"}) {
    json off, given, none;
    const FlatImage withNone =
        render(kCornell, renderer + "-none", {"--renderer", renderer, "--lights", "none"}, &off);
    const FlatImage without = render(bare, renderer + "-bare", {"--renderer", renderer}, &none);
    const FlatImage all = render(kCornell, renderer + "-all", {"--renderer", renderer}, &given);
    expectSame(withNone, without, renderer + ": --lights none vs the file without lights");
    EXPECT_FALSE(withNone.color == all.color) << renderer << ": the light made no difference";
    // SPEC §8: no light, no shadow work; the default render does some.
    EXPECT_TRUE(leftOut(off, "shadow")) << renderer << ": " << off["passesLeftOut"].dump();
    EXPECT_FALSE(hasShadowWork(off)) << renderer << ": " << off["counters"].dump();
    EXPECT_EQ(off["passesLeftOut"], none["passesLeftOut"]) << renderer;
    EXPECT_TRUE(hasShadowWork(given)) << renderer << ": " << given["counters"].dump();
  }
}

TEST(Lights, KeepingTheOnlyLightIsTheDefault) {
  for (const std::string renderer : {"raster", "hybrid"}) {
    expectSame(render(kCornell, renderer + "-keep0", {"--renderer", renderer, "--lights", "0"}),
               render(kCornell, renderer + "-default", {"--renderer", renderer}), renderer + ": --lights 0");
  }
}

TEST(Lights, BadListsAreRefused) {
  const std::string out = test::scratchPath("lights-bad.exr");
  for (const Args& bad : {Args{"--lights", "1"}, Args{"--lights", "0,3"}}) {
    const auto r = runRastray(Args{"render", kCornell, "--size", "8", "8", "-o", out} + bad);
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(r.err.find("--lights"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("the scene has 1 light"), std::string::npos) << r.err;
  }
  for (const std::string bad : {"", "x", "0,", "-1", "0;1", "1234567890"}) {
    const auto r = runRastray({"render", kCornell, "--size", "8", "8", "-o", out, "--lights", bad});
    EXPECT_EQ(r.status, 2) << "'" << bad << "': " << r.err;
    EXPECT_NE(r.err.find("--lights"), std::string::npos) << r.err;
  }
}

TEST(Lights, InfoListsEveryLightByIndex) {
  const auto r = runRastray({"info", kCornell, "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  ASSERT_EQ(j["lightList"].size(), 1u);
  EXPECT_EQ(j["lightList"][0]["index"], 0);
  EXPECT_EQ(j["lightList"][0]["name"], "CeilingLight");
  EXPECT_EQ(j["lightList"][0]["type"], "point");
  const auto text = runRastray({"info", kCornell});
  EXPECT_NE(text.out.find("light 0    point 'CeilingLight'"), std::string::npos) << text.out;
}

TEST(Cameras, EveryCameraNodeCanBeChosen) {
  const std::string scene = cornellWithTwoCameras();
  const auto info = runRastray({"info", scene, "--json"});
  ASSERT_EQ(info.status, 0) << info.err;
  const json list = json::parse(info.out)["cameraList"];
  ASSERT_EQ(list.size(), 2u) << list.dump();
  EXPECT_NE(list[1]["origin"].get<std::string>().find("'SideCamera'"), std::string::npos) << list.dump();
  EXPECT_EQ(list[1]["eye"], json({0.5, 0.2, 3.0}));

  // The default is the first camera node; --camera 1 views from the second.
  const FlatImage first = render(scene, "camera0", {"--camera", "0"});
  expectSame(first, render(scene, "camera-default", {}), "--camera 0 vs the default");
  const FlatImage second = render(scene, "camera1", {"--camera", "1"});
  EXPECT_FALSE(first.color == second.color) << "--camera 1 rendered as camera 0";

  // --camera 1 equals camera 0 with camera 1's eye, target, up and yfov given.
  char yfov[64];
  std::snprintf(yfov, sizeof yfov, "%.17g", kSecondYfov * 180.0 / M_PI);
  const Args explicitPose = {"--eye", "0.5", "0.2",  "3", "--target", "0.5",
                             "0.2",   "2",   "--up", "0", "1",        "0"};
  expectSame(second, render(scene, "camera1-explicit", Args{"--camera", "0", "--yfov", yfov} + explicitPose),
             "--camera 1 vs its pose given");
  // The other overrides apply on top of the chosen camera.
  const auto onTop = runRastray({"info", scene, "--json", "--camera", "1", "--eye", "0.5", "0.2", "4"});
  ASSERT_EQ(onTop.status, 0) << onTop.err;
  const json camera = json::parse(onTop.out)["camera"];
  EXPECT_EQ(camera["eye"], json({0.5, 0.2, 4.0}));
  EXPECT_NEAR(camera["yfovDegrees"].get<double>(), kSecondYfov * 180.0 / M_PI, 1e-9);
  EXPECT_NE(camera["origin"].get<std::string>().find("'SideCamera'"), std::string::npos) << camera.dump();
}

TEST(Cameras, AnIndexOutOfRangeIsRefused) {
  const std::string scene = cornellWithTwoCameras();
  const std::string out = test::scratchPath("camera-bad.exr");
  for (const Args& args : {Args{"render", scene, "--size", "8", "8", "-o", out, "--camera", "2"},
                           Args{"info", scene, "--camera", "2"}, Args{"info", kCornell, "--camera", "1"}}) {
    const auto r = runRastray(args);
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(r.err.find("--camera"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("the scene has"), std::string::npos) << r.err;
  }
  EXPECT_NE(runRastray({"info", scene, "--camera", "2"}).err.find("has 2 camera nodes"), std::string::npos);
}

}  // namespace
}  // namespace rastray

#endif  // RASTRAY_HAVE_RENDERERS
