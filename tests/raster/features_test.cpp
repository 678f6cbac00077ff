// Shadow maps, the hybrid hook, MASK, shading rate, wireframe and the
// debug trace.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>

#include "common/error.h"
#include "common/gltf/loader.h"
#include "common/sampling.h"
#include "common/trace.h"
#include "raster/rasterizer.h"
#include "raster_test_util.h"

#include "tests/test_labels.h"

// Every test here renders on 2 or more threads (the ThreadSanitizer stage runs them).
RASTRAY_TEST_LABELS("threads");

namespace rastray {
namespace {

using test::addMesh;
using test::colored;

// A 6×6 floor at y = 0, a 1×1 occluder at y = 1, camera above looking down.
Scene shadowScene(LightType type) {
  Scene scene;
  const std::vector<glm::uvec3> quad = {{0, 1, 2}, {0, 2, 3}};
  addMesh(scene, {{-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, {-3, 0, -3}}, quad,
          colored(glm::vec4(0.8f, 0.8f, 0.8f, 1)));
  addMesh(scene, {{-0.5f, 1, 0.5f}, {0.5f, 1, 0.5f}, {0.5f, 1, -0.5f}, {-0.5f, 1, -0.5f}}, quad,
          colored(glm::vec4(0.8f, 0.2f, 0.2f, 1)));
  Light light;
  light.type = type;
  light.intensity = 5.0f;
  // Off to the side, so that the occluder does not hide its own shadow from the camera.
  light.position = glm::dvec3(-1.5, 3.0, 0.2);
  light.direction = glm::normalize(glm::dvec3(0.8, -1.0, 0.2));
  if (type == LightType::Spot) {
    light.direction = glm::normalize(glm::dvec3(1.5, -3.0, -0.2));
    light.outerConeAngle = 1.2f;
    light.innerConeAngle = 1.1f;
  }
  scene.lights.push_back(light);
  return scene;
}

// Analytic: does the segment from floor point p towards the light cross the occluder?
bool occluded(const Light& light, const glm::dvec3& p) {
  const glm::dvec3 toLight =
      light.type == LightType::Directional ? -light.direction : glm::normalize(light.position - p);
  const glm::dvec3 q = p + toLight * ((1.0 - p.y) / toLight.y);
  return std::abs(q.x) < 0.5 && std::abs(q.z) < 0.5;
}

TEST(ShadowMaps, MatchAnalyticShadowsWithoutAcne) {
  for (LightType type : {LightType::Point, LightType::Directional, LightType::Spot}) {
    const Scene scene = shadowScene(type);
    const Camera camera = test::perspectiveCamera(96, 96, 1.2, glm::dvec3(0, 6, 0.01), glm::dvec3(0), 0.1);
    RasterOptions o;
    o.shadowMapSize = 512;
    std::vector<SampleHit> hits;
    const RenderOutput lit = renderRasterWithHits(scene, analyzeScene(scene), camera, o, &hits);
    o.shadows = RasterShadows::None;
    const RenderOutput unshadowed = test::render(scene, camera, o);
    EXPECT_GT(lit.counters.get("raster.shadow_map_triangles"), 0u);
    EXPECT_EQ(lit.counters.get("raster.shadow_maps"), type == LightType::Point ? 6u : 1u);
    size_t floor = 0, shadowed = 0, wrong = 0;
    for (int y = 0; y < camera.height; ++y)
      for (int x = 0; x < camera.width; ++x) {
        const size_t p = lit.image.index(x, y);
        if (lit.image.instance[p] != 0) continue;
        ++floor;
        const Ray ray = camera.primaryRay(glm::dvec2(x + 0.5, y + 0.5));
        const glm::dvec3 point = ray.origin + ray.direction * (double(lit.image.depth[p]) / ray.depthPerT);
        const bool expectShadow = occluded(scene.lights[0], point);
        const bool dark = lit.image.color[p].g < 0.5f * unshadowed.image.color[p].g;
        const bool same = lit.image.color[p] == unshadowed.image.color[p];
        shadowed += expectShadow;
        if (expectShadow ? !dark : !same) ++wrong;
      }
    EXPECT_GT(shadowed, 50u);
    // Map aliasing only along the shadow's border.
    EXPECT_LT(wrong, floor / 50) << int(type) << " " << wrong << " of " << floor;
  }
}

TEST(ShadowMaps, BlendOccludersLetOneMinusAlphaThrough) {
  Scene scene = shadowScene(LightType::Directional);
  scene.materials[1] = colored(glm::vec4(0.8f, 0.2f, 0.2f, 0.25f), AlphaMode::Blend, true);
  const Camera camera = test::perspectiveCamera(96, 96, 1.2, glm::dvec3(0, 6, 0.01), glm::dvec3(0), 0.1);
  RasterOptions o;
  o.shadowMapSize = 512;
  const RenderOutput lit = test::render(scene, camera, o);
  o.shadows = RasterShadows::None;
  const RenderOutput unshadowed = test::render(scene, camera, o);
  EXPECT_GT(lit.counters.get("raster.shadow_map_transmissive_fragments"), 0u);
  size_t inShadow = 0, wrong = 0;
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x) {
      const size_t p = lit.image.index(x, y);
      if (lit.image.instance[p] != 0) continue;  // floor seen directly (not through the sheet)
      const Ray ray = camera.primaryRay(glm::dvec2(x + 0.5, y + 0.5));
      const glm::dvec3 point = ray.origin + ray.direction * (double(lit.image.depth[p]) / ray.depthPerT);
      if (!occluded(scene.lights[0], point)) continue;
      ++inShadow;
      const float ratio = lit.image.color[p].g / unshadowed.image.color[p].g;
      wrong += std::abs(ratio - 0.75f) > 0.01f;
    }
  EXPECT_GT(inShadow, 50u);
  EXPECT_LT(wrong, inShadow / 10);
}

class NoLight : public LightVisibility {
 public:
  glm::vec3 transmittance(const SurfacePoint&, int, const glm::dvec3&, double) const override {
    ++calls;
    return glm::vec3(0.0f);
  }
  mutable std::atomic<int> calls{0};
};

class Magenta : public SecondaryRayTracer {
 public:
  glm::vec3 radiance(const SurfacePoint&, const glm::dvec3&, RayKind, int, float) const override {
    return glm::vec3(1, 0, 1);
  }
};

TEST(HybridHook, ShaderUsesTheGivenVisibilityAndSecondaryRays) {
  Scene scene = shadowScene(LightType::Point);
  Material mirror = colored(glm::vec4(1));
  mirror.metallic = 1.0f;
  mirror.roughness = 0.0f;
  scene.materials[1] = mirror;
  const Camera camera = test::perspectiveCamera(32, 32, 1.2, glm::dvec3(0, 6, 0.01), glm::dvec3(0), 0.1);
  RasterOptions o;
  o.shadows = RasterShadows::Traced;
  EXPECT_THROW(test::render(scene, camera, o), InputError);  // rays need the hybrid's visibility
  NoLight dark;
  Magenta magenta;
  const RenderOutput out = renderRaster(scene, analyzeScene(scene), camera, o, &magenta, &dark);
  EXPECT_GT(dark.calls.load(), 0);
  const size_t centre = out.image.index(16, 16);
  ASSERT_EQ(out.image.instance[centre], 1u);
  EXPECT_EQ(out.image.color[centre], glm::vec4(1, 0, 1, 1));
  const size_t corner = out.image.index(6, 16);
  ASSERT_EQ(out.image.instance[corner], 0u);
  EXPECT_EQ(out.image.color[corner], glm::vec4(0, 0, 0, 1));  // all light blocked
}

TEST(Mask, AlphaBelowTheCutoffCoversNothing) {
  Scene scene;
  const std::vector<glm::uvec3> quad = {{0, 1, 2}, {0, 2, 3}};
  addMesh(scene, {{-1, -1, -1}, {0, -1, -1}, {0, 1, -1}, {-1, 1, -1}}, quad,
          colored(glm::vec4(1, 1, 1, 0.3f), AlphaMode::Mask));
  addMesh(scene, {{0, -1, -1}, {1, -1, -1}, {1, 1, -1}, {0, 1, -1}}, quad,
          colored(glm::vec4(1, 1, 1, 0.7f), AlphaMode::Mask));
  const RenderOutput out = test::render(scene, test::orthoCamera(8, 1.0, 0.0, 10.0), RasterOptions{});
  EXPECT_EQ(out.image.instance[out.image.index(2, 4)], kNoId);
  EXPECT_EQ(out.image.instance[out.image.index(6, 4)], 1u);
  EXPECT_EQ(out.image.color[out.image.index(6, 4)].a, 1.0f);
  EXPECT_GT(out.counters.get("raster.alpha_rejected"), 0u);
}

TEST(ShadingRate, PixelRateShadesOncePerPixelAndTriangle) {
  const Scene scene = loadScene(test::scenePath("three-triangles.gltf"));
  const Camera camera = makeCamera(scene, CameraOverrides{}, 32, 32);
  RasterOptions o;
  o.spp = 4;
  const RenderOutput perSample = test::render(scene, camera, o);
  o.shadingRate = ShadingRate::Pixel;
  const RenderOutput perPixel = test::render(scene, camera, o);
  EXPECT_LT(perPixel.counters.get("raster.shaded_samples") * 3,
            perSample.counters.get("raster.shaded_samples"));
  // Flat eye-lit colours: the same image either way.
  EXPECT_EQ(perPixel.image.color, perSample.image.color);
}

// SPEC §8's leaving out, counted: an unlit, emissive surface (black base
// colour under the eye light) has one colour, so its samples get no
// primary ray and no refined hit; a lit base colour gets both per sample.
TEST(LeftOut, AnEmissiveSurfaceIsShadedWithoutRefinedHits) {
  for (const bool black : {true, false}) {
    Scene scene;
    Material m = colored(black ? glm::vec4(0, 0, 0, 1) : glm::vec4(0.5f, 0.5f, 0.5f, 1));
    m.emissive = glm::vec3(1.0f, 0.5f, 0.25f);
    addMesh(scene, {{-1, -1, -2}, {1, -1, -2}, {0, 1, -2}}, {{0, 1, 2}}, m);
    const Camera camera = test::perspectiveCamera(16, 16, 1.0, glm::dvec3(0.0), glm::dvec3(0, 0, -1));
    const RenderOutput out = test::render(scene, camera, RasterOptions{});
    const uint64_t shaded = out.counters.get("raster.shaded_samples");
    EXPECT_GT(shaded, 0u);
    EXPECT_EQ(out.counters.get("raster.refined_samples"), black ? 0u : shaded) << "black " << black;
  }
}

TEST(SampleCounts, GridPatternsShareTheCentreSample) {
  const Scene scene = loadScene(test::scenePath("three-triangles.gltf"));
  const Camera camera = makeCamera(scene, CameraOverrides{}, 8, 8);
  RasterOptions o;
  const RenderOutput one = test::render(scene, camera, o);
  for (int spp : {25, 49}) {
    o.spp = spp;  // n odd: the centre sample is the pixel centre, on a 1/(2n) grid (k = n)
    const RenderOutput many = test::render(scene, camera, o);
    EXPECT_EQ(many.image.instance, one.image.instance) << spp;
    EXPECT_EQ(many.image.depth, one.image.depth) << spp;
  }
}

TEST(Wireframe, HiddenEdgesAreRemovedAndHalosGapCrossings) {
  const Scene scene = loadScene(test::scenePath("three-triangles.gltf"));
  const Camera camera = makeCamera(scene, CameraOverrides{}, 64, 64);
  RasterOptions o;
  const RenderOutput shaded = test::render(scene, camera, o);
  o.wireframe = true;
  const RenderOutput wire = test::render(scene, camera, o);
  o.halo = true;
  const RenderOutput halo = test::render(scene, camera, o);
  // Yellow's left edge: visible above red (world (−0.081, 0.604) → pixel (29, 12)),
  // hidden behind red at (−0.425, −0.015) → pixel (18, 32).
  EXPECT_EQ(wire.image.color[wire.image.index(29, 12)], glm::vec4(0, 0, 0, 1));
  EXPECT_EQ(wire.image.color[wire.image.index(18, 32)], shaded.image.color[shaded.image.index(18, 32)]);
  const uint64_t lines = wire.counters.get("raster.wireframe_pixels");
  const uint64_t gapped = halo.counters.get("raster.wireframe_pixels");
  EXPECT_GT(lines, 100u);
  EXPECT_LT(gapped, lines);
  EXPECT_GT(gapped, lines / 2);
}

// The first event of `stage` at sample `sample` whose instance is
// `instance` (kNoId: any), or nullptr.
const TraceEvent* findEvent(const std::vector<TraceEvent>& events, TraceStage stage, int sample,
                            uint32_t instance = kNoId) {
  for (const TraceEvent& e : events)
    if (e.stage == stage && e.sample == sample && (instance == kNoId || e.instance == instance)) return &e;
  return nullptr;
}

std::string valueOf(const TraceEvent& e, const std::string& name) {
  for (const auto& [n, v] : e.values)
    if (n == name) return v;
  return "";
}

TEST(TracePixel, RecordsEveryStageAtThePixelAndPrintsNothing) {
  const Scene scene = loadScene(test::scenePath("three-triangles.gltf"));
  const Camera camera = makeCamera(scene, CameraOverrides{}, 8, 8);
  RasterOptions o;
  TraceLog log;
  o.trace = {&log, {5, 5}};  // on yellow's bottom edge, blue behind
  testing::internal::CaptureStderr();
  const RenderOutput traced = test::render(scene, camera, o);
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
  const std::vector<TraceEvent> events = log.events();
  const std::string text = log.text();
  ASSERT_FALSE(events.empty());
  EXPECT_EQ(events.front().stage, TraceStage::Tile) << text;

  // The fill rule: some sample lies exactly on an edge that is not top-left.
  bool dropped = false;
  for (const TraceEvent& e : events)
    if (e.stage == TraceStage::Coverage)
      for (const auto& [name, value] : e.values)
        dropped = dropped || value.find("(on edge, dropped)") != std::string::npos;
  EXPECT_TRUE(dropped) << text;

  // Blue (instance 1) reaches the depth test at sample 0 with a hexadecimal key.
  const TraceEvent* depth = findEvent(events, TraceStage::Depth, 0, 1);
  ASSERT_NE(depth, nullptr) << text;
  EXPECT_EQ(valueOf(*depth, "key").rfind("0x", 0), 0u) << text;
  EXPECT_TRUE(depth->outcome == "pass" || depth->outcome == "fail") << text;

  // The final colour of sample 0 is the pixel's colour (1 spp: the resolve is the identity).
  const TraceEvent* final = findEvent(events, TraceStage::Final, 0);
  ASSERT_NE(final, nullptr) << text;
  const glm::vec4 c = traced.image.color[traced.image.index(5, 5)];
  char expected[96];
  std::snprintf(expected, sizeof expected, "(%.4f, %.4f, %.4f, %.4f)", double(c.r), double(c.g), double(c.b),
                double(c.a));
  EXPECT_EQ(valueOf(*final, "color"), expected);
  EXPECT_NE(text.find("final sample 0:"), std::string::npos) << text;

  // Tracing changes nothing in the image.
  const RenderOutput plain = test::render(scene, camera, RasterOptions{});
  EXPECT_EQ(plain.image.color, traced.image.color);
  EXPECT_EQ(plain.image.depth, traced.image.depth);
}

TEST(TracePixel, OnlyTheTileHoldingThePixelRecords) {
  const Scene scene = loadScene(test::scenePath("three-triangles.gltf"));
  const Camera camera = makeCamera(scene, CameraOverrides{}, 160, 120);
  RasterOptions o;
  o.spp = 4;
  TraceLog log;
  o.trace = {&log, {100, 70}};
  test::render(scene, camera, o);
  const std::vector<TraceEvent> events = log.events();
  ASSERT_FALSE(events.empty());
  int tiles = 0, finals = 0;
  for (const TraceEvent& e : events) {
    tiles += e.stage == TraceStage::Tile;
    finals += e.stage == TraceStage::Final;
  }
  EXPECT_EQ(tiles, 1);
  EXPECT_EQ(finals, 4);  // one per sample of the pixel
  EXPECT_EQ(valueOf(events.front(), "rect"), "[64, 128) x [64, 120)");
}

}  // namespace
}  // namespace rastray
