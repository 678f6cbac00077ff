#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <random>
#include <string>

#include "common/gltf/loader.h"
#include "common/sampling.h"
#include "common/surface.h"
#include "common/texture.h"
#include "raster/rasterizer.h"
#include "raster/resolve.h"
#include "raster_test_util.h"

#include "tests/test_labels.h"

// Every test here renders on 2 or more threads (the ThreadSanitizer stage runs them).
RASTRAY_TEST_LABELS("threads");

namespace rastray {
namespace {

using test::addMesh;
using test::colored;
using test::render;
using test::scenePath;

Camera sceneCamera(const Scene& scene, int w, int h) { return makeCamera(scene, CameraOverrides{}, w, h); }

TEST(ThreeTriangles, ExactIdsAndDepthsAtEverySample) {
  const Scene scene = loadScene(scenePath("three-triangles.gltf"));
  const Camera camera = sceneCamera(scene, 8, 8);
  RasterOptions o;
  const RenderOutput out = render(scene, camera, o);
  // Pixel centres (1 spp) by hand: world (x, y) = ((px + .5)/4 − 1, 1 − (py + .5)/4).
  // Y = yellow (0, depth 0.5), B = blue (1, 0.75), R = red (2, 0.25); R in front.
  // Row 5 (y = −0.375) lies on yellow's horizontal bottom edge: not yellow's
  // under the top-left rule, so blue shows at (5, 5) and (6, 5).
  const char* expected[8] = {"........", "........", "...YY...", "..RRYB..",
                             ".RRRYYB.", ".RRRRBB.", "...RR...", "........"};
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      const size_t p = out.image.index(x, y);
      const char e = expected[y][x];
      const uint32_t inst = e == 'Y' ? 0u : e == 'B' ? 1u : e == 'R' ? 2u : kNoId;
      const float depth = e == 'Y' ? 0.5f : e == 'B' ? 0.75f : e == 'R' ? 0.25f : INFINITY;
      EXPECT_EQ(out.image.instance[p], inst) << x << "," << y;
      EXPECT_EQ(out.image.triangle[p], inst == kNoId ? kNoId : 0u) << x << "," << y;
      EXPECT_FLOAT_EQ(out.image.depth[p], depth) << x << "," << y;
      EXPECT_EQ(out.image.color[p].a, inst == kNoId ? 0.0f : 1.0f);
    }
}

// The rasterizer's own hit (perspective-correct b1, b2 and depth) of the
// nearest visible surface at sample s of pixel (x, y).
SampleHit rasterHit(const Scene& scene, const Camera& camera, int spp, int x, int y, int s) {
  RasterOptions o;
  o.spp = spp;
  std::vector<SampleHit> hits;
  renderRasterWithHits(scene, analyzeScene(scene), camera, o, &hits);
  return hits[(size_t(y) * size_t(camera.width) + size_t(x)) * size_t(spp) + size_t(s)];
}

// Barycentrics at pixel (3, 2), world (−0.125, 0.375) on yellow (vertices
// (−0.625, −0.375), (0.625, −0.375), (0, 0.75) in stored order):
// b2 = (0.375 + 0.375) / 1.125 = 2/3, b1 = (−0.125 + 0.625 − 2/3 · 0.625) / 1.25 = 1/15.
TEST(ThreeTriangles, RasterBarycentricsMatchHandValues) {
  const Scene scene = loadScene(scenePath("three-triangles.gltf"));
  const Camera camera = sceneCamera(scene, 8, 8);
  const SampleHit h = rasterHit(scene, camera, 1, 3, 2, 0);
  EXPECT_EQ(h.instance, 0u);
  EXPECT_NEAR(h.b1, 1.0 / 15.0, 1e-6);
  EXPECT_NEAR(h.b2, 2.0 / 3.0, 1e-6);
  EXPECT_FLOAT_EQ(h.depth, 0.5f);
}

TEST(Interpenetration, VisibilitySwitchesAtTheIntersectionLine) {
  const Scene scene = loadScene(scenePath("interpenetrating.gltf"));
  const Camera camera = sceneCamera(scene, 96, 72);
  RasterOptions o;
  o.spp = 4;
  o.keepSamples = true;
  const RenderOutput out = render(scene, camera, o);
  // Every sample where both triangles overlap shows instance A above y = 0
  // and B below (or the reverse): check through the world position of the hit.
  int above[2] = {0, 0}, below[2] = {0, 0};
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x) {
      const size_t p = out.image.index(x, y);
      if (out.image.instance[p] == kNoId) continue;
      // Flat ids come from the sample nearest the pixel centre.
      const Ray ray = camera.primaryRay(glm::dvec2(x, y) + samplePositions(4)[size_t(centreSampleIndex(4))]);
      // Both planes hit along this ray? Then the visible one must be the nearer.
      double t[2];
      glm::dvec2 b[2];
      bool both = true;
      for (uint32_t i = 0; i < 2; ++i) {
        both = both && intersectTrianglePlane(scene, i, 0, ray, &t[i], &b[i]) && b[i].x >= 0.02 &&
               b[i].y >= 0.02 && b[i].x + b[i].y <= 0.98;
      }
      if (!both || std::abs(t[0] - t[1]) < 1e-3) continue;
      const uint32_t nearer = t[0] < t[1] ? 0u : 1u;
      EXPECT_EQ(out.image.instance[p], nearer) << x << "," << y;
      const double worldY = (ray.origin + ray.direction * t[nearer]).y;
      (worldY > 0 ? above : below)[nearer]++;
    }
  // The split is along y = 0: each triangle wins on one side only.
  EXPECT_GT(above[0] + above[1], 10);
  EXPECT_GT(below[0] + below[1], 10);
  EXPECT_TRUE((above[0] == 0 && below[1] == 0) || (above[1] == 0 && below[0] == 0))
      << above[0] << " " << above[1] << " " << below[0] << " " << below[1];
}

