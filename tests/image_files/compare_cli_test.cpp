// `rastray compare` through the real binary: exit statuses 0/1/2, the JSON
// report, the table, and the maps, on EXR pairs with known differences.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "common/image.h"
#include "tests/app/run_command.h"
#include "tests/compare/frames.h"

namespace rastray {
namespace {

using nlohmann::json;
using test::runRastray;

class CompareCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = test::makeTempDir("cli");
    a = dir + "/a.exr";
    b = dir + "/b.exr";
    same = dir + "/same.exr";
    const FlatImage fa = test::threeTrianglesFrame();
    FlatImage fb = fa;
    test::setHit(fb, 5, 5, 1, 0, 0.75f);  // silhouette edge (on yellow's bottom edge)
    test::setHit(fb, 4, 4, 2, 0, 0.25f);  // genuine
    fb.color[fb.index(4, 4)] = {1, 0, 0, 1};
    writeExr(a, fa, ColorPrecision::Float);
    writeExr(b, fb, ColorPrecision::Float);
    writeExr(same, fa, ColorPrecision::Float);
  }

  std::string dir, a, b, same;
  const std::string scene = test::scenePath("three-triangles.gltf");
};

int lineCount(const std::string& s) { return int(std::count(s.begin(), s.end(), '\n')); }

