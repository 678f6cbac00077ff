// The EXR readers on files with a subset of the SPEC §6 channels (another
// renderer's visibility export: Z and IDs only), the deep `cutoff` channel
// and the width of deep-image offsets.
#include <unistd.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

#include <OpenImageIO/deepdata.h>
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include "common/error.h"
#include "common/image.h"
#include "common/scene.h"
#include "tests/test_files.h"

namespace rastray {
namespace {

namespace fs = std::filesystem;

constexpr float kInf = std::numeric_limits<float>::infinity();

class ImageChannelsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::scratchDir();  // removed when the test passes
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  fs::path dir_;
};

// A flat EXR with exactly `names` (each in `formats`), one row of values per
// pixel given as doubles and converted to each channel's format.
void writeFlat(const std::string& file, int w, int h, const std::vector<std::string>& names,
               const std::vector<OIIO::TypeDesc>& formats, const std::vector<double>& values) {
  OIIO::ImageSpec spec(w, h, int(names.size()), OIIO::TypeFloat);
  spec.channelnames = names;
  spec.channelformats = formats;
  spec.alpha_channel = -1;
  spec.z_channel = -1;
  std::vector<char> native(spec.image_bytes(true));
  char* p = native.data();
  for (size_t i = 0; i < values.size(); ++i) {
    const OIIO::TypeDesc t = formats[i % names.size()];
    if (t == OIIO::TypeUInt32) {
      const uint32_t v = uint32_t(values[i]);
      std::memcpy(p, &v, 4);
    } else {
      const float v = float(values[i]);
      std::memcpy(p, &v, 4);
    }
    p += 4;
  }
  auto out = OIIO::ImageOutput::create(file);
  ASSERT_TRUE(out && out->open(file, spec)) << OIIO::geterror();
  ASSERT_TRUE(out->write_image(OIIO::TypeUnknown, native.data())) << out->geterror();
  ASSERT_TRUE(out->close());
}

TEST_F(ImageChannelsTest, FlatVisibilityOnlyFileReadsWithoutColour) {
  const std::string file = path("vis.exr");
  writeFlat(file, 2, 1, {"Z", "id.instance", "id.triangle"},
            {OIIO::TypeFloat, OIIO::TypeUInt32, OIIO::TypeUInt32},
            {1.5, 3, 7, double(kInf), double(kNoId), double(kNoId)});
  const FlatImage image = readExr(file);
  ASSERT_EQ(image.width, 2);
  EXPECT_FALSE(image.hasColor);
  EXPECT_EQ(image.depth[0], 1.5f);
  EXPECT_EQ(image.instance[0], 3u);
  EXPECT_EQ(image.triangle[0], 7u);
  EXPECT_EQ(image.depth[1], kInf);
  EXPECT_EQ(image.instance[1], kNoId);
  // No colour: RGB stay 0 and, without A, alpha reads as 1 as always.
  EXPECT_EQ(image.color[0], glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
}

TEST_F(ImageChannelsTest, FlatFileWithOnlyAlphaHasNoColourButKeepsAlpha) {
  const std::string file = path("alpha.exr");
  writeFlat(file, 2, 1, {"A"}, {OIIO::TypeFloat}, {0.25, 1.0});
  const FlatImage image = readExr(file);
  EXPECT_FALSE(image.hasColor);
  EXPECT_EQ(image.color[0].a, 0.25f);
  EXPECT_EQ(image.color[1].a, 1.0f);
  EXPECT_EQ(image.instance[0], kNoId);
  EXPECT_EQ(image.depth[0], kInf);
}

TEST_F(ImageChannelsTest, FlatFileWithColourHasColour) {
  const std::string file = path("rgb.exr");
  writeFlat(file, 1, 1, {"R", "G", "B"}, {OIIO::TypeFloat, OIIO::TypeFloat, OIIO::TypeFloat}, {1, 2, 3});
  EXPECT_TRUE(readExr(file).hasColor);
}

TEST_F(ImageChannelsTest, FileWithNoneOfTheChannelsIsRefusedAndListsWhatItHas) {
  const std::string file = path("luminance.exr");
  writeFlat(file, 1, 1, {"Y", "beauty.R"}, {OIIO::TypeFloat, OIIO::TypeFloat}, {1, 2});
  try {
    readExr(file);
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), file);
    EXPECT_EQ(e.element(), "channels");
    EXPECT_NE(e.message().find("beauty.R"), std::string::npos) << e.what();
  }
}