// Triangle order within instances permuted: identical buffers once the IDs
// are mapped back.
TEST(OrderIndependence, ShuffledTrianglesAndThreadCountsGiveIdenticalBuffers) {
  const Scene scene = loadScene(scenePath("cornell-box.gltf"));
  const Camera camera = sceneCamera(scene, 80, 60);
  RasterOptions o;
  o.spp = 4;
  o.shadows = RasterShadows::None;
  const RenderOutput ref = render(scene, camera, o);
  std::mt19937 rng(3);
  Scene shuffled = scene;
  std::vector<std::vector<uint32_t>> perm(scene.instances.size());  // new index → old index
  for (size_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& inst = scene.instances[i];
    perm[i].resize(inst.triangleCount);
    std::iota(perm[i].begin(), perm[i].end(), 0u);
    std::shuffle(perm[i].begin(), perm[i].end(), rng);
    for (uint32_t k = 0; k < inst.triangleCount; ++k)
      shuffled.triangles[inst.firstTriangle + k] = scene.triangles[inst.firstTriangle + perm[i][k]];
  }
  const RenderOutput out = render(shuffled, camera, o);
  size_t hits = 0;
  for (size_t p = 0; p < ref.image.instance.size(); ++p) {
    ASSERT_EQ(ref.image.instance[p], out.image.instance[p]) << p;
    if (ref.image.instance[p] == kNoId) continue;
    ++hits;
    EXPECT_EQ(ref.image.triangle[p], perm[out.image.instance[p]][out.image.triangle[p]]) << p;
    EXPECT_EQ(ref.image.depth[p], out.image.depth[p]) << p;
    EXPECT_EQ(ref.image.color[p], out.image.color[p]) << p;
  }
  EXPECT_GT(hits, ref.image.instance.size() / 2);
  {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    const RenderOutput serial = render(scene, camera, o);
    EXPECT_EQ(serial.image.color, ref.image.color);
    EXPECT_EQ(serial.image.instance, ref.image.instance);
    EXPECT_EQ(serial.image.triangle, ref.image.triangle);
    EXPECT_EQ(serial.image.depth, ref.image.depth);
  }
}

TEST(Clipping, CameraInsideABoxSeesWallsEverywhere) {
  Scene scene;
  // A closed cube [−1, 1]³, faces wound CCW from inside (so they face the camera).
  std::vector<glm::vec3> v;
  for (int i = 0; i < 8; ++i) v.push_back(glm::vec3(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1));
  const std::vector<glm::uvec3> outward = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                                           {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  std::vector<glm::uvec3> inward;
  for (const auto& t : outward) inward.push_back({t.x, t.z, t.y});
  addMesh(scene, v, inward, colored(glm::vec4(1)));
  const Camera camera =
      test::perspectiveCamera(64, 48, 2.0, glm::dvec3(0.1, 0.2, 0.3), glm::dvec3(1, 0.5, -1), 0.05);
  RasterOptions o;
  o.cull = CullMode::Back;  // the inward faces are front faces from inside
  o.keepSamples = true;
  const RenderOutput out = render(scene, camera, o);
  EXPECT_GT(out.counters.get("raster.clipped"), 0u);
  EXPECT_GT(out.counters.get("raster.triangles_from_clipping"), 0u);
  size_t exact = 0;
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x) {
      const size_t p = out.image.index(x, y);
      ASSERT_NE(out.image.instance[p], kNoId) << x << "," << y;
      // The analytic distance to the cube along the ray.
      const Ray ray = camera.primaryRay({x + 0.5, y + 0.5});
      double t = INFINITY;
      for (int a = 0; a < 3; ++a)
        for (double side : {-1.0, 1.0}) {
          const double ta = (side - ray.origin[a]) / ray.direction[a];
          if (ta > 0) t = std::min(t, ta);
        }
      // Depth comes from the unsnapped planes (exact to float); samples
      // within snapping distance (1/256 px) of a box edge may see the
      // neighbouring wall, whose plane meets this one there.
      const double error = std::abs(out.image.depth[p] - t * ray.depthPerT);
      EXPECT_LT(error, 1e-3 * t) << x << "," << y;
      exact += error < 1e-6 * t;
    }
  EXPECT_GT(exact, size_t(camera.width * camera.height) * 98 / 100);
}

