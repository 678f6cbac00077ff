// The SIMD RGBA8 encoder (common/rgba8.h) against its scalar definition:
// the same bytes around every one of the 255 sRGB steps, over a sweep of
// all of [0, 1], and for the inputs a renderer can produce at the edges
// (alpha 0, NaN, infinities, negatives, colour above alpha).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "common/image.h"
#include "common/rgba8.h"

namespace rastray {
namespace {

float floatOf(uint32_t u) {
  float f;
  std::memcpy(&f, &u, sizeof f);
  return f;
}

// Encodes with both and compares pixel by pixel (a failure names the pixel).
void expectSameBytes(const std::vector<glm::vec4>& pixels) {
  std::vector<uint8_t> fast(pixels.size() * 4), reference(pixels.size() * 4);
  encodeRgba8(pixels.data(), pixels.size(), fast.data());
  encodeRgba8Reference(pixels.data(), pixels.size(), reference.data());
  for (size_t i = 0; i < pixels.size(); ++i)
    for (size_t k = 0; k < 4; ++k)
      ASSERT_EQ(int(fast[4 * i + k]), int(reference[4 * i + k]))
          << "pixel " << i << " channel " << k << ": (" << pixels[i].r << ", " << pixels[i].g << ", "
          << pixels[i].b << ", " << pixels[i].a << ")";
}

TEST(Rgba8, TheDefinitionIsTheExactCurveRounded) {
  EXPECT_EQ(srgbByte(0.0f), 0);
  EXPECT_EQ(srgbByte(1.0f), 255);
  EXPECT_EQ(srgbByte(std::numeric_limits<float>::quiet_NaN()), 0);
  EXPECT_EQ(srgbByte(-1.0f), 0);
  EXPECT_EQ(srgbByte(std::numeric_limits<float>::infinity()), 255);
  EXPECT_EQ(srgbByte(0.5f), 188);  // 1.055 · 0.5^(1/2.4) − 0.055 = 0.7354 → 187.5 + 0.5
  EXPECT_EQ(srgbByte(0.0031308f * 0.5f), uint8_t(0.0031308f * 0.5f * 12.92f * 255.0f + 0.5f));
}

TEST(Rgba8, EveryStepAndItsNeighboursEncodeAsTheDefinition) {
  // Each step found here by bisection over the definition, independently of
  // the encoder's table, then ±3 ulps around it, as opaque colour.
  std::vector<glm::vec4> pixels;
  for (int k = 1; k < 256; ++k) {
    uint32_t lo = 0, hi = 0x3F800000u;
    while (hi - lo > 1) {
      const uint32_t mid = lo + (hi - lo) / 2;
      (srgbByte(floatOf(mid)) >= k ? hi : lo) = mid;
    }
    for (int d = -3; d <= 3; ++d) {
      const float v = floatOf(uint32_t(int64_t(hi) + d));
      pixels.push_back({v, v, v, 1.0f});
    }
  }
  expectSameBytes(pixels);
}

TEST(Rgba8, ASweepOfTheUnitIntervalEncodesAsTheDefinition) {
  // Every 61st bit pattern of [0, 1] (17 M values): every bucket of the
  // encoder's table many times over.
  std::vector<glm::vec4> pixels;
  for (uint32_t u = 0; u <= 0x3F800000u; u += 61 * 4) {
    pixels.push_back({floatOf(u), floatOf(u + 61), floatOf(u + 122), floatOf(u + 183)});
    if (pixels.size() == (1u << 16)) {
      for (glm::vec4& p : pixels) p.a = std::min(p.a, 1.0f);
      expectSameBytes(pixels);
      pixels.clear();
    }
  }
  expectSameBytes(pixels);
}

TEST(Rgba8, PremultipliedEdgeCasesEncodeAsTheDefinition) {
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  const float specials[] = {0.0f,      -0.0f, 1e-45f, 1e-30f, 1e-7f, 0.25f, 0.999999f, 1.0f,
                            1.000001f, 2.0f,  1e30f,  inf,    -inf,  nan,   -1.0f,     -1e-30f};
  std::vector<glm::vec4> pixels;
  for (float c : specials)
    for (float a : specials) pixels.push_back({c, a * 0.5f, c * 0.25f, a});
  std::mt19937 rng(20261127);
  std::uniform_real_distribution<float> unit(-0.1f, 1.2f);
  for (int i = 0; i < 200000; ++i) pixels.push_back({unit(rng), unit(rng), unit(rng), unit(rng)});
  // Odd counts leave a tail after the last full vector.
  for (size_t n : {size_t(0), size_t(1), size_t(3), size_t(17), pixels.size()}) {
    std::vector<glm::vec4> prefix(pixels.begin(), pixels.begin() + std::ptrdiff_t(n));
    expectSameBytes(prefix);
  }
}

}  // namespace
}  // namespace rastray
