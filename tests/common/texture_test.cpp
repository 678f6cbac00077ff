#include "common/texture.h"

#include <cmath>

#include <gtest/gtest.h>

#include "common/image.h"

namespace rastray {
namespace {

// A scene holding one textured material over a w×h image filled by `fill`.
template <typename Fill>
Scene textureScene(int w, int h, Fill fill, TextureSampler sampler = {}) {
  Scene s;
  TextureImage img;
  img.width = w;
  img.height = h;
  img.rgba8.resize(size_t(w) * size_t(h) * 4);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) fill(x, y, &img.rgba8[(size_t(y) * size_t(w) + size_t(x)) * 4]);
  s.images.push_back(img);
  Texture t;
  t.image = 0;
  t.sampler = sampler;
  s.textures.push_back(t);
  Material m;
  m.baseColorTexture = 0;
  s.materials.push_back(m);
  return s;
}

TEST(Texture, MipChainGoesDownToOneTexel) {
  const Scene s = textureScene(256, 64, [](int, int, uint8_t* p) { p[0] = p[1] = p[2] = p[3] = 255; });
  const TextureSet set(s);
  ASSERT_EQ(set.levelCount(0), 9u);  // 256 → 1 in width
  EXPECT_EQ(set.levels(0).back().width, 1);
  EXPECT_EQ(set.levels(0).back().height, 1);
  EXPECT_EQ(set.levels(0)[3].width, 32);
  EXPECT_EQ(set.levels(0)[3].height, 8);
}

TEST(Texture, CheckerAveragesToMidGreyInLinearSpace) {
  // Black/white checker: the 1×1 level is the linear mean 0.5, which is
  // sRGB 0.735, not the 0.5 that averaging encoded bytes would give.
  const Scene s = textureScene(64, 64, [](int x, int y, uint8_t* p) {
    const uint8_t v = ((x + y) % 2) ? 255 : 0;
    p[0] = p[1] = p[2] = v;
    p[3] = 255;
  });
  const TextureSet set(s);
  const glm::vec4 top = set.levels(0).back().texels[0];
  EXPECT_NEAR(top.r, 0.5f, 1e-5f);
  EXPECT_NEAR(top.a, 1.0f, 1e-6f);
}

TEST(Texture, MipsArePremultipliedSoTransparentTexelsDoNotFringe) {
  // Left half: opaque red; right half: fully transparent green. Averaged
  // premultiplied and un-premultiplied on lookup, the colour is pure red.
  const Scene s = textureScene(2, 1, [](int x, int, uint8_t* p) {
    p[0] = x == 0 ? 255 : 0;
    p[1] = x == 0 ? 0 : 255;
    p[2] = 0;
    p[3] = x == 0 ? 255 : 0;
  });
  const TextureSet set(s);
  TextureFootprint huge;
  huge.dUVdx = glm::vec2(4.0f, 0.0f);
  const glm::vec4 c = set.sample(0, {0.5f, 0.5f}, huge, TextureFilter::Trilinear);
  EXPECT_NEAR(c.r, 1.0f, 1e-5f);
  EXPECT_NEAR(c.g, 0.0f, 1e-5f);
  EXPECT_NEAR(c.a, 0.5f, 1e-5f);
}

TEST(Texture, LevelOfDetailFollowsTheFootprint) {
  const Scene s = textureScene(256, 256, [](int, int, uint8_t* p) { p[3] = 255; });
  const TextureSet set(s);
  TextureFootprint fp;
  fp.dUVdx = glm::vec2(4.0f / 256.0f, 0.0f);  // 4 texels per pixel
  fp.dUVdy = glm::vec2(0.0f, 1.0f / 256.0f);
  EXPECT_NEAR(set.levelOfDetail(0, fp), 2.0f, 1e-5f);
  fp.dUVdx = glm::vec2(0.5f / 256.0f, 0.0f);
  fp.dUVdy = glm::vec2(0.0f, 0.5f / 256.0f);
  EXPECT_NEAR(set.levelOfDetail(0, fp), -1.0f, 1e-5f);
}

TEST(Texture, WrapModes) {
  auto fill = [](int x, int, uint8_t* p) {
    p[0] = uint8_t(x * 85);  // 0, 85, 170, 255
    p[1] = p[2] = 0;
    p[3] = 255;
  };
  TextureSampler repeat, clamp, mirror;
  clamp.wrapS = clamp.wrapT = 33071;
  mirror.wrapS = mirror.wrapT = 33648;
  const TextureFootprint none;
  auto red = [&](const TextureSampler& s, float u) {
    const TextureSet set(textureScene(4, 1, fill, s));
    return set.sample(0, {u, 0.5f}, none, TextureFilter::Nearest).r;
  };
  EXPECT_FLOAT_EQ(red(repeat, 1.125f), srgbToLinear(0.0f));   // texel 0 again
  EXPECT_FLOAT_EQ(red(repeat, -0.125f), srgbToLinear(1.0f));  // texel 3
  EXPECT_FLOAT_EQ(red(clamp, 1.9f), srgbToLinear(1.0f));      // edge texel 3
  EXPECT_FLOAT_EQ(red(clamp, -3.0f), srgbToLinear(0.0f));     // edge texel 0
  EXPECT_FLOAT_EQ(red(mirror, 1.125f), srgbToLinear(1.0f));   // mirrored: texel 3
  EXPECT_FLOAT_EQ(red(mirror, 1.875f), srgbToLinear(0.0f));   // mirrored: texel 0
}

TEST(Texture, BilinearInterpolatesBetweenTexelCentres) {
  const Scene s = textureScene(2, 1, [](int x, int, uint8_t* p) {
    p[0] = p[1] = p[2] = x == 0 ? 0 : 255;
    p[3] = 255;
  });
  TextureSampler clamp;
  clamp.wrapS = clamp.wrapT = 33071;
  const TextureSet set(textureScene(
      2, 1,
      [](int x, int, uint8_t* p) {
        p[0] = p[1] = p[2] = x == 0 ? 0 : 255;
        p[3] = 255;
      },
      clamp));
  // uv 0.5 is halfway between the two texel centres (0.25 and 0.75).
  EXPECT_NEAR(set.sample(0, {0.5f, 0.5f}, {}, TextureFilter::Bilinear).r, 0.5f, 1e-6f);
  EXPECT_NEAR(set.sample(0, {0.25f, 0.5f}, {}, TextureFilter::Bilinear).r, 0.0f, 1e-6f);
  (void)s;
}

}  // namespace
}  // namespace rastray
