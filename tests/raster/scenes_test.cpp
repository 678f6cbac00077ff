// Every bundled scene and real-world file renders in every mode without
// error, with consistent deep output and counters.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "common/gltf/loader.h"
#include "raster/rasterizer.h"
#include "raster_test_util.h"

#include "tests/test_labels.h"

// Every test here renders on 2 or more threads (the ThreadSanitizer stage runs them).
RASTRAY_TEST_LABELS("threads");

namespace rastray {
namespace {

std::vector<std::string> inputFiles() {
  std::vector<std::string> files;
  for (const char* dir :
       {RASTRAY_SCENES, RASTRAY_TEST_DATA "/real-world", RASTRAY_TEST_DATA "/malformed/valid"}) {
    if (!std::filesystem::exists(dir)) continue;
    for (const auto& e : std::filesystem::directory_iterator(dir)) {
      const std::string ext = e.path().extension().string();
      if (ext == ".gltf" || ext == ".glb") files.push_back(e.path().string());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

TEST(Scenes, EveryFileRendersInEveryModeConsistently) {
  const auto files = inputFiles();
  ASSERT_GT(files.size(), 5u);
  for (const std::string& file : files) {
    SCOPED_TRACE(file);
    Scene scene;
    try {
      scene = loadScene(file);
    } catch (const std::exception&) {
      continue;  // files the loader rejects are the loader's tests
    }
    const SceneAnalysis analysis = analyzeScene(scene);
    const Camera camera = makeCamera(scene, CameraOverrides{}, 40, 30);
    int variant = 0;
    for (TransparencyMode mode :
         {TransparencyMode::Exact, TransparencyMode::Sorted, TransparencyMode::Peel}) {
      RasterOptions o;
      o.spp = variant % 2 ? 4 : 1;
      o.transparency = mode;
      o.peelLayers = 4;
      o.keepSamples = true;
      o.shadowMapSize = 128;
      o.depthFormat = variant == 1   ? DepthFormat::Unorm16
                      : variant == 2 ? DepthFormat::Float
                                     : DepthFormat::FloatReversed;
      o.cull = variant == 2 ? CullMode::Back : CullMode::None;
      o.wireframe = variant == 1;
      o.halo = variant == 1;
      ++variant;
      const RenderOutput out = renderRaster(scene, analysis, camera, o);
      ASSERT_EQ(out.image.color.size(), 40u * 30u);
      ASSERT_EQ(out.samples.offsets.size(), 40u * 30u + 1);
      EXPECT_EQ(out.samples.offsets.back(), out.samples.samples.size());
      for (const glm::vec4& c : out.image.color) {
        EXPECT_LE(c.a, 1.0f + 1e-5f);
        EXPECT_GE(c.a, 0.0f);
      }
      if (!analysis.transparency) {
        EXPECT_EQ(out.counters.get("raster.fragments_transparent"), 0u);
      }
      EXPECT_LE(out.counters.get("raster.samples_passed"), out.counters.get("raster.samples_tested"));
      EXPECT_EQ(out.counters.get("raster.triangles_in"), scene.triangleCount());
    }
  }
}

}  // namespace
}  // namespace rastray
