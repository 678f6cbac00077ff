#include "common/image.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <OpenImageIO/deepdata.h>
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include "common/error.h"
#include "common/scene.h"
#include "tests/test_files.h"

namespace rastray {
namespace {

namespace fs = std::filesystem;

constexpr float kInf = std::numeric_limits<float>::infinity();

// Each test gets an empty directory of its own under the system temp dir.
class ImageTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::scratchDir();  // removed when the test passes
  }
  void TearDown() override {
    // A test made it read-only: writable again, so it can be removed.
    std::error_code ignored;
    fs::permissions(dir_, fs::perms::owner_all, fs::perm_options::add, ignored);
  }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  // Names of the entries in `d` (default: the test directory), sorted.
  std::vector<std::string> entries(const fs::path& d) const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(d)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }
  std::vector<std::string> entries() const { return entries(dir_); }

  fs::path dir_;
};

// Channel name -> format, as OIIO reports the file.
std::map<std::string, std::string> channelFormats(const std::string& file) {
  auto in = OIIO::ImageInput::open(file);
  EXPECT_TRUE(in) << OIIO::geterror();
  std::map<std::string, std::string> formats;
  if (!in) return formats;
  for (int c = 0; c < in->spec().nchannels; ++c) {
    formats[in->spec().channelnames[c]] = in->spec().channelformat(c).c_str();
  }
  return formats;
}

// Writes a flat float EXR with the given channels directly through OIIO, as
// another renderer might. `values` holds one row of nchannels per pixel.
void writeForeignExr(const std::string& file, const OIIO::ImageSpec& spec, const std::vector<float>& values) {
  auto out = OIIO::ImageOutput::create(file);
  ASSERT_TRUE(out) << OIIO::geterror();
  ASSERT_TRUE(out->open(file, spec)) << out->geterror();
  ASSERT_TRUE(out->write_image(OIIO::TypeFloat, values.data())) << out->geterror();
  ASSERT_TRUE(out->close()) << out->geterror();
}

OIIO::ImageSpec floatSpec(int w, int h, std::vector<std::string> names) {
  OIIO::ImageSpec spec(w, h, int(names.size()), OIIO::TypeFloat);
  spec.channelnames = std::move(names);
  spec.alpha_channel = -1;
  spec.z_channel = -1;
  return spec;
}

FlatImage testImage() {
  FlatImage image(3, 2);
  image.color = {{0.25f, 0.5f, 0.75f, 1.0f}, {1.0f / 3.0f, 0.1f, 1e-3f, 0.5f},
                 {0.0f, 0.0f, 0.0f, 0.0f},   {4.0f, 100.0f, 1e-5f, 1.0f},
                 {0.2f, 0.3f, 0.4f, 0.6f},   {0.125f, 0.0625f, 2.0f, 1.0f}};
  image.depth = {1.5f, 1e30f, kInf, 1e-38f, 0.0f, 1.0f / 3.0f};
  // 16777217 = 2^24 + 1 has no float representation: a float round trip
  // would change it.
  image.instance = {0, 16777217u, kNoId, 0xFFFFFFFEu, 7, 123456789};
  image.triangle = {kNoId, 1, kNoId, 16777217u, 0, 3000000001u};
  return image;
}

void expectSameIdsAndDepth(const FlatImage& a, const FlatImage& b) {
  ASSERT_EQ(a.width, b.width);
  ASSERT_EQ(a.height, b.height);
  for (size_t i = 0; i < a.depth.size(); ++i) {
    EXPECT_EQ(a.depth[i], b.depth[i]) << "pixel " << i;
    EXPECT_EQ(a.instance[i], b.instance[i]) << "pixel " << i;
    EXPECT_EQ(a.triangle[i], b.triangle[i]) << "pixel " << i;
  }
}

TEST(SrgbTest, KnownValuesOfBothSegments) {
  // Reference values from the IEC 61966-2-1 formulas evaluated in double.
  EXPECT_EQ(linearToSrgb(0.0f), 0.0f);
  EXPECT_FLOAT_EQ(linearToSrgb(1.0f), 1.0f);
  EXPECT_FLOAT_EQ(linearToSrgb(0.5f), 0.7353569830524495f);
  EXPECT_FLOAT_EQ(linearToSrgb(0.002f), 0.02584f);  // linear segment: 12.92 v
  EXPECT_FLOAT_EQ(srgbToLinear(0.5f), 0.21404114048223255f);
  EXPECT_FLOAT_EQ(srgbToLinear(0.02f), 0.02f / 12.92f);
  EXPECT_FLOAT_EQ(srgbToLinear(1.0f), 1.0f);
  // The two segments meet at linear 0.0031308 / encoded 0.04045.
  EXPECT_NEAR(linearToSrgb(0.0031308f), 0.04045f, 1e-7f);
  EXPECT_NEAR(srgbToLinear(0.04045f), 0.0031308f, 1e-8f);
}

