// `rastray info --json` on real-world files made by other tools, against
// counts computed independently (tests/data/real-world/expected_counts.py,
// which follows SPEC §1 and §2 without sharing code with the loader).
#include <fstream>
#include <map>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "run_command.h"

namespace rastray {
namespace {

using nlohmann::json;
using test::runRastray;

json expectedCounts() {
  std::ifstream in(std::string(RASTRAY_TEST_DATA) + "/real-world/expected.json");
  return json::parse(in);
}

class RealWorldInfo : public ::testing::TestWithParam<std::string> {};

TEST_P(RealWorldInfo, CountsFollowSpecFlattening) {
  const std::string file = GetParam();
  const json expected = expectedCounts().at(file);
  const auto r = runRastray({"info", std::string(RASTRAY_TEST_DATA) + "/real-world/" + file, "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const json got = json::parse(r.out);
  EXPECT_EQ(got["instances"], expected["instances"]);
  EXPECT_EQ(got["triangles"], expected["triangles"]);
  EXPECT_EQ(got["nodes"], expected["nodes"]);
  EXPECT_EQ(got["visitedNodes"], expected["visitedNodes"]);
  EXPECT_EQ(got["meshes"], expected["meshes"]);
  EXPECT_EQ(got["cameras"], expected["cameras"]);
  EXPECT_EQ(got["cameraNodes"], expected["cameraNodes"]);
  EXPECT_EQ(got["skippedPrimitives"], expected["skippedPrimitives"]);
  EXPECT_EQ(got["sceneIndex"], expected["sceneIndex"]);
  EXPECT_EQ(got["lights"]["total"], expected["lights"]);
  const int defaults = expected["defaultMaterialUsed"].get<bool>() ? 1 : 0;
  EXPECT_EQ(got["materials"]["total"].get<int>(), expected["materials"].get<int>() + defaults);
  if (expected["firstCameraNode"].is_number())
    EXPECT_NE(got["camera"]["origin"].get<std::string>().find(
                  "node " + std::to_string(expected["firstCameraNode"].get<int>())),
              std::string::npos)
        << got["camera"]["origin"];
  else
    EXPECT_EQ(got["camera"]["origin"], "default");
  // What the file uses and nothing renders, feature by feature.
  json ignored = json::object();
  for (const json& f : got["ignored"]) ignored[f["feature"].get<std::string>()] = f["count"];
  EXPECT_EQ(ignored, expected["ignored"]);
  // Instance order and per-instance triangle counts (SPEC §1 walk order).
  const json& want = expected["instanceList"];
  const json& have = got["instanceList"];
  ASSERT_EQ(have.size(), want.size());
  for (size_t i = 0; i < want.size(); ++i) {
    EXPECT_EQ(have[i]["node"], want[i]["node"]) << "instance " << i;
    EXPECT_EQ(have[i]["mesh"], want[i]["mesh"]) << "instance " << i;
    EXPECT_EQ(have[i]["primitive"], want[i]["primitive"]) << "instance " << i;
    EXPECT_EQ(have[i]["mode"], want[i]["mode"]) << "instance " << i;
    EXPECT_EQ(have[i]["triangles"], want[i]["triangles"]) << "instance " << i;
  }
}

std::vector<std::string> realWorldFiles() {
  std::vector<std::string> files;
  const json all = expectedCounts();
  for (auto it = all.begin(); it != all.end(); ++it) files.push_back(it.key());
  return files;
}

INSTANTIATE_TEST_SUITE_P(Files, RealWorldInfo, ::testing::ValuesIn(realWorldFiles()),
                         [](const ::testing::TestParamInfo<std::string>& param) {
                           std::string name;
                           for (char c : param.param)
                             name += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
                           return name;
                         });

TEST(BundledScenes, InfoWorksOnEveryScene) {
  for (const char* scene : {"three-triangles", "interpenetrating", "cyclic-overlap", "cornell-box",
                            "transparent-layers", "textured-plane", "vertex-colors"}) {
    const auto r = runRastray({"info", std::string(RASTRAY_SCENES) + "/" + scene + ".gltf", "--json"});
    ASSERT_EQ(r.status, 0) << scene << ": " << r.err;
    const json j = json::parse(r.out);
    EXPECT_GT(j["triangles"].get<int>(), 0) << scene;
    EXPECT_NE(j["camera"]["origin"], "default") << scene << " should carry its own camera";
  }
}

TEST(BundledScenes, AnalysisMatchesWhatEachSceneShows) {
  auto needed = [](const std::string& scene) {
    const auto r = runRastray({"info", std::string(RASTRAY_SCENES) + "/" + scene + ".gltf", "--json"});
    std::map<std::string, bool> m;
    const json doc = json::parse(r.out);
    for (const json& d : doc["analysis"]) m[d["work"].get<std::string>()] = d["needed"].get<bool>();
    return m;
  };
  auto box = needed("cornell-box");
  EXPECT_TRUE(box["shadows"]);
  EXPECT_TRUE(box["reflection rays"]);
  EXPECT_TRUE(box["refraction rays"]);
  EXPECT_FALSE(box["transparency pass"]);
  auto tri = needed("three-triangles");
  for (const auto& [work, on] : tri) EXPECT_FALSE(on) << work;
  EXPECT_TRUE(needed("transparent-layers")["transparency pass"]);
  EXPECT_TRUE(needed("textured-plane")["textures"]);
}

}  // namespace
}  // namespace rastray
