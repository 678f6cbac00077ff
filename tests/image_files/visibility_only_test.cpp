// `rastray compare` against another renderer's visibility export: an EXR
// with only Z, id.instance and id.triangle (SPEC §6), flat and deep. The
// full file is a real rastray render; the visibility-only one is made from
// it with one hit changed, so the expected numbers are known exactly.
#include <OpenImageIO/deepdata.h>
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>

#include "common/image.h"
#include "common/scene.h"
#include "tests/app/run_command.h"
#include "tests/compare/frames.h"

namespace rastray {
namespace {

using nlohmann::json;
using test::runRastray;

const char* const kVisibilityChannels[] = {"Z", "id.instance", "id.triangle"};

OIIO::ImageSpec visibilitySpec(int w, int h, bool deep) {
  OIIO::ImageSpec spec(w, h, 3, OIIO::TypeFloat);
  spec.channelnames.assign(std::begin(kVisibilityChannels), std::end(kVisibilityChannels));
  spec.channelformats = {OIIO::TypeFloat, OIIO::TypeUInt32, OIIO::TypeUInt32};
  spec.alpha_channel = -1;
  spec.z_channel = 0;
  spec.deep = deep;
  return spec;
}

// Z and the IDs of `image`, nothing else, as another renderer exports them.
void writeVisibilityOnly(const std::string& file, const FlatImage& image) {
  const OIIO::ImageSpec spec = visibilitySpec(image.width, image.height, false);
  std::vector<char> native(spec.image_bytes(true));
  for (size_t i = 0; i < image.depth.size(); ++i) {
    char* p = native.data() + 12 * i;
    std::memcpy(p, &image.depth[i], 4);
    std::memcpy(p + 4, &image.instance[i], 4);
    std::memcpy(p + 8, &image.triangle[i], 4);
  }
  auto out = OIIO::ImageOutput::create(file);
  ASSERT_TRUE(out && out->open(file, spec)) << OIIO::geterror();
  ASSERT_TRUE(out->write_image(OIIO::TypeUnknown, native.data())) << out->geterror();
  ASSERT_TRUE(out->close());
}

// The deep variant: no id.sample either, so it fits 1-spp files.
void writeVisibilityOnly(const std::string& file, const DeepImage& image) {
  const OIIO::ImageSpec spec = visibilitySpec(image.width, image.height, true);
  OIIO::DeepData deep(spec);
  const size_t pixels = image.offsets.size() - 1;
  for (size_t p = 0; p < pixels; ++p)
    deep.set_samples(int64_t(p), int(image.offsets[p + 1] - image.offsets[p]));
  for (size_t p = 0; p < pixels; ++p)
    for (uint64_t i = image.offsets[p]; i < image.offsets[p + 1]; ++i) {
      const int s = int(i - image.offsets[p]);
      const DeepSample& d = image.samples[i];
      deep.set_deep_value(int64_t(p), 0, s, d.depth);
      deep.set_deep_value(int64_t(p), 1, s, d.instance);
      deep.set_deep_value(int64_t(p), 2, s, d.triangle);
    }
  auto out = OIIO::ImageOutput::create(file);
  ASSERT_TRUE(out && out->open(file, spec)) << OIIO::geterror();
  ASSERT_TRUE(out->write_deep_image(deep)) << out->geterror();
  ASSERT_TRUE(out->close());
}

int lineCount(const std::string& s) { return int(std::count(s.begin(), s.end(), '\n')); }

class VisibilityOnly : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = test::makeTempDir("visonly");
    full = dir + "/full.exr";
    vis = dir + "/vis.exr";
    const auto r =
        runRastray({"render", scene, "--renderer", "raster", "--size", "8", "8", "--spp", "1", "-o", full});
    ASSERT_EQ(r.status, 0) << r.err;
    FlatImage image = readExr(full);
    ASSERT_TRUE(image.hasColor);
    // One hit becomes "nothing": exactly one mismatching pixel.
    for (size_t i = 0; i < image.instance.size(); ++i) hits += image.instance[i] != kNoId;
    const auto first =
        std::find_if(image.instance.begin(), image.instance.end(), [](uint32_t id) { return id != kNoId; });
    ASSERT_NE(first, image.instance.end());
    const size_t k = size_t(first - image.instance.begin());
    image.instance[k] = image.triangle[k] = kNoId;
    image.depth[k] = std::numeric_limits<float>::infinity();
    writeVisibilityOnly(vis, image);
  }

  std::string dir, full, vis;
  uint64_t hits = 0;  // in the full render
  const std::string scene = test::scenePath("three-triangles.gltf");
};