TEST(SrgbTest, EveryByteSurvivesARoundTrip) {
  for (int b = 0; b < 256; ++b) {
    const float encoded = float(b) / 255.0f;
    EXPECT_NEAR(linearToSrgb(srgbToLinear(encoded)), encoded, 2e-7f) << b;
  }
}

TEST(FlatImageTest, StartsTransparentEmptyAndUnhit) {
  const FlatImage image(4, 3);
  EXPECT_EQ(image.width, 4);
  EXPECT_EQ(image.height, 3);
  ASSERT_EQ(image.color.size(), 12u);
  ASSERT_EQ(image.depth.size(), 12u);
  ASSERT_EQ(image.instance.size(), 12u);
  ASSERT_EQ(image.triangle.size(), 12u);
  for (size_t i = 0; i < 12; ++i) {
    EXPECT_EQ(image.color[i], glm::vec4(0.0f));
    EXPECT_EQ(image.depth[i], kInf);
    EXPECT_EQ(image.instance[i], kNoId);
    EXPECT_EQ(image.triangle[i], kNoId);
  }
  EXPECT_EQ(image.index(1, 2), 9u);
}

TEST_F(ImageTest, PngIsStraightSrgbRoundedToNearest) {
  FlatImage image(2, 2);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  image.color = {
      {0.25f, 0.1f, 0.0f, 0.5f},   // straight (0.5, 0.2, 0), alpha 127.5 rounds up
      {0.3f, 0.6f, 0.9f, 0.0f},    // alpha 0: colour 0 whatever was stored
      {2.0f, 1.0f, 0.002f, 1.0f},  // clamps; 0.002 on the linear segment
      {-0.1f, nan, 0.04f, 0.8f},   // negative and NaN clamp to 0; 0.04 / 0.8 = 0.05
  };
  const std::string file = path("out.png");
  writeImage(file, image);

  // Ask OIIO for the bytes as stored: by default it would premultiply them.
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  auto in = OIIO::ImageInput::open(file, &config);
  ASSERT_TRUE(in) << OIIO::geterror();
  EXPECT_STREQ(in->format_name(), "png");
  ASSERT_EQ(in->spec().nchannels, 4);
  EXPECT_EQ(in->spec().format, OIIO::TypeUInt8);
  std::vector<uint8_t> bytes(16);
  ASSERT_TRUE(in->read_image(0, 0, 0, 4, OIIO::TypeUInt8, bytes.data())) << in->geterror();
  // sRGB(0.5) = 0.73536 -> 187.52; sRGB(0.2) = 0.48453 -> 123.55;
  // 12.92 * 0.002 -> 6.59; sRGB(0.05) = 0.24780 -> 63.19; 0.8 -> 204.
  const std::vector<uint8_t> expected = {188, 124, 0,  128,  //
                                         0,   0,   0,  0,    //
                                         255, 255, 7,  255,  //
                                         0,   0,   63, 204};
  EXPECT_EQ(bytes, expected);
  EXPECT_EQ(entries(), std::vector<std::string>{"out.png"});
}

// exrChannelType reads a channel's stored type through the module's
// checked EXR opening (sweep --reference asks it of R). Its first version
// read the type from a spec whose ImageInput was already gone.
TEST_F(ImageTest, ExrChannelTypeNamesEachChannelsStoredType) {
  const std::string half = path("half.exr"), full = path("float.exr");
  writeImage(half, testImage(), ColorPrecision::Half);
  writeImage(full, testImage(), ColorPrecision::Float);
  for (const auto& [file, color] : {std::pair{half, "half"}, std::pair{full, "float"}}) {
    for (const char* c : {"R", "G", "B", "A"}) EXPECT_EQ(exrChannelType(file, c), color) << file << " " << c;
    EXPECT_EQ(exrChannelType(file, "Z"), "float");
    EXPECT_EQ(exrChannelType(file, "id.instance"), "uint");
    EXPECT_EQ(exrChannelType(file, "Y"), "");
  }
  EXPECT_THROW(exrChannelType(path("missing.exr"), "R"), InputError);
}