TEST_F(CompareCli, IdenticalFilesPassEveryThreshold) {
  const auto r =
      runRastray({"compare", a, same, "--min-agreement", "1", "--max-genuine", "0", "--fail-rms", "0"});
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("thresholds  passed"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("image-space only"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Yee"), std::string::npos) << r.out;
}

TEST_F(CompareCli, JsonWithSceneClassifiesGeometrically) {
  const auto r = runRastray({"compare", a, b, "--scene", scene, "--spp", "1", "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["classification"]["mode"], "geometric");
  EXPECT_EQ(j["classification"]["depthFormat"], "float-reversed");
  const json& px = j["visibility"]["pixels"];
  EXPECT_EQ(px["compared"], 64);
  EXPECT_EQ(px["agreeing"], 62);
  EXPECT_EQ(px["mismatches"]["genuine"]["count"], 1);
  EXPECT_EQ(px["mismatches"]["silhouette-edge"]["count"], 1);
  EXPECT_EQ(j["visibility"]["examples"]["genuine"]["x"], 4);
  EXPECT_EQ(j["visibility"]["examples"]["genuine"]["y"], 4);
  // Yellow (1, 1, 0, 1) against red (1, 0, 0, 1) at one pixel of 64:
  // channel G differs by 1, the largest error, at (4, 4).
  EXPECT_EQ(j["color"]["maxError"], 1.0);
  EXPECT_EQ(j["color"]["maxAt"]["x"], 4);
  EXPECT_EQ(j["color"]["maxAt"]["channel"], "G");
  EXPECT_NEAR(j["color"]["rmsError"].get<double>(), std::sqrt(1.0 / 256.0), 1e-9);
  EXPECT_EQ(j["passed"], true);
}

// The camera options the files were rendered with are accepted as given
// to render, --size among them; a size that is not the files' is refused
// in the documented `command line: OPTION: why` form.
TEST_F(CompareCli, AcceptsTheCameraOptionsUsedForRendering) {
  auto r = runRastray({"compare", a, b, "--scene", scene, "--spp", "1", "--size", "8", "8", "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(json::parse(r.out)["classification"]["mode"], "geometric");
  r = runRastray({"compare", a, b, "--scene", scene, "--spp", "1", "--size", "320", "240"});
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_EQ(r.err, "command line: --size: 320x240 is not the files' size, 8x8\n");
}

TEST_F(CompareCli, WithoutSceneSayImageSpace) {
  const auto r = runRastray({"compare", a, b, "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["classification"]["mode"], "image-space");
  EXPECT_EQ(j["visibility"]["pixels"]["mismatching"], 2);
}

TEST_F(CompareCli, ThresholdsFailWithStatusOne) {
  auto r = runRastray({"compare", a, b, "--scene", scene, "--spp", "1", "--max-genuine", "0"});
  EXPECT_EQ(r.status, 1) << r.out << r.err;
  EXPECT_NE(r.err.find("--max-genuine"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("FAILED"), std::string::npos);
  r = runRastray({"compare", a, b, "--scene", scene, "--spp", "1", "--max-genuine", "1"});
  EXPECT_EQ(r.status, 0) << r.err;
  // Image space is coarser: red lies beside (4, 4) in A, so the one
  // genuine mismatch reads as a silhouette there, and --max-genuine 0 passes.
  r = runRastray({"compare", a, b, "--max-genuine", "0"});
  EXPECT_EQ(r.status, 0) << r.err;
  r = runRastray({"compare", a, b, "--min-agreement", "0.99"});  // 62/64 = 0.969
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("--min-agreement"), std::string::npos) << r.err;
  r = runRastray({"compare", a, b, "--min-agreement", "0.95"});
  EXPECT_EQ(r.status, 0) << r.err;
  r = runRastray({"compare", a, b, "--fail-rms", "0.05"});  // RMS 1/16 = 0.0625
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("--fail-rms"), std::string::npos) << r.err;
  r = runRastray({"compare", a, b, "--fail-rms", "0.07", "--json"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(json::parse(r.out)["violations"].empty());
}

TEST_F(CompareCli, BadInputExitsTwoWithOneLine) {
  FlatImage small(4, 4);
  writeExr(dir + "/small.exr", small);
  auto r = runRastray({"compare", a, dir + "/small.exr"});
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("small.exr"), std::string::npos) << r.err;

  r = runRastray({"compare", a, dir + "/missing.exr"});
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("missing.exr"), std::string::npos) << r.err;

  r = runRastray({"compare", a, b, "--scene", scene});  // flat + scene needs --spp
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--spp"), std::string::npos) << r.err;

  r = runRastray({"compare", a, b, "--depth-format", "unorm24"});  // no planes known
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--depth-format"), std::string::npos) << r.err;

  r = runRastray({"compare", a, b, "--depth-format", "unorm24", "--znear", "0.125", "--zfar", "1"});
  EXPECT_EQ(r.status, 0) << r.err;  // the planes are stated

  r = runRastray({"compare", a, b, "--eye", "0", "0", "1"});  // a camera option without the scene
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--eye"), std::string::npos) << r.err;

  r = runRastray({"compare", a, b, "--depth-format", "float64"});
  EXPECT_EQ(r.status, 2);

  DeepImage deep;
  deep.width = deep.height = 8;
  deep.offsets.assign(65, 0);
  writeDeepExr(dir + "/deep.exr", deep);
  r = runRastray({"compare", a, dir + "/deep.exr"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("deep.exr"), std::string::npos) << r.err;

  FlatImage other = test::threeTrianglesFrame();
  test::setHit(other, 4, 4, 9, 0, 0.5f);
  writeExr(dir + "/other.exr", other);
  r = runRastray({"compare", a, dir + "/other.exr", "--scene", scene, "--spp", "1"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("other.exr: pixel (4, 4)"), std::string::npos) << r.err;
}

TEST_F(CompareCli, WritesTheMaps) {
  const std::string heat = dir + "/heat.png", mismatch = dir + "/mismatch.png", depth = dir + "/depth.png";
  const auto r = runRastray({"compare", a, b, "--scene", scene, "--spp", "1", "--heatmap", heat,
                             "--mismatch-map", mismatch, "--depth-map", depth});
  ASSERT_EQ(r.status, 0) << r.err;
  for (const std::string& p : {heat, mismatch, depth}) EXPECT_TRUE(std::filesystem::exists(p)) << p;
  FlatImage map = readExr(a);  // only to keep the map's size in view: 8x8
  EXPECT_EQ(map.width, 8);
}

TEST_F(CompareCli, DeepFilesCompareSamplesAndLayers) {
  // 8×8 at 4 spp; pixel (5, 5) disagrees in all four samples (genuine with
  // the scene: every sample lies ≥ 1/8 px from yellow's bottom edge).
  DeepImage da, db;
  da.width = db.width = da.height = db.height = 8;
  da.offsets.push_back(0);
  db.offsets.push_back(0);
  for (int p = 0; p < 64; ++p) {
    for (uint32_t s = 0; s < 4; ++s) {
      if (p != 5 * 8 + 5) continue;
      DeepSample ya;
      ya.sample = s;
      ya.instance = 0;
      ya.depth = 0.5f;
      ya.color = {1, 1, 0, 1};
      DeepSample yb = ya;
      yb.instance = 1;
      yb.depth = 0.75f;
      da.samples.push_back(ya);
      db.samples.push_back(yb);
    }
    da.offsets.push_back(uint32_t(da.samples.size()));
    db.offsets.push_back(uint32_t(db.samples.size()));
  }
  writeDeepExr(dir + "/da.exr", da);
  writeDeepExr(dir + "/db.exr", db);
  const auto r =
      runRastray({"compare", dir + "/da.exr", dir + "/db.exr", "--scene", scene, "--spp", "4", "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["kind"], "deep");
  EXPECT_EQ(j["visibility"]["samples"]["compared"], 256);
  EXPECT_EQ(j["visibility"]["samples"]["mismatches"]["genuine"]["count"], 4);
  EXPECT_EQ(j["visibility"]["layers"]["compared"], 256);
  const auto fail = runRastray({"compare", dir + "/da.exr", dir + "/db.exr", "--max-genuine", "3"});
  EXPECT_EQ(fail.status, 1) << fail.out << fail.err;
}

TEST_F(CompareCli, FileFromAnotherRendererWithoutIds) {
  // RGBA only, as a renderer without AOVs writes it: every pixel reads as
  // "nothing hit", so every hit of A mismatches, and the report says why.
  const std::string rgba = dir + "/rgba.exr";
  const FlatImage fa = test::threeTrianglesFrame();
  {
    auto out = OIIO::ImageOutput::create(rgba);
    ASSERT_TRUE(out);
    OIIO::ImageSpec spec(8, 8, 4, OIIO::TypeDesc::FLOAT);
    ASSERT_TRUE(out->open(rgba, spec));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, fa.color.data()));
    out->close();
  }
  const auto r = runRastray({"compare", a, rgba, "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["visibility"]["pixels"]["mismatching"], 20);  // the 20 hits of the 8×8 frame
  ASSERT_EQ(j["notes"].size(), 1u);
  EXPECT_NE(j["notes"][0].get<std::string>().find("rgba.exr"), std::string::npos);
  EXPECT_EQ(j["color"]["rmsError"], 0.0);
}

}  // namespace
}  // namespace rastray