TEST(Counters, NoBlendMaterialMeansNoTransparencyWork) {
  const Scene scene = loadScene(scenePath("three-triangles.gltf"));
  const RenderOutput out = render(scene, sceneCamera(scene, 16, 16), RasterOptions{});
  EXPECT_EQ(out.counters.get("raster.fragments_transparent"), 0u);
  EXPECT_EQ(out.counters.get("raster.triangles_in"), 3u);
  EXPECT_GT(out.counters.get("raster.fragments_opaque"), 0u);
  EXPECT_EQ(out.counters.get("raster.shadow_map_triangles"), 0u);
  const bool leftOut = std::any_of(
      out.passesLeftOut.begin(), out.passesLeftOut.end(),
      [](const std::string& s) { return s.rfind("transparency pass: no BLEND material", 0) == 0; });
  EXPECT_TRUE(leftOut);
}

TEST(Textures, MipLevelGrowsTowardsTheHorizonOnTheGrazingPlane) {
  const Scene scene = loadScene(scenePath("textured-plane.gltf"));
  const SceneAnalysis analysis = analyzeScene(scene);
  const Camera camera = sceneCamera(scene, 64, 64);
  RasterOptions o;
  o.keepSamples = true;
  o.shadows = RasterShadows::None;
  const RenderOutput out = renderRaster(scene, analysis, camera, o);
  const Shader shader(scene, analysis, camera, o.shading, nullptr, nullptr);
  // Level of detail along the centre column, bottom (near) to top (far).
  std::vector<float> lod;
  for (int y = camera.height - 1; y >= 0; --y) {
    const size_t p = out.image.index(camera.width / 2, y);
    if (out.image.instance[p] == kNoId) continue;
    const size_t k = out.samples.offsets[p];
    ASSERT_LT(k, out.samples.offsets[p + 1]);
    const Ray ray = camera.primaryRay({camera.width / 2 + 0.5, y + 0.5});
    const SampleHit hit = refineHit(
        scene, ray, SampleHit{out.samples.samples[k].instance, out.samples.samples[k].triangle, 0, 0, 0});
    const SurfacePoint sp = makeSurfacePoint(scene, hit);
    lod.push_back(shader.textures().levelOfDetail(
        sp.material->baseColorTexture, pixelFootprint(scene, camera, sp, {camera.width / 2 + 0.5, y + 0.5})));
  }
  ASSERT_GT(lod.size(), 10u);
  for (size_t i = 1; i < lod.size(); ++i) EXPECT_GE(lod[i], lod[i - 1] - 1e-3f) << i;
  EXPECT_LT(lod.front(), 2.0f);
  EXPECT_GT(lod.back(), lod.front() + 3.0f);
  // The far rows average the checker (trilinear); the near rows keep its contrast.
  float nearMin = 1, nearMax = 0;
  for (int x = 0; x < camera.width; ++x) {
    const float g = out.image.color[out.image.index(x, camera.height - 1)].g;
    nearMin = std::min(nearMin, g);
    nearMax = std::max(nearMax, g);
  }
  EXPECT_GT(nearMax - nearMin, 0.2f);
}

}  // namespace

}  // namespace rastray

namespace rastray {
namespace {

// A tile whose results are only its pixels takes the lean form
// (raster/resolve.h: no front hits, no background samples written; at
// shading rate pixel, pixels won by one setup alone take a path of their
// own): the same picture, depth and ids as the full form, which per-sample
// hits ask for. The Cornell box in perspective (depth varies along every
// wall; background at the open side), at every rate and at sample counts
// whose centre sample is the first and, at 25 (a 5 × 5 grid), is not.
TEST(LeanTiles, GiveTheFullFormsPicturesAtEveryRate) {
  const Scene scene = loadScene(scenePath("cornell-box.gltf"));
  const Camera camera = sceneCamera(scene, 97, 61);
  for (const int spp : {1, 2, 4, 25})
    for (const ShadingRate rate : {ShadingRate::Sample, ShadingRate::Pixel}) {
      SCOPED_TRACE("spp " + std::to_string(spp) + (rate == ShadingRate::Pixel ? " pixel" : " sample"));
      RasterOptions o;
      o.spp = spp;
      o.shadingRate = rate;
      o.shadows = RasterShadows::None;
      const RenderOutput lean = render(scene, camera, o);
      std::vector<SampleHit> hits;
      const RenderOutput full = renderRasterWithHits(scene, analyzeScene(scene), camera, o, &hits);
      const FlatImage &a = lean.image, &b = full.image;
      EXPECT_EQ(0, std::memcmp(a.color.data(), b.color.data(), a.color.size() * sizeof(glm::vec4)));
      EXPECT_EQ(0, std::memcmp(a.depth.data(), b.depth.data(), a.depth.size() * sizeof(float)));
      EXPECT_EQ(a.instance, b.instance);
      EXPECT_EQ(a.triangle, b.triangle);
      EXPECT_GT(std::count(a.instance.begin(), a.instance.end(), kNoId), 0);
    }
}

}  // namespace
}  // namespace rastray