TEST_F(ImageTest, ExrRoundTripsEveryChannelExactlyInFloat) {
  const FlatImage image = testImage();
  const std::string file = path("flat.exr");
  writeImage(file, image, ColorPrecision::Float);

  const std::map<std::string, std::string> expectedFormats = {
      {"R", "float"}, {"G", "float"},          {"B", "float"},         {"A", "float"},
      {"Z", "float"}, {"id.instance", "uint"}, {"id.triangle", "uint"}};
  EXPECT_EQ(channelFormats(file), expectedFormats);
  EXPECT_FALSE(isDeepExr(file));

  const FlatImage back = readExr(file);
  expectSameIdsAndDepth(image, back);
  for (size_t i = 0; i < image.color.size(); ++i) EXPECT_EQ(back.color[i], image.color[i]) << i;
  EXPECT_EQ(entries(), std::vector<std::string>{"flat.exr"});
}

TEST_F(ImageTest, ExrHalfColourRoundsButKeepsDepthAndIdsExact) {
  FlatImage image = testImage();
  image.color[0] = {1.0f / 3.0f, 0.1f, 1.0f, 1.0f};
  const std::string halfFile = path("half.exr"), floatFile = path("float.exr");
  writeExr(halfFile, image);  // half is the default
  writeExr(floatFile, image, ColorPrecision::Float);

  EXPECT_EQ(channelFormats(halfFile)["R"], "half");
  EXPECT_EQ(channelFormats(halfFile)["A"], "half");
  EXPECT_EQ(channelFormats(halfFile)["Z"], "float");
  EXPECT_EQ(channelFormats(halfFile)["id.triangle"], "uint");

  const FlatImage half = readExr(halfFile);
  const FlatImage full = readExr(floatFile);
  // 1/3 and 0.1 in half (round to nearest): 0x3555 and 0x2E66.
  EXPECT_EQ(half.color[0].r, 0.333251953125f);
  EXPECT_EQ(half.color[0].g, 0.0999755859375f);
  EXPECT_EQ(half.color[0].b, 1.0f);
  EXPECT_EQ(full.color[0].r, 1.0f / 3.0f);
  EXPECT_EQ(full.color[0].g, 0.1f);
  for (size_t i = 0; i < image.color.size(); ++i) {
    for (int k = 0; k < 4; ++k) {
      // Rounding to half errs by at most 2^-11 relative, or 2^-25 (half a
      // step) among the subnormals below 2^-14.
      const float v = image.color[i][k];
      EXPECT_NEAR(half.color[i][k], v, std::max(std::abs(v) * 0x1p-11f, 0x1p-25f)) << i << " " << k;
    }
  }
  expectSameIdsAndDepth(image, half);
}

TEST_F(ImageTest, WriteImageChoosesTheFormatByExtensionInAnyCase) {
  const FlatImage image = testImage();
  writeImage(path("a.EXR"), image);
  writeImage(path("b.Png"), image);
  auto exr = OIIO::ImageInput::open(path("a.EXR"));
  auto png = OIIO::ImageInput::open(path("b.Png"));
  ASSERT_TRUE(exr && png);
  EXPECT_STREQ(exr->format_name(), "openexr");
  EXPECT_STREQ(png->format_name(), "png");
}

TEST_F(ImageTest, WriteReplacesAnExistingFileAndLeavesNoTemporary) {
  const std::string file = path("out.exr");
  FlatImage first(2, 2), second(2, 2);
  second.depth.assign(4, 5.0f);
  writeExr(file, first);
  writeExr(file, second);
  EXPECT_EQ(readExr(file).depth, second.depth);
  EXPECT_EQ(entries(), std::vector<std::string>{"out.exr"});
}

TEST_F(ImageTest, ReadExrDefaultsMissingAlphaDepthAndIds) {
  const std::string file = path("rgb.exr");
  writeForeignExr(file, floatSpec(2, 1, {"R", "G", "B"}), {0.1f, 0.2f, 0.3f, 4.0f, 5.0f, 6.0f});
  const FlatImage image = readExr(file);
  ASSERT_EQ(image.width, 2);
  ASSERT_EQ(image.height, 1);
  EXPECT_EQ(image.color[0], glm::vec4(0.1f, 0.2f, 0.3f, 1.0f));
  EXPECT_EQ(image.color[1], glm::vec4(4.0f, 5.0f, 6.0f, 1.0f));
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(image.depth[i], kInf);
    EXPECT_EQ(image.instance[i], kNoId);
    EXPECT_EQ(image.triangle[i], kNoId);
  }
}

