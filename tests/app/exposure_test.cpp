// --exposure scales the output colour by 2^EV after every renderer, in the
// image and in the deep layers; alpha, depth and IDs are untouched.
#include <gtest/gtest.h>

#include <cmath>

#include "app/engine/render_setup.h"
#include "tests/test_files.h"

namespace rastray {
namespace {

RenderOutput render(const std::string& renderer, const std::string& exposure) {
  std::vector<std::string> args = {"--renderer", renderer, "--size", "48", "36", "--spp", "4"};
  if (!exposure.empty()) args.insert(args.end(), {"--exposure", exposure});
  RenderSettings settings = renderSettingsFrom(args);
  settings.keepSamples = true;
  const std::string scene = test::scenePath("cornell-box.gltf");
  return renderScene(loadSceneForRender(scene, settings), settings).output;
}

TEST(Exposure, ScalesPremultipliedColourByPowersOfTwoOnly) {
  for (const char* renderer : {"raster", "raytrace", "hybrid"}) {
    const RenderOutput plain = render(renderer, "");
    const RenderOutput brighter = render(renderer, "1.5");
    const float scale = std::exp2(1.5f);
    ASSERT_EQ(plain.image.color.size(), brighter.image.color.size());
    size_t lit = 0;
    for (size_t i = 0; i < plain.image.color.size(); ++i) {
      const glm::vec4 &a = plain.image.color[i], &b = brighter.image.color[i];
      for (int c = 0; c < 3; ++c) ASSERT_EQ(b[c], a[c] * scale) << renderer << " pixel " << i;
      ASSERT_EQ(b.a, a.a) << renderer << " pixel " << i;
      lit += a.r > 0.0f;
    }
    EXPECT_GT(lit, plain.image.color.size() / 2) << renderer;
    EXPECT_EQ(brighter.image.depth, plain.image.depth) << renderer;
    EXPECT_EQ(brighter.image.instance, plain.image.instance) << renderer;
    EXPECT_EQ(brighter.image.triangle, plain.image.triangle) << renderer;
    ASSERT_EQ(brighter.samples.samples.size(), plain.samples.samples.size()) << renderer;
    ASSERT_FALSE(plain.samples.samples.empty());
    for (size_t i = 0; i < plain.samples.samples.size(); ++i) {
      const DeepSample &a = plain.samples.samples[i], &b = brighter.samples.samples[i];
      for (int c = 0; c < 3; ++c) ASSERT_EQ(b.color[c], a.color[c] * scale) << renderer << " deep " << i;
      ASSERT_EQ(b.color.a, a.color.a);
      ASSERT_EQ(b.depth, a.depth);
    }
  }
}

TEST(Exposure, OutOfRangeOrNotANumberIsRefused) {
  for (const char* bad : {"65", "-65", "nan", "inf", "two"})
    EXPECT_THROW(renderSettingsFrom({"--exposure", bad}), InputError) << bad;
  EXPECT_EQ(renderSettingsFrom({"--exposure", "-2"}).exposure, -2.0);
}

}  // namespace
}  // namespace rastray
