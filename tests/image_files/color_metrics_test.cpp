// Colour metrics on known differences, and the diagnostic maps read back
// from their PNG files.
#include "compare/color_metrics.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "compare/maps.h"
#include "tests/compare/frames.h"

namespace rastray {
namespace {

FlatImage uniform(int w, int h, glm::vec4 c) {
  FlatImage f(w, h);
  for (glm::vec4& p : f.color) p = c;
  return f;
}

TEST(ColorMetrics, UniformOffsetGivesKnownMeanRmsPsnr) {
  // RGB offset by 1/8, alpha equal: per-channel errors 1/8, 1/8, 1/8, 0.
  const FlatImage a = uniform(16, 8, {0.5f, 0.5f, 0.5f, 1.0f});
  const FlatImage b = uniform(16, 8, {0.625f, 0.625f, 0.625f, 1.0f});
  const ColorMetrics m = compareColors(a, b);
  EXPECT_NEAR(m.meanError, 0.125 * 3.0 / 4.0, 1e-9);
  const double rms = std::sqrt(0.125 * 0.125 * 3.0 / 4.0);
  EXPECT_NEAR(m.rmsError, rms, 1e-9);
  EXPECT_NEAR(m.psnr, 20.0 * std::log10(1.0 / rms), 1e-6);
  EXPECT_NEAR(m.maxError, 0.125, 1e-9);
  EXPECT_EQ(m.pixels, 128u);
  EXPECT_EQ(m.differingPixels, 128u);
}

TEST(ColorMetrics, IdenticalImages) {
  const FlatImage a = test::threeTrianglesFrame();
  const ColorMetrics m = compareColors(a, a);
  EXPECT_EQ(m.meanError, 0.0);
  EXPECT_EQ(m.rmsError, 0.0);
  EXPECT_TRUE(std::isinf(m.psnr) && m.psnr > 0);
  EXPECT_EQ(m.maxX, -1);
  EXPECT_EQ(m.differingPixels, 0u);
  EXPECT_EQ(m.yeeFailingPixels, 0u);
}

TEST(ColorMetrics, MaxErrorLocation) {
  const FlatImage a = uniform(16, 8, {0.2f, 0.2f, 0.2f, 1.0f});
  FlatImage b = a;
  b.color[b.index(3, 1)].g = 0.3f;
  b.color[b.index(11, 6)].b = 0.9f;  // the largest: 0.7 in channel B at (11, 6)
  const ColorMetrics m = compareColors(a, b);
  EXPECT_NEAR(m.maxError, 0.7, 1e-6);
  EXPECT_EQ(m.maxX, 11);
  EXPECT_EQ(m.maxY, 6);
  EXPECT_EQ(m.maxChannel, 2);
  EXPECT_EQ(m.differingPixels, 2u);
}

TEST(ColorMetrics, YeeSeesALargeChangeButNotAnInvisibleOne) {
  FlatImage a(64, 64), b(64, 64), c(64, 64);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const float g = float(x) / 63.0f;
      a.color[a.index(x, y)] = {g, g, g, 1.0f};
      c.color[c.index(x, y)] = {g * (1.0f + 1e-4f), g, g, 1.0f};  // far below visibility
      b.color[b.index(x, y)] = (x / 8 + y / 8) % 2 ? glm::vec4(1, 0, 0, 1) : glm::vec4(g, g, g, 1.0f);
    }
  EXPECT_EQ(compareColors(a, c).yeeFailingPixels, 0u);
  EXPECT_GT(compareColors(a, b).yeeFailingPixels, 100u);
}

TEST(ColorMetrics, DeepFlattenCompositesThenAverages) {
  // One pixel, 2 spp: sample 0 = a half-transparent red over opaque blue;
  // sample 1 = nothing. Box average over 2 samples.
  DeepImage d;
  d.width = d.height = 1;
  DeepSample red, blue;
  red.color = {0.5f, 0.0f, 0.0f, 0.5f};
  red.depth = 1.0f;
  blue.color = {0.0f, 0.0f, 1.0f, 1.0f};
  blue.depth = 2.0f;
  d.samples = {red, blue};
  d.offsets = {0, 2};
  const FlatImage f = flattenDeepColor(d, 2);
  EXPECT_FLOAT_EQ(f.color[0].r, 0.25f);
  EXPECT_FLOAT_EQ(f.color[0].b, 0.25f);
  EXPECT_FLOAT_EQ(f.color[0].a, 0.5f);
}

// A deep layer for colorWhereHitsAgree: hit (instance, 0) at `sample`.
DeepSample layer(uint32_t sample, uint32_t instance, glm::vec4 color) {
  DeepSample d;
  d.sample = sample;
  d.instance = instance;
  d.triangle = 0;
  d.color = color;
  return d;
}

TEST(ColorWhereHitsAgree, ComparesOnlySamplesWithTheSameHitList) {
  // Two pixels at 2 spp. Pixel 0: sample 0 has the same two layers in both
  // (second layer differs by 0.25 in green); sample 1 hits instance 1 in A
  // and instance 2 in B (a visibility difference, left out, although its
  // colour differs by 1). Pixel 1: sample 0 agrees with a 0.5 difference in
  // blue; sample 1 has one layer in A and two in B (left out).
  DeepImage a, b;
  a.width = b.width = 2;
  a.height = b.height = 1;
  const glm::vec4 grey(0.5f, 0.5f, 0.5f, 1.0f);
  a.samples = {layer(0, 1, grey), layer(0, 3, grey), layer(1, 1, {0, 0, 0, 1}),  // pixel 0
               layer(0, 4, grey), layer(1, 5, grey)};                            // pixel 1
  a.offsets = {0, 3, 5};
  b.samples = {layer(0, 1, grey),         layer(0, 3, {0.5f, 0.75f, 0.5f, 1.0f}),
               layer(1, 2, {1, 1, 1, 1}), layer(0, 4, {0.5f, 0.5f, 1.0f, 1.0f}),
               layer(1, 5, grey),         layer(1, 6, grey)};
  b.offsets = {0, 3, 6};
  const AgreeingColorStats s = colorWhereHitsAgree(a, b);
  EXPECT_EQ(s.layers, 3u);  // pixel 0 sample 0 (two layers), pixel 1 sample 0
  EXPECT_DOUBLE_EQ(s.maxError, 0.5);
  EXPECT_EQ(s.maxX, 1);
  EXPECT_EQ(s.maxY, 0);
  // The same frame against itself: every layer compared, no error.
  const AgreeingColorStats same = colorWhereHitsAgree(b, b);
  EXPECT_EQ(same.layers, 6u);
  EXPECT_EQ(same.maxError, 0.0);
}

// Reads an 8-bit PNG back as bytes.
std::vector<uint8_t> readPng(const std::string& path, int* w, int* h) {
  auto in = OIIO::ImageInput::open(path);
  EXPECT_TRUE(in) << path;
  if (!in) return {};
  const OIIO::ImageSpec& spec = in->spec();
  *w = spec.width;
  *h = spec.height;
  std::vector<uint8_t> px(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
  in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT8, px.data());
  EXPECT_EQ(spec.nchannels, 4);
  return px;
}

glm::ivec3 bytes(const glm::dvec3& srgb) { return glm::ivec3(glm::round(srgb * 255.0)); }

TEST(Maps, MismatchMapColoursEachPixelByItsClass) {
  const std::string dir = test::makeTempDir("maps");
  VisibilityReport r;
  r.width = 3;
  r.height = 1;
  r.pixels = {PixelVisibility::BothEmpty, PixelVisibility::Genuine, PixelVisibility::DepthTie};
  writeMismatchMap(dir + "/mismatch.png", r);
  int w, h;
  const std::vector<uint8_t> px = readPng(dir + "/mismatch.png", &w, &h);
  ASSERT_EQ(px.size(), 12u);
  for (int i = 0; i < 3; ++i) {
    const glm::ivec3 want = bytes(mismatchColor(r.pixels[size_t(i)]));
    EXPECT_EQ(glm::ivec3(px[4 * i], px[4 * i + 1], px[4 * i + 2]), want) << "pixel " << i;
  }
  // One entry per pixel class (Genuine is the last).
  EXPECT_EQ(mismatchLegend().size(), size_t(PixelVisibility::Genuine) + 1);
  EXPECT_EQ(cssColor(mismatchColor(PixelVisibility::Genuine)), "#ff0000");
}

TEST(Maps, HeatMapScalesToTheLargestDifference) {
  const std::string dir = test::makeTempDir("heat");
  const FlatImage a = uniform(4, 1, {0.0f, 0.0f, 0.0f, 1.0f});
  FlatImage b = a;
  b.color[1].r = 0.25f;
  b.color[3].r = 0.5f;  // the largest: the top of the bar
  const ColorBar bar = writeDifferenceHeatMap(dir + "/heat.png", a, b);
  EXPECT_EQ(bar.lo, 0.0);
  EXPECT_EQ(bar.hi, 0.5);
  int w, h;
  const std::vector<uint8_t> px = readPng(dir + "/heat.png", &w, &h);
  ASSERT_EQ(px.size(), 16u);
  EXPECT_EQ(glm::ivec3(px[0], px[1], px[2]), bytes(bar.stops.front().srgb));
  EXPECT_EQ(glm::ivec3(px[12], px[13], px[14]), bytes(bar.stops.back().srgb));
  EXPECT_EQ(glm::ivec3(px[4], px[5], px[6]), bytes(bar.stops[2].srgb));  // 0.25 of 0.5: the middle stop
  EXPECT_NE(bar.cssGradient().find("#000004 0%"), std::string::npos) << bar.cssGradient();
}

}  // namespace
}  // namespace rastray