TEST_F(ImageTest, ReadExrTakesIntegralFloatIds) {
  const std::string file = path("floatids.exr");
  // 2^32 is what 0xFFFFFFFF becomes in float.
  writeForeignExr(file, floatSpec(3, 1, {"R", "G", "B", "A", "Z", "id.instance", "id.triangle"}),
                  {0, 0, 0, 1, 2.0f, 0.0f,          12.0f,  //
                   0, 0, 0, 1, 3.0f, 16777216.0f,   5.0f,   //
                   0, 0, 0, 0, kInf, 4294967296.0f, 4294967296.0f});
  const FlatImage image = readExr(file);
  EXPECT_EQ(image.instance, (std::vector<uint32_t>{0, 16777216u, kNoId}));
  EXPECT_EQ(image.triangle, (std::vector<uint32_t>{12, 5, kNoId}));
  EXPECT_EQ(image.depth, (std::vector<float>{2.0f, 3.0f, kInf}));
}

TEST_F(ImageTest, ReadExrRejectsFractionalIds) {
  const std::string file = path("badids.exr");
  writeForeignExr(file, floatSpec(2, 1, {"R", "G", "B", "id.instance"}), {0, 0, 0, 1.0f, 0, 0, 0, 2.5f});
  try {
    readExr(file);
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), file);
    EXPECT_EQ(e.element(), "channel id.instance");
    EXPECT_NE(e.message().find("pixel (1, 0)"), std::string::npos) << e.what();
  }
}

TEST_F(ImageTest, ReadExrTakesAPartialColourSetAsNoColour) {
  // R and B without G: colour cannot be compared without guessing G, so the
  // image has no colour (SPEC §6: any subset of the channels is accepted).
  const std::string file = path("noG.exr");
  writeForeignExr(file, floatSpec(1, 1, {"R", "B", "A"}), {1, 2, 0.5f});
  const FlatImage image = readExr(file);
  EXPECT_FALSE(image.hasColor);
  EXPECT_EQ(image.color[0], glm::vec4(0.0f, 0.0f, 0.0f, 0.5f));
}

TEST_F(ImageTest, ReadExrPlacesACroppedDataWindowInTheDisplayWindow) {
  const std::string file = path("crop.exr");
  OIIO::ImageSpec spec = floatSpec(2, 1, {"R", "G", "B", "A", "Z"});
  spec.x = 11;
  spec.y = 21;
  spec.full_x = 10;
  spec.full_y = 20;
  spec.full_width = 4;
  spec.full_height = 3;
  writeForeignExr(file, spec, {1, 2, 3, 1, 7.0f, 4, 5, 6, 1, 8.0f});
  const FlatImage image = readExr(file);
  ASSERT_EQ(image.width, 4);
  ASSERT_EQ(image.height, 3);
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 4; ++x) {
      const size_t i = image.index(x, y);
      if (y == 1 && (x == 1 || x == 2)) {
        EXPECT_EQ(image.color[i], x == 1 ? glm::vec4(1, 2, 3, 1) : glm::vec4(4, 5, 6, 1));
        EXPECT_EQ(image.depth[i], x == 1 ? 7.0f : 8.0f);
      } else {
        EXPECT_EQ(image.color[i], glm::vec4(0.0f)) << x << "," << y;
        EXPECT_EQ(image.depth[i], kInf) << x << "," << y;
      }
      EXPECT_EQ(image.instance[i], kNoId);
    }
  }
}

DeepImage testDeepImage() {
  DeepImage image;
  image.width = 3;
  image.height = 2;
  const std::vector<uint32_t> counts = {0, 1, 3, 0, 2, 5};
  image.offsets = {0};
  for (uint32_t n : counts) image.offsets.push_back(image.offsets.back() + n);
  // Sorted by (sample, depth, instance, triangle) within each pixel, as
  // DeepImage requires and readDeepExr returns.
  uint32_t k = 0;
  for (size_t p = 0; p < counts.size(); ++p) {
    for (uint32_t s = 0; s < counts[p]; ++s, ++k) {
      DeepSample d;
      d.color = {0.1f * float(k), 1.0f / float(k + 3), 0.5f, 0.25f + 0.125f * float(s)};
      d.depth = 1.0f + float(s) / 3.0f;
      d.instance = s == 1 ? kNoId : 16777217u + k;
      d.triangle = 3000000000u + k;
      d.sample = s / 2;  // two layers in sample 0, two in sample 1, ...
      d.cutOff = k % 3 == 1;
      image.samples.push_back(d);
    }
  }
  image.samples.back().depth = kInf;
  return image;
}