TEST_F(VisibilityOnly, FlatComparesVisibilityAndSaysColourWasSkipped) {
  const auto r = runRastray({"compare", full, vis});
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("colour: skipped (" + vis + " has no R G B channels"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("PSNR"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("63 agree"), std::string::npos) << r.out;
}

TEST_F(VisibilityOnly, FlatJsonHasVisibilityNumbersAndColourSkipped) {
  const auto r = runRastray({"compare", vis, full, "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["visibility"]["pixels"]["compared"], 64);
  EXPECT_EQ(j["visibility"]["pixels"]["agreeing"], 63);
  EXPECT_EQ(j["visibility"]["pixels"]["mismatching"], 1);
  // Depth is compared on the hits both files share, exactly equal here.
  EXPECT_EQ(j["depthError"]["count"], hits - 1);
  EXPECT_EQ(j["depthError"]["maxAbsolute"], 0.0);
  ASSERT_TRUE(j["color"].is_object());
  EXPECT_EQ(j["color"].size(), 1u) << j["color"];
  EXPECT_EQ(j["color"]["skipped"], vis + " has no R G B channels: visibility and depth only");
  EXPECT_EQ(j["passed"], true);
}

TEST_F(VisibilityOnly, BothWithoutColourNamesBoth) {
  const std::string vis2 = dir + "/vis2.exr";
  std::filesystem::copy_file(vis, vis2);
  const auto r = runRastray({"compare", vis, vis2, "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["color"]["skipped"],
            vis + " and " + vis2 + " have no R G B channels: visibility and depth only");
  EXPECT_EQ(j["visibility"]["pixels"]["agreeing"], 64);
}

TEST_F(VisibilityOnly, ColourOptionsCannotApplyAndExitTwo) {
  auto r = runRastray({"compare", full, vis, "--fail-rms", "0.1"});
  EXPECT_EQ(r.status, 2) << r.out << r.err;
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("--fail-rms: cannot apply: colour skipped"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;

  const std::string heat = dir + "/heat.png";
  r = runRastray({"compare", full, vis, "--heatmap", heat});
  EXPECT_EQ(r.status, 2) << r.out << r.err;
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("--heatmap"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(heat));
}

TEST_F(VisibilityOnly, VisibilityThresholdsStillApply) {
  auto r = runRastray({"compare", full, vis, "--min-agreement", "1"});  // 63/64
  EXPECT_EQ(r.status, 1) << r.out << r.err;
  EXPECT_NE(r.err.find("--min-agreement"), std::string::npos) << r.err;
  r = runRastray({"compare", full, vis, "--min-agreement", "0.98", "--mismatch-map", dir + "/m.png"});
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_TRUE(std::filesystem::exists(dir + "/m.png"));
}

TEST_F(VisibilityOnly, DeepComparesLayersAndSaysColourWasSkipped) {
  const std::string deepFull = dir + "/deep_full.exr", deepVis = dir + "/deep_vis.exr";
  const auto render = runRastray(
      {"render", scene, "--renderer", "raster", "--size", "8", "8", "--spp", "1", "--deep", "-o", deepFull});
  ASSERT_EQ(render.status, 0) << render.err;
  DeepImage image = readDeepExr(deepFull);
  ASSERT_TRUE(image.hasColor);
  ASSERT_FALSE(image.samples.empty());
  const uint64_t layers = image.samples.size();
  // One hit layer gets an instance no scene has: one mismatching layer.
  const auto hit = std::find_if(image.samples.begin(), image.samples.end(),
                                [](const DeepSample& d) { return d.instance != kNoId; });
  ASSERT_NE(hit, image.samples.end());
  hit->instance += 100;
  writeVisibilityOnly(deepVis, image);

  const auto r = runRastray({"compare", deepFull, deepVis, "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["kind"], "deep");
  // 1 spp, opaque: at most one layer per pixel, so 64 compared, of which
  // the pixels without a layer agree as both empty.
  EXPECT_EQ(j["visibility"]["layers"]["compared"], 64);
  EXPECT_EQ(j["visibility"]["layers"]["bothEmpty"], 64 - layers);
  EXPECT_EQ(j["visibility"]["layers"]["mismatching"], 1);
  EXPECT_EQ(j["color"]["skipped"], deepVis + " has no R G B channels: visibility and depth only");

  const auto table = runRastray({"compare", deepFull, deepVis});
  ASSERT_EQ(table.status, 0) << table.err;
  EXPECT_NE(table.out.find("colour: skipped"), std::string::npos) << table.out;
}

TEST_F(VisibilityOnly, SppAboveTheLimitIsRefused) {
  const auto r = runRastray({"compare", full, vis, "--spp", "289"});
  EXPECT_EQ(r.status, 2) << r.out << r.err;
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("256"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace rastray
