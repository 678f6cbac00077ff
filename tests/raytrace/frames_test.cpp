// The ray caster over several frames: a caster built once (one BVH) and
// rebound renders exactly what a new caster renders, whatever the order of
// cameras; the tile size does not change the image or the deep output;
// each frame counts its own rays and reports its stage times.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "common/gltf/loader.h"
#include "raytrace/ray_caster.h"
#include "test_scenes.h"

#include "tests/test_labels.h"

// Every test here renders on 2 or more threads (the ThreadSanitizer stage runs them).
RASTRAY_TEST_LABELS("threads");

namespace rastray {
namespace {

using test::scenePath;

bool sameDepth(float a, float b) { return a == b || (std::isinf(a) && std::isinf(b) && (a > 0) == (b > 0)); }

// Every output of two frames bit for bit: pixels, Z, IDs, every deep
// sample, and the counters.
void expectIdentical(const RenderOutput& a, const RenderOutput& b, const std::string& what) {
  ASSERT_EQ(a.image.width, b.image.width) << what;
  ASSERT_EQ(a.image.height, b.image.height) << what;
  size_t differ = 0;
  for (size_t i = 0; i < a.image.color.size(); ++i)
    if (a.image.color[i] != b.image.color[i] || !sameDepth(a.image.depth[i], b.image.depth[i]) ||
        a.image.instance[i] != b.image.instance[i] || a.image.triangle[i] != b.image.triangle[i])
      ++differ;
  EXPECT_EQ(differ, 0u) << what << ": pixels differ";
  ASSERT_EQ(a.hasSamples, b.hasSamples) << what;
  EXPECT_EQ(a.samples.offsets, b.samples.offsets) << what;
  ASSERT_EQ(a.samples.samples.size(), b.samples.samples.size()) << what;
  size_t deepDiffer = 0;
  for (size_t i = 0; i < a.samples.samples.size(); ++i) {
    const DeepSample &x = a.samples.samples[i], &y = b.samples.samples[i];
    if (x.color != y.color || !sameDepth(x.depth, y.depth) || x.instance != y.instance ||
        x.triangle != y.triangle || x.sample != y.sample || x.cutOff != y.cutOff)
      ++deepDiffer;
  }
  EXPECT_EQ(deepDiffer, 0u) << what << ": deep samples differ";
  EXPECT_EQ(a.counters.values, b.counters.values) << what;
}

RenderOutput renderWithNewCaster(const Scene& scene, const Camera& camera, const RayOptions& options) {
  RayCaster caster(scene, analyzeScene(scene));
  caster.bind(camera, options);
  return caster.render();
}

// Cornell box: shadow, reflection and refraction rays; transparent layers:
// BLEND continuation (single rays); textured plane: footprints.
const char* kScenes[] = {"cornell-box.gltf", "transparent-layers.gltf", "textured-plane.gltf"};

TEST(Frames, RebindingACasterRendersWhatANewCasterRenders) {
  for (const char* name : kScenes) {
    const Scene scene = loadScene(scenePath(name));
    RayOptions options;
    options.spp = 4;
    options.keepSamples = true;
    const Camera a = makeCamera(scene, {}, 40, 30);
    CameraOverrides other;
    other.yfovDegrees = 30.0;
    const Camera b = makeCamera(scene, other, 24, 36);
    RayOptions flat = options;
    flat.keepSamples = false;
    flat.spp = 1;

    RayCaster caster(scene, analyzeScene(scene));
    caster.bind(a, options);
    const RenderOutput first = caster.render();
    expectIdentical(first, caster.render(), std::string(name) + ": the same frame again");
    caster.bind(b, flat);
    expectIdentical(caster.render(), renderWithNewCaster(scene, b, flat),
                    std::string(name) + ": rebound to another camera and options");
    caster.bind(a, options);
    expectIdentical(caster.render(), first, std::string(name) + ": bound back to the first camera");
    expectIdentical(first, renderWithNewCaster(scene, a, options), std::string(name) + ": a new caster");
  }
}

// Tiles that do not divide the image (7), the default (16) and one tile
// larger than the image: the same pixels and the same deep output, whose
// per-tile buffers are assembled into one image.
TEST(Frames, TileSizeDoesNotChangeTheOutput) {
  for (const char* name : kScenes) {
    const Scene scene = loadScene(scenePath(name));
    const Camera camera = makeCamera(scene, {}, 45, 31);
    RayOptions options;
    options.spp = 4;
    options.keepSamples = true;
    const RenderOutput reference = renderWithNewCaster(scene, camera, options);
    ASSERT_TRUE(reference.hasSamples);
    EXPECT_GT(reference.samples.samples.size(), 0u) << name;
    for (int size : {1, 7, 64}) {
      options.tileSize = size;
      expectIdentical(renderWithNewCaster(scene, camera, options), reference,
                      std::string(name) + ": tile size " + std::to_string(size));
    }
  }
}

// A primary ray that gathered no layer is shaded without its surface list
// when no deep output is kept (resolveStoppingHit); with deep output it
// goes through the list (collectCrossings, composite). Both must give the
// same flat pixels, Z, IDs and counts, bit for bit: opaque scenes (every
// ray takes the short path), textured (footprints), vertex colours,
// secondary and shadow rays (Cornell box), and BLEND scenes (where only
// rays with no layer in front take it), at 1 and 4 spp.
TEST(Frames, OpaqueShortPathGivesTheSurfaceListsPixels) {
  for (const char* name : {"three-triangles.gltf", "vertex-colors.gltf", "textured-plane.gltf",
                           "cornell-box.gltf", "transparent-layers.gltf", "cyclic-overlap.gltf"}) {
    const Scene scene = loadScene(scenePath(name));
    const Camera camera = makeCamera(scene, {}, 37, 29);
    for (int spp : {1, 4}) {
      RayOptions options;
      options.spp = spp;
      const RenderOutput shortPath = renderWithNewCaster(scene, camera, options);
      options.keepSamples = true;
      RenderOutput listPath = renderWithNewCaster(scene, camera, options);
      ASSERT_TRUE(listPath.hasSamples) << name;
      EXPECT_GT(listPath.samples.samples.size(), 0u) << name;
      listPath.hasSamples = false;
      listPath.samples = DeepImage{};
      expectIdentical(shortPath, listPath, std::string(name) + ", " + std::to_string(spp) + " spp");
    }
  }
}

double timing(const RenderOutput& out, const std::string& name) {
  for (const auto& [stage, seconds] : out.timings)
    if (stage == name) return seconds;
  return -1.0;
}

// Each frame reports its own stage times and counts its own rays (not the
// frames before it since bind()).
TEST(Frames, EachFrameReportsItsStagesAndItsOwnRays) {
  const Scene scene = loadScene(scenePath("cornell-box.gltf"));
  RayCaster caster(scene, analyzeScene(scene));
  RayOptions options;
  caster.bind(makeCamera(scene, {}, 32, 24), options);
  const RenderOutput first = caster.render();
  const RenderOutput second = caster.render();
  EXPECT_EQ(first.counters.get("rays.primary"), uint64_t(32 * 24));
  EXPECT_GT(first.counters.get("rays.shadow"), 0u);
  EXPECT_EQ(second.counters.values, first.counters.values);
  for (const RenderOutput* out : {&first, &second}) {
    for (const char* stage : {"raytrace.primary", "raytrace.shade"}) {
      const double s = timing(*out, stage);
      EXPECT_GE(s, 0.0) << stage << " missing or negative";
      EXPECT_TRUE(std::isfinite(s)) << stage;
    }
    EXPECT_LT(timing(*out, "raytrace.deep_output"), 0.0) << "deep assembly timed without deep output";
  }
  options.keepSamples = true;
  caster.bind(makeCamera(scene, {}, 32, 24), options);
  EXPECT_GE(timing(caster.render(), "raytrace.deep_output"), 0.0);
}

}  // namespace
}  // namespace rastray
