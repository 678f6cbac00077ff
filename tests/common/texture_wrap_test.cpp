// Texture wrapping far outside [0, 1] on textures wider than int arithmetic
// on uv × size allows: every wrap mode must give the texel the mode's
// period says, with no float → int overflow (run under
// -DRASTRAY_SANITIZE=ON to have UBSan check the conversions).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "common/texture.h"

namespace rastray {
namespace {

constexpr int kWide = 4096;

// A kWide × 1 texture whose texel x has red = x % 256 / 255 and green =
// x / 256 / 255 (sRGB bytes), so every texel is told apart.
Scene wideScene(int wrapS) {
  Scene s;
  TextureImage img;
  img.width = kWide;
  img.height = 1;
  img.rgba8.resize(size_t(kWide) * 4);
  for (int x = 0; x < kWide; ++x) {
    uint8_t* p = &img.rgba8[size_t(x) * 4];
    p[0] = uint8_t(x % 256);
    p[1] = uint8_t(x / 256);
    p[2] = 0;
    p[3] = 255;
  }
  s.images.push_back(img);
  Texture t;
  t.image = 0;
  t.sampler.wrapS = wrapS;
  t.sampler.wrapT = wrapS;
  s.textures.push_back(t);
  Material m;
  m.baseColorTexture = 0;
  s.materials.push_back(m);
  return s;
}

// The texel index a nearest lookup returned, read back from its colour.
int texelIndex(const TextureSet& set, glm::vec2 uv) {
  const glm::vec4 c = set.sample(0, uv, TextureFootprint{}, TextureFilter::Nearest);
  const std::vector<MipLevel>& levels = set.levels(0);
  for (int x = 0; x < kWide; ++x)
    if (levels[0].texels[size_t(x)] == c) return x;
  return -1;
}

constexpr int kRepeat = 10497, kMirrored = 33648, kClamp = 33071;

TEST(TextureWrap, RepeatFollowsThePeriodBeyondTheIntRangeOfTexelCoordinates) {
  const TextureSet set(wideScene(kRepeat));
  // 1e6 + 0.25 is exact in float; × 4096 = 4,096,001,024 texels, beyond
  // INT_MAX: texel 1024 of the period.
  EXPECT_EQ(texelIndex(set, {1e6f + 0.25f, 0.5f}), 1024);
  EXPECT_EQ(texelIndex(set, {-(1e6f + 0.25f), 0.5f}), kWide - 1024);
  // 2^100 is a whole number of periods: texel 0.
  EXPECT_EQ(texelIndex(set, {std::ldexp(1.0f, 100), 0.5f}), 0);
  EXPECT_EQ(texelIndex(set, {std::numeric_limits<float>::max(), 0.5f}), 0);
  EXPECT_EQ(texelIndex(set, {-std::numeric_limits<float>::max(), 0.5f}), 0);
}

TEST(TextureWrap, MirroredRepeatFollowsItsDoublePeriod) {
  const TextureSet set(wideScene(kMirrored));
  // 1e6 + 0.25 holds 500,000 whole double periods, then a quarter of the
  // image forwards: texel 1024.
  EXPECT_EQ(texelIndex(set, {1e6f + 0.25f, 0.5f}), 1024);
  // 1e6 + 1.25: an odd number of images, mirrored: texel 4095 − 1024.
  EXPECT_EQ(texelIndex(set, {1e6f + 1.25f, 0.5f}), kWide - 1 - 1024);
  EXPECT_EQ(texelIndex(set, {std::numeric_limits<float>::max(), 0.5f}), 0);
}

TEST(TextureWrap, ClampGivesTheEdgeTexelForAnyUv) {
  const TextureSet set(wideScene(kClamp));
  EXPECT_EQ(texelIndex(set, {1e6f + 0.25f, 0.5f}), kWide - 1);
  EXPECT_EQ(texelIndex(set, {std::numeric_limits<float>::max(), 0.5f}), kWide - 1);
  EXPECT_EQ(texelIndex(set, {-std::numeric_limits<float>::max(), 0.5f}), 0);
}

TEST(TextureWrap, EveryFilterAcceptsAnyUvAndFootprint) {
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  const float big = std::numeric_limits<float>::max();
  const glm::vec2 uvs[] = {{1e6f + 0.25f, 0.5f}, {big, -big}, {-big, big},
                           {inf, 0.5f},          {nan, nan},  {-inf, 2e9f}};
  const TextureFootprint footprints[] = {
      {}, {{1e-3f, 0.0f}, {0.0f, 1e-3f}}, {{inf, 0.0f}, {0.0f, inf}}, {{nan, nan}, {nan, nan}}};
  for (int mode : {kRepeat, kMirrored, kClamp}) {
    const TextureSet set(wideScene(mode));
    for (const glm::vec2& uv : uvs)
      for (const TextureFootprint& fp : footprints)
        for (TextureFilter f : {TextureFilter::Sampler, TextureFilter::Nearest, TextureFilter::Bilinear,
                                TextureFilter::Trilinear}) {
          const glm::vec4 c = set.sample(0, uv, fp, f);
          EXPECT_TRUE(std::isfinite(c.r) && std::isfinite(c.g) && std::isfinite(c.a))
              << "mode " << mode << " filter " << toString(f) << " uv " << uv.x << " " << uv.y;
        }
  }
  // Bilinear across the REPEAT seam far out: the two texels are the last
  // and the first of the period.
  const TextureSet set(wideScene(kRepeat));
  const glm::vec4 seam = set.sample(0, {1e6f, 0.5f}, {}, TextureFilter::Bilinear);
  const std::vector<MipLevel>& levels = set.levels(0);
  const glm::vec4 expected = 0.5f * (levels[0].texels[0] + levels[0].texels[kWide - 1]);
  EXPECT_NEAR(seam.r, expected.r, 1e-6f);
  EXPECT_NEAR(seam.g, expected.g, 1e-6f);
}

}  // namespace
}  // namespace rastray
