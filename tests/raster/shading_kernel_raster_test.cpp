// The rasterizer's deferred shading through the shading kernel against the
// scalar double reference (ShadingOptions::referenceShading): the same hits,
// colours within the kernel's stated bound (common/shading_kernel.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "common/gltf/loader.h"
#include "raster_test_util.h"

namespace rastray {
namespace {

// The bound of common/shading_kernel.h: per channel, relative to
// max(1, |reference|); a resolved pixel averages its samples, so it holds
// for pixels too. Lanes at a lit/unlit threshold may flip: at most 1 in 1000.
constexpr float kRelativeBound = 1e-6f;

void expectWithinBound(const FlatImage& kernel, const FlatImage& reference, const std::string& what) {
  ASSERT_EQ(kernel.color.size(), reference.color.size());
  size_t beyond = 0;
  for (size_t i = 0; i < kernel.color.size(); ++i) {
    // Visibility does not depend on the shading path: the same hits.
    ASSERT_EQ(kernel.instance[i], reference.instance[i]) << what << " " << i;
    ASSERT_EQ(kernel.triangle[i], reference.triangle[i]) << what << " " << i;
    for (int ch = 0; ch < 4; ++ch) {
      const float r = reference.color[i][ch], k = kernel.color[i][ch];
      if (!(std::abs(k - r) <= kRelativeBound * std::max(1.0f, std::abs(r)))) ++beyond;
    }
  }
  EXPECT_LE(beyond * 1000, kernel.color.size()) << what << ": " << beyond << " channels beyond the bound";
}

TEST(ShadingKernelRaster, KernelAndReferenceShadingAgreeWithinTheBound) {
  for (const char* name :
       {"cornell-box.gltf", "textured-plane.gltf", "vertex-colors.gltf", "stiff/far-node-1e6.gltf",
        "stiff/grazing-lit-89.9.gltf", "stiff/scale-1e4.gltf"}) {
    const Scene scene = loadScene(test::scenePath(name));
    const Camera camera = makeCamera(scene, {}, 96, 72);
    for (const ShadingRate rate : {ShadingRate::Sample, ShadingRate::Pixel}) {
      RasterOptions options;
      options.spp = rate == ShadingRate::Pixel ? 4 : 1;
      options.shadingRate = rate;
      options.shadowMapSize = 256;
      const RenderOutput kernel = test::render(scene, camera, options);
      options.shading.referenceShading = true;
      const RenderOutput reference = test::render(scene, camera, options);
      expectWithinBound(kernel.image, reference.image,
                        std::string(name) + (rate == ShadingRate::Pixel ? " pixel" : ""));
    }
  }
}

// The reference option really switches paths: on the lit Cornell box the
// two images differ in some bit.
TEST(ShadingKernelRaster, ReferenceShadingOptionChangesThePath) {
  const Scene scene = loadScene(test::scenePath("cornell-box.gltf"));
  const Camera camera = makeCamera(scene, {}, 64, 48);
  RasterOptions options;
  options.shadows = RasterShadows::None;
  const RenderOutput kernel = test::render(scene, camera, options);
  options.shading.referenceShading = true;
  const RenderOutput reference = test::render(scene, camera, options);
  EXPECT_NE(kernel.image.color, reference.image.color);
}

}  // namespace
}  // namespace rastray
