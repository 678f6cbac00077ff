// The ray caster's primary hits through the shading kernel: against the
// scalar double reference (ShadingOptions::referenceShading) within the
// kernel's stated bound, and the tile batch of stopping hits against the
// per-sample path (deep output: each surface shaded on its own) bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "common/analysis.h"
#include "common/camera.h"
#include "common/gltf/loader.h"
#include "raytrace/ray_caster.h"
#include "test_scenes.h"

namespace rastray {
namespace {

constexpr float kRelativeBound = 1e-6f;  // common/shading_kernel.h

RenderOutput castScene(const Scene& scene, int w, int h, const RayOptions& options) {
  RayCaster caster(scene, analyzeScene(scene));
  caster.bind(makeCamera(scene, {}, w, h), options);
  return caster.render();
}

TEST(ShadingKernelRaytrace, KernelAndReferenceShadingAgreeWithinTheBound) {
  for (const char* name :
       {"cornell-box.gltf", "textured-plane.gltf", "vertex-colors.gltf", "transparent-layers.gltf",
        "stiff/far-node-1e6.gltf", "stiff/grazing-lit-89.9.gltf", "stiff/scale-1e-4.gltf"}) {
    SCOPED_TRACE(name);
    const Scene scene = loadScene(test::scenePath(name));
    RayOptions options;
    options.spp = 2;
    const RenderOutput kernel = castScene(scene, 96, 72, options);
    options.shading.referenceShading = true;
    const RenderOutput reference = castScene(scene, 96, 72, options);
    size_t beyond = 0;
    for (size_t i = 0; i < kernel.image.color.size(); ++i) {
      ASSERT_EQ(kernel.image.instance[i], reference.image.instance[i]) << i;
      for (int ch = 0; ch < 4; ++ch) {
        const float r = reference.image.color[i][ch], k = kernel.image.color[i][ch];
        if (!(std::abs(k - r) <= kRelativeBound * std::max(1.0f, std::abs(r)))) ++beyond;
      }
    }
    EXPECT_LE(beyond * 1000, kernel.image.color.size()) << beyond << " channels beyond the bound";
  }
}

// A tile's stopping hits shaded as one batch give the bits each sample's
// surface gets shaded alone (the deep output's path: every surface list
// composited one by one, its primary surfaces through the kernel singly).
TEST(ShadingKernelRaytrace, TileBatchEqualsPerSampleShadingBitForBit) {
  for (const char* name : {"cornell-box.gltf", "textured-plane.gltf", "three-triangles.gltf"}) {
    SCOPED_TRACE(name);
    const Scene scene = loadScene(test::scenePath(name));
    RayOptions options;
    options.spp = 4;
    const RenderOutput batched = castScene(scene, 64, 48, options);
    options.keepSamples = true;
    const RenderOutput single = castScene(scene, 64, 48, options);
    EXPECT_EQ(batched.image.color, single.image.color);
    EXPECT_EQ(batched.image.depth, single.image.depth);
  }
}

}  // namespace
}  // namespace rastray
