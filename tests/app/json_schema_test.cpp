// Issue 13: every JSON output names its schema and version, so a program
// reading it can tell what it holds and refuse what it does not know.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "app/studies/stability.h"
#include "app/studies/stability_report.h"
#include "tests/app/run_command.h"
#include "tests/test_files.h"

namespace rastray {
namespace {

const std::string kScene = std::string(RASTRAY_SCENES) + "/three-triangles.gltf";

void expectSchema(const nlohmann::json& j, const std::string& name) {
  ASSERT_TRUE(j.is_object()) << name;
  EXPECT_EQ(j.value("schema", ""), name);
  EXPECT_EQ(j.value("version", 0), 1) << name;
}

nlohmann::json stdoutJson(const std::vector<std::string>& args) {
  const test::CommandResult r = test::runRastray(args);
  EXPECT_EQ(r.status, 0) << args[0] << ": " << r.err;
  return nlohmann::json::parse(r.out, nullptr, false);
}

nlohmann::json fileJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in, nullptr, false);
}

class JsonSchema : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::scratchPath("out");
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  std::string dir_;
};

TEST_F(JsonSchema, InfoRenderExplainAndCrossval) {
  expectSchema(stdoutJson({"info", kScene, "--json"}), "rastray.info");
  expectSchema(stdoutJson({"render", kScene, "--size", "16", "12", "-o", dir_ + "/a.png", "--json"}),
               "rastray.render");
  expectSchema(stdoutJson({"explain", kScene, "3", "3", "--size", "16", "12", "--json"}), "rastray.explain");
  expectSchema(stdoutJson({"crossval", kScene, "--size", "16", "12", "--json"}), "rastray.crossval");
}

TEST_F(JsonSchema, Compare) {
  const std::string a = dir_ + "/a.exr", b = dir_ + "/b.exr";
  ASSERT_EQ(test::runRastray({"render", kScene, "--size", "16", "12", "-o", a}).status, 0);
  ASSERT_EQ(
      test::runRastray({"render", kScene, "--renderer", "raytrace", "--size", "16", "12", "-o", b}).status,
      0);
  expectSchema(stdoutJson({"compare", a, b, "--json"}), "rastray.compare");
}

TEST_F(JsonSchema, BenchSweepAndStability) {
  const std::string bench = dir_ + "/bench.json";
  ASSERT_EQ(
      test::runRastray({"bench", kScene, "--size", "16", "12", "--frames", "1", "--json", bench}).status, 0);
  expectSchema(fileJson(bench), "rastray.bench");

  const std::string sweep = dir_ + "/sweep";
  const test::CommandResult s = test::runRastray(
      {"sweep", kScene, "--vary", "spp=1,4", "--size", "16", "12", "--repeat", "1", "--report", sweep});
  ASSERT_EQ(s.status, 0) << s.err;
  expectSchema(fileJson(sweep + "/sweep.json"), "rastray.sweep");

  expectSchema(stability::tableJson({}, true), "rastray.stability");
}

}  // namespace
}  // namespace rastray
