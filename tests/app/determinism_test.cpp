// Issue 13: the same command gives bit-identical pixels, IDs and depths
// (and deep samples) whatever the thread count and the order TBB runs the
// tiles in, for each renderer.
#include <gtest/gtest.h>

#include <cstring>

#include <tbb/global_control.h>

#include "app/engine/render_setup.h"
#include "app/studies/stability_measure.h"

#include "tests/test_labels.h"

// Every test here renders on 2 or more threads (the ThreadSanitizer stage runs them).
RASTRAY_TEST_LABELS("threads");

namespace rastray {
namespace {

RenderRun renderWithThreads(const std::string& scene, const std::vector<std::string>& args, int threads) {
  const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
  RenderSettings settings = renderSettingsFrom(args);
  settings.keepSamples = true;
  return renderScene(loadSceneForRender(scene, settings), settings);
}

template <typename T>
bool sameBits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

void expectIdentical(const RenderOutput& a, const RenderOutput& b, const std::string& what) {
  EXPECT_TRUE(sameBits(a.image.color, b.image.color)) << what << ": colour";
  EXPECT_TRUE(sameBits(a.image.depth, b.image.depth)) << what << ": depth";
  EXPECT_TRUE(sameBits(a.image.instance, b.image.instance)) << what << ": instance IDs";
  EXPECT_TRUE(sameBits(a.image.triangle, b.image.triangle)) << what << ": triangle IDs";
  ASSERT_EQ(a.samples.samples.size(), b.samples.samples.size()) << what << ": deep sample count";
  EXPECT_TRUE(sameBits(a.samples.offsets, b.samples.offsets)) << what << ": deep offsets";
  for (size_t i = 0; i < a.samples.samples.size(); ++i) {
    const DeepSample &x = a.samples.samples[i], &y = b.samples.samples[i];
    if (std::memcmp(&x.color, &y.color, sizeof x.color) != 0 ||
        std::memcmp(&x.depth, &y.depth, sizeof x.depth) || x.instance != y.instance ||
        x.triangle != y.triangle || x.sample != y.sample || x.cutOff != y.cutOff) {
      ADD_FAILURE() << what << ": deep sample " << i << " differs";
      break;
    }
  }
}

TEST(Determinism, OneAndTwoThreadsGiveTheSameBits) {
  const std::vector<std::string> scenes = {"cornell-box", "transparent-layers", "textured-plane",
                                           "cyclic-overlap"};
  for (const std::string& name : scenes) {
    const std::string path = std::string(RASTRAY_SCENES) + "/" + name + ".gltf";
    for (const char* renderer : {"raster", "raytrace", "hybrid"}) {
      const std::vector<std::string> args{"--renderer", renderer, "--size", "96", "72", "--spp", "4"};
      const RenderRun one = renderWithThreads(path, args, 1);
      ASSERT_EQ(one.output.image.color.size(), 96u * 72u);
      ASSERT_GT(one.output.samples.samples.size(), 1000u) << name << " " << renderer;  // deep output was kept
      // Twice with two threads: TBB hands tiles out in a different order
      // each time.
      for (int run = 0; run < 2; ++run)
        expectIdentical(one.output, renderWithThreads(path, args, 2).output,
                        name + " " + renderer + " run " + std::to_string(run));
    }
  }
}

}  // namespace
}  // namespace rastray