// Issue 13: the same image gives the same bytes. OIIO stamps DateTime into
// EXR headers unless told otherwise; neither flat nor deep files carry it,
// and two writes a second apart are identical.
TEST_F(ImageTest, ExrHeadersCarryNoTimestamp) {
  const std::string flat = path("flat.exr"), deep = path("deep.exr");
  writeExr(flat, testImage(), ColorPrecision::Half);
  writeDeepExr(deep, testDeepImage());
  for (const std::string& file : {flat, deep}) {
    auto in = OIIO::ImageInput::open(file);
    ASSERT_TRUE(in) << file;
    EXPECT_EQ(in->spec().find_attribute("DateTime"), nullptr) << file;
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));  // DateTime has whole seconds
  const std::string again = path("again.exr");
  writeExr(again, testImage(), ColorPrecision::Half);
  const auto bytes = [](const std::string& f) {
    std::ifstream in(f, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  EXPECT_EQ(bytes(flat), bytes(again));
}

TEST_F(ImageTest, DeepExrRoundTripsEverySampleExactly) {
  const DeepImage image = testDeepImage();
  const std::string file = path("deep.exr");
  writeDeepExr(file, image);
  EXPECT_TRUE(isDeepExr(file));
  const std::map<std::string, std::string> expectedFormats = {
      {"R", "float"},          {"G", "float"},        {"B", "float"},
      {"A", "float"},          {"Z", "float"},        {"id.instance", "uint"},
      {"id.triangle", "uint"}, {"id.sample", "uint"}, {"cutoff", "uint"}};
  EXPECT_EQ(channelFormats(file), expectedFormats);

  const DeepImage back = readDeepExr(file);
  ASSERT_EQ(back.width, 3);
  ASSERT_EQ(back.height, 2);
  EXPECT_EQ(back.offsets, image.offsets);
  ASSERT_EQ(back.samples.size(), image.samples.size());
  for (size_t i = 0; i < image.samples.size(); ++i) {
    const DeepSample &a = image.samples[i], &b = back.samples[i];
    EXPECT_EQ(b.color, a.color) << i;
    EXPECT_EQ(b.depth, a.depth) << i;
    EXPECT_EQ(b.instance, a.instance) << i;
    EXPECT_EQ(b.triangle, a.triangle) << i;
    EXPECT_EQ(b.sample, a.sample) << i;
    EXPECT_EQ(b.cutOff, a.cutOff) << i;
  }
  EXPECT_TRUE(back.hasColor);
  EXPECT_EQ(entries(), std::vector<std::string>{"deep.exr"});
}

TEST_F(ImageTest, DeepExrWithNoSamplesAtAll) {
  DeepImage image;
  image.width = 2;
  image.height = 2;
  image.offsets.assign(5, 0);
  const std::string file = path("empty.exr");
  writeDeepExr(file, image);
  const DeepImage back = readDeepExr(file);
  EXPECT_EQ(back.width, 2);
  EXPECT_EQ(back.offsets, image.offsets);
  EXPECT_TRUE(back.samples.empty());
}

TEST_F(ImageTest, ReadDeepExrDefaultsMissingChannelsAndSortsFrontToBack) {
  // A deep file as another renderer might write it: half RGBA, float Z, no
  // IDs, layers not in depth order.
  const std::string file = path("foreign_deep.exr");
  OIIO::ImageSpec spec(2, 1, 4, OIIO::TypeHalf);
  spec.channelnames = {"R", "G", "B", "Z"};
  spec.channelformats = {OIIO::TypeHalf, OIIO::TypeHalf, OIIO::TypeHalf, OIIO::TypeFloat};
  spec.alpha_channel = -1;
  spec.z_channel = 3;
  spec.deep = true;
  OIIO::DeepData deep(spec);
  deep.set_samples(0, 0);
  deep.set_samples(1, 3);
  const float depths[3] = {5.0f, 2.0f, 3.5f};
  for (int s = 0; s < 3; ++s) {
    for (int c = 0; c < 3; ++c) deep.set_deep_value(1, c, s, 0.25f * float(s + 1));
    deep.set_deep_value(1, 3, s, depths[s]);
  }
  {
    auto out = OIIO::ImageOutput::create(file);
    ASSERT_TRUE(out && out->open(file, spec)) << OIIO::geterror();
    ASSERT_TRUE(out->write_deep_image(deep)) << out->geterror();
    ASSERT_TRUE(out->close());
  }

  const DeepImage image = readDeepExr(file);
  EXPECT_EQ(image.offsets, (std::vector<uint64_t>{0, 0, 3}));
  ASSERT_EQ(image.samples.size(), 3u);
  const float sortedDepth[3] = {2.0f, 3.5f, 5.0f};
  const float sortedColor[3] = {0.5f, 0.75f, 0.25f};
  for (int s = 0; s < 3; ++s) {
    const DeepSample& d = image.samples[s];
    EXPECT_EQ(d.depth, sortedDepth[s]);
    EXPECT_EQ(d.color, glm::vec4(sortedColor[s], sortedColor[s], sortedColor[s], 1.0f));
    EXPECT_EQ(d.instance, kNoId);
    EXPECT_EQ(d.triangle, kNoId);
    EXPECT_EQ(d.sample, 0u);
  }
}

TEST_F(ImageTest, ReadDeepExrPlacesACroppedDataWindowAndTakesFloatIds) {
  // Display window 3x2, data window the single pixel (1, 1), IDs as float.
  const std::string file = path("cropped_deep.exr");
  OIIO::ImageSpec spec(1, 1, 7, OIIO::TypeFloat);
  spec.channelnames = {"R", "G", "B", "A", "Z", "id.instance", "id.sample"};
  spec.alpha_channel = 3;
  spec.z_channel = 4;
  spec.x = 1;
  spec.y = 1;
  spec.full_width = 3;
  spec.full_height = 2;
  spec.deep = true;
  OIIO::DeepData deep(spec);
  deep.set_samples(0, 2);
  for (int s = 0; s < 2; ++s) {
    for (int c = 0; c < 4; ++c) deep.set_deep_value(0, c, s, 0.5f);
    deep.set_deep_value(0, 4, s, 2.0f);
    deep.set_deep_value(0, 5, s, s == 0 ? 4294967296.0f : 42.0f);
    deep.set_deep_value(0, 6, s, float(1 - s));  // sample 1 first in the file
  }
  {
    auto out = OIIO::ImageOutput::create(file);
    ASSERT_TRUE(out && out->open(file, spec)) << OIIO::geterror();
    ASSERT_TRUE(out->write_deep_image(deep)) << out->geterror();
    ASSERT_TRUE(out->close());
  }
  const DeepImage image = readDeepExr(file);
  ASSERT_EQ(image.width, 3);
  ASSERT_EQ(image.height, 2);
  EXPECT_EQ(image.offsets, (std::vector<uint64_t>{0, 0, 0, 0, 0, 2, 2}));
  ASSERT_EQ(image.samples.size(), 2u);
  EXPECT_EQ(image.samples[0].sample, 0u);
  EXPECT_EQ(image.samples[0].instance, 42u);
  EXPECT_EQ(image.samples[1].sample, 1u);
  EXPECT_EQ(image.samples[1].instance, kNoId);
  EXPECT_EQ(image.samples[1].triangle, kNoId);
  EXPECT_EQ(image.samples[1].color, glm::vec4(0.5f));
  EXPECT_EQ(image.samples[1].depth, 2.0f);
}

TEST_F(ImageTest, FlatAndDeepReadersRefuseTheOtherKind) {
  const std::string flat = path("flat.exr"), deep = path("deep.exr");
  writeExr(flat, FlatImage(2, 2));
  writeDeepExr(deep, testDeepImage());
  EXPECT_THROW(readExr(deep), InputError);
  EXPECT_THROW(readDeepExr(flat), InputError);
}

TEST_F(ImageTest, UnknownExtensionWritesNothing) {
  for (const std::string name : {"out.tif", "out", "out.jpg"}) {
    const std::string file = path(name);
    try {
      writeImage(file, FlatImage(2, 2));
      FAIL() << "no InputError for " << name;
    } catch (const InputError& e) {
      EXPECT_EQ(e.file(), file);
    }
  }
  EXPECT_TRUE(entries().empty());
}

TEST_F(ImageTest, MissingDirectoryThrowsAndLeavesNothing) {
  const std::string file = path("no/such/dir/out.exr");
  try {
    writeExr(file, FlatImage(2, 2));
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), file);
    EXPECT_EQ(e.element(), "");
  }
  EXPECT_THROW(writePng(path("no/out.png"), FlatImage(2, 2)), InputError);
  EXPECT_THROW(writeDeepExr(path("no/deep.exr"), testDeepImage()), InputError);
  EXPECT_TRUE(entries().empty());
}