// A deep file with one pixel of `n` layers and only the given uint/float
// channels: channel c of layer s holds values[s * names.size() + c].
void writeDeep(const std::string& file, const std::vector<std::string>& names,
               const std::vector<OIIO::TypeDesc>& formats, int n, const std::vector<double>& values) {
  OIIO::ImageSpec spec(1, 1, int(names.size()), OIIO::TypeFloat);
  spec.channelnames = names;
  spec.channelformats = formats;
  spec.alpha_channel = -1;
  spec.z_channel = -1;
  spec.deep = true;
  OIIO::DeepData deep(spec);
  deep.set_samples(0, n);
  for (int s = 0; s < n; ++s)
    for (size_t c = 0; c < names.size(); ++c) {
      const double v = values[size_t(s) * names.size() + c];
      if (formats[c] == OIIO::TypeUInt32)
        deep.set_deep_value(0, int(c), s, uint32_t(v));
      else
        deep.set_deep_value(0, int(c), s, float(v));
    }
  auto out = OIIO::ImageOutput::create(file);
  ASSERT_TRUE(out && out->open(file, spec)) << OIIO::geterror();
  ASSERT_TRUE(out->write_deep_image(deep)) << out->geterror();
  ASSERT_TRUE(out->close());
}

TEST_F(ImageChannelsTest, DeepVisibilityOnlyFileReadsWithoutColourOrCutOff) {
  const std::string file = path("vis_deep.exr");
  writeDeep(file, {"Z", "id.instance", "id.triangle"}, {OIIO::TypeFloat, OIIO::TypeUInt32, OIIO::TypeUInt32},
            2, {4.0, 1, 2, 2.0, 5, 6});
  const DeepImage image = readDeepExr(file);
  EXPECT_FALSE(image.hasColor);
  ASSERT_EQ(image.samples.size(), 2u);
  // Sorted front to back.
  EXPECT_EQ(image.samples[0].depth, 2.0f);
  EXPECT_EQ(image.samples[0].instance, 5u);
  EXPECT_EQ(image.samples[0].triangle, 6u);
  EXPECT_EQ(image.samples[1].instance, 1u);
  for (const DeepSample& d : image.samples) {
    EXPECT_FALSE(d.cutOff);
    EXPECT_EQ(d.color, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
  }
}

TEST_F(ImageChannelsTest, DeepCutoffReadsFromUintOrIntegralFloat) {
  const std::string file = path("cutoff_float.exr");
  writeDeep(file, {"Z", "id.instance", "id.triangle", "cutoff"},
            {OIIO::TypeFloat, OIIO::TypeUInt32, OIIO::TypeUInt32, OIIO::TypeFloat}, 2,
            {1.0, 0, 0, 0.0, 2.0, 1, 0, 1.0});
  const DeepImage image = readDeepExr(file);
  ASSERT_EQ(image.samples.size(), 2u);
  EXPECT_FALSE(image.samples[0].cutOff);
  EXPECT_TRUE(image.samples[1].cutOff);
}

TEST_F(ImageChannelsTest, CutoffChannelIsWrittenOnlyWhereTheRendererStopped) {
  DeepImage image;
  image.width = image.height = 1;
  image.offsets = {0, 3};
  image.samples.resize(3);
  for (uint32_t i = 0; i < 3; ++i) {
    image.samples[i].depth = float(i + 1);
    image.samples[i].instance = i;
    image.samples[i].triangle = 0;
  }
  image.samples[1].cutOff = true;
  const std::string file = path("cutoff.exr");
  writeDeepExr(file, image);
  // Read the raw channel, not through readDeepExr: the file must say it.
  auto in = OIIO::ImageInput::open(file);
  ASSERT_TRUE(in) << OIIO::geterror();
  const int c = in->spec().channelindex("cutoff");
  ASSERT_GE(c, 0);
  EXPECT_EQ(in->spec().channelformat(c), OIIO::TypeUInt32);
  OIIO::DeepData deep;
  ASSERT_TRUE(in->read_native_deep_image(0, 0, deep));
  ASSERT_EQ(deep.samples(0), 3);
  EXPECT_EQ(deep.deep_value_uint(0, c, 0), 0u);
  EXPECT_EQ(deep.deep_value_uint(0, c, 1), 1u);
  EXPECT_EQ(deep.deep_value_uint(0, c, 2), 0u);
  const DeepImage back = readDeepExr(file);
  ASSERT_EQ(back.samples.size(), 3u);
  EXPECT_FALSE(back.samples[0].cutOff);
  EXPECT_TRUE(back.samples[1].cutOff);
  EXPECT_FALSE(back.samples[2].cutOff);
}

TEST(DeepImageTest, OffsetsAre64BitAndHoldMoreThan2To32Entries) {
  EXPECT_TRUE((std::is_same_v<decltype(DeepImage::offsets)::value_type, uint64_t>));
  DeepImage image;
  image.offsets = {0, uint64_t(1) << 32};
  image.offsets.push_back(image.offsets.back() + 5);
  EXPECT_EQ(image.offsets[2] - image.offsets[1], 5u);
  EXPECT_GT(image.offsets[2], uint64_t(std::numeric_limits<uint32_t>::max()));
}

}  // namespace
}  // namespace rastray