TEST_F(ImageTest, ReadOnlyDirectoryThrowsAndLeavesNothing) {
  const fs::path locked = dir_ / "locked";
  fs::create_directory(locked);
  fs::permissions(locked, fs::perms::owner_read | fs::perms::owner_exec);
  if (::access(locked.c_str(), W_OK) == 0) {
    GTEST_SKIP() << "running with privileges that ignore directory permissions";
  }
  EXPECT_THROW(writeExr((locked / "out.exr").string(), FlatImage(2, 2)), InputError);
  EXPECT_TRUE(entries(locked).empty());
}

// The temporary file is written completely and only the rename fails: it
// must be removed, and the target left as it was.
TEST_F(ImageTest, FailedRenameRemovesTheTemporaryFile) {
  const fs::path target = dir_ / "target.exr";
  fs::create_directory(target);
  fs::create_directory(target / "keep");  // a non-empty directory cannot be replaced
  EXPECT_THROW(writeExr(target.string(), FlatImage(2, 2)), InputError);
  EXPECT_THROW(writeDeepExr(target.string(), testDeepImage()), InputError);
  EXPECT_EQ(entries(), std::vector<std::string>{"target.exr"});
  EXPECT_EQ(entries(target), std::vector<std::string>{"keep"});
}

TEST_F(ImageTest, CorruptAndTruncatedExrThrowInputError) {
  // Large enough for many compressed chunks, varied so zip cannot shrink it
  // to nothing.
  FlatImage image(64, 64);
  for (size_t i = 0; i < image.color.size(); ++i) {
    image.color[i] = glm::vec4(float(i % 7) / 7.0f, float(i % 13) / 13.0f, float(i) * 1e-4f, 1.0f);
    image.depth[i] = 1.0f + float(i) * 0.37f;
    image.instance[i] = uint32_t(i * 2654435761u);
  }
  const std::string good = path("good.exr");
  writeExr(good, image, ColorPrecision::Float);
  DeepImage deep = testDeepImage();
  const std::string goodDeep = path("gooddeep.exr");
  writeDeepExr(goodDeep, deep);

  const auto truncatedCopy = [&](const std::string& from, const std::string& name) {
    const std::string to = path(name);
    fs::copy_file(from, to);
    fs::resize_file(to, fs::file_size(to) / 2);
    return to;
  };
  const std::string truncated = truncatedCopy(good, "truncated.exr");
  const std::string truncatedDeep = truncatedCopy(goodDeep, "truncateddeep.exr");
  // Zip-compressed pixel data with a damaged middle: zlib's checksum fails.
  const std::string damaged = path("damaged.exr");
  fs::copy_file(good, damaged);
  {
    std::fstream f(damaged, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(std::streamoff(fs::file_size(damaged) / 2));
    f << std::string(200, '\xAB');
  }
  const std::string garbage = path("garbage.exr");
  std::ofstream(garbage) << "this is not an OpenEXR file, although its name says so";

  const auto expectInputError = [](const std::string& file, auto read) {
    try {
      read(file, kNoReadLimit);
      ADD_FAILURE() << "no InputError for " << file;
    } catch (const InputError& e) {
      EXPECT_EQ(e.file(), file);
    }
  };
  expectInputError(truncated, readExr);
  expectInputError(truncatedDeep, readDeepExr);
  expectInputError(damaged, readExr);
  expectInputError(garbage, readExr);
  expectInputError(garbage, isDeepExr);
  expectInputError(path("missing.exr"), readExr);
  expectInputError(path("missing.exr"), isDeepExr);
}

TEST_F(ImageTest, ReadExrRefusesOtherFormats) {
  const std::string png = path("image.png");
  writePng(png, FlatImage(2, 2));
  EXPECT_THROW(readExr(png), InputError);
}

}  // namespace
}  // namespace rastray
