// ShadowMaps (raster/shadow_map.h): the maps rendered through the fast
// depth-only pass equal those of the reference walk, texel for texel and
// fragment for fragment, and the fast lookup returns the reference
// lookup's bits, one point at a time and in batches. The default biases
// against references computed here: a steep lit plane shows no acne, and a
// wall on a 2e5-unit plane under a light 0.1° above the horizon casts the
// shadow its analytic mask says, no more and no less.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <random>
#include <string>

#include "common/analysis.h"
#include "common/gltf/loader.h"
#include "common/shading.h"
#include "raster/rasterizer.h"
#include "raster/shadow_map.h"
#include "raster_test_util.h"
#include "tests/test_labels.h"

namespace rastray {
namespace {

using test::addMesh;
using test::colored;

// A floor, opaque boxes' tops, a BLEND sheet and a refractive sheet above
// it, lit by a point, a spot and a directional light.
Scene lightScene() {
  Scene scene;
  const std::vector<glm::uvec3> quad = {{0, 1, 2}, {0, 2, 3}};
  const auto square = [](double cx, double y, double cz, double h) {
    const float x0 = float(cx - h), x1 = float(cx + h), z0 = float(cz - h), z1 = float(cz + h), fy = float(y);
    return std::vector<glm::vec3>{{x0, fy, z1}, {x1, fy, z1}, {x1, fy, z0}, {x0, fy, z0}};
  };
  addMesh(scene, square(0, 0, 0, 3), quad, colored(glm::vec4(0.8f)));
  addMesh(scene, square(-1.2, 1.0, 0.4, 0.5), quad, colored(glm::vec4(0.8f, 0.2f, 0.2f, 1)));
  addMesh(scene, square(1.0, 0.6, -0.8, 0.4), quad, colored(glm::vec4(0.2f, 0.8f, 0.2f, 1)));
  addMesh(scene, square(0.3, 1.3, 0.9, 0.7), quad,
          colored(glm::vec4(0.2f, 0.2f, 0.9f, 0.4f), AlphaMode::Blend, true));
  Material glass = colored(glm::vec4(0.9f, 0.95f, 1.0f, 1.0f), AlphaMode::Opaque, true);
  glass.transmission = 1.0f;
  addMesh(scene, square(-0.2, 1.6, -0.6, 0.6), quad, glass);
  // A coplanar copy of the glass: two layers with equal keys at each texel.
  addMesh(scene, square(-0.2, 1.6, -0.6, 0.6), quad, glass);
  Light point;
  point.type = LightType::Point;
  point.position = glm::dvec3(0.2, 2.5, 0.1);
  Light spot = point;
  spot.type = LightType::Spot;
  spot.position = glm::dvec3(-1.0, 3.0, 1.0);
  spot.direction = glm::normalize(glm::dvec3(0.3, -1.0, -0.3));
  spot.outerConeAngle = 0.9f;
  Light sun;
  sun.type = LightType::Directional;
  sun.direction = glm::normalize(glm::dvec3(0.4, -1.0, 0.2));
  scene.lights = {point, spot, sun};
  return scene;
}

struct Fixture {
  Scene scene = lightScene();
  SceneAnalysis analysis = analyzeScene(scene);
  Camera camera = test::perspectiveCamera(64, 64, 1.0, glm::dvec3(0, 5, 4), glm::dvec3(0), 0.1);
  RasterOptions options;
  Shader shader{scene, analysis, camera, options.shading, nullptr, nullptr};
  Fixture(int size) { options.shadowMapSize = size; }
};

TEST(ShadowMapPass, FastMapsEqualTheReferenceWalks) {
  for (int size : {100, 256}) {
    Fixture f(size);
    const ShadowMaps fast(f.scene, f.options, &f.shader, CoveragePath::Fast);
    const ShadowMaps slow(f.scene, f.options, &f.shader, CoveragePath::Reference);
    ASSERT_EQ(fast.mapCount(), 8u);  // 6 cube faces, a spot map, a directional map
    ASSERT_EQ(slow.mapCount(), fast.mapCount());
    EXPECT_GT(fast.attenuatingFragments(), 0u);
    EXPECT_EQ(fast.attenuatingFragments(), slow.attenuatingFragments());
    for (size_t i = 0; i < fast.mapCount(); ++i) {
      const ShadowMaps::Map& a = fast.mapAt(i);
      const ShadowMaps::Map& b = slow.mapAt(i);
      for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x)
          ASSERT_EQ(a.depth.key(x, y), b.depth.key(x, y)) << "map " << i << " texel " << x << " " << y;
      ASSERT_EQ(a.attenuation.size(), b.attenuation.size()) << "map " << i;
      for (size_t tile = 0; tile < a.attenuation.size(); ++tile) {
        ASSERT_EQ(a.attenuation[tile].size(), b.attenuation[tile].size()) << "map " << i << " tile " << tile;
        for (size_t k = 0; k < a.attenuation[tile].size(); ++k) {
          EXPECT_EQ(a.attenuation[tile][k].texel, b.attenuation[tile][k].texel);
          EXPECT_EQ(a.attenuation[tile][k].key, b.attenuation[tile][k].key);
          EXPECT_EQ(a.attenuation[tile][k].transmittance, b.attenuation[tile][k].transmittance);
        }
      }
      EXPECT_EQ(a.attenuationTexels, b.attenuationTexels) << "map " << i;
    }
  }
}

// The maps of every lit bundled scene (scenes/*.gltf, scenes/stiff/*.gltf)
// by 8×8 blocks (planes, keys, clear) against the reference walk's, whose
// blocks are all keys (the maps as they were stored before blocks): every
// texel's key, every transmissive fragment, and the transmittance of
// lookups at every triangle's vertices and centroid, from the fast lookup
// on the block maps and the reference lookup on the reference maps.
TEST(ShadowMapPass, BlockMapsLookUpAsTheReferenceMapsOnTheBundledLitScenes) {
  std::vector<std::string> paths;
  for (const char* dir : {"", "/stiff"})
    for (const auto& entry : std::filesystem::directory_iterator(std::string(RASTRAY_SCENES) + dir))
      if (entry.path().extension() == ".gltf") paths.push_back(entry.path().string());
  std::sort(paths.begin(), paths.end());
  size_t lit = 0, planeBlocks = 0, lookups = 0, dark = 0, partial = 0;
  for (const std::string& path : paths) {
    const Scene scene = loadScene(path);
    if (scene.lights.empty()) continue;
    ++lit;
    const SceneAnalysis analysis = analyzeScene(scene);
    const Camera camera = makeCamera(scene, {}, 16, 16);
    RasterOptions options;
    options.shadowMapSize = 150;  // partial tiles and blocks at the edges
    const Shader shader{scene, analysis, camera, options.shading, nullptr, nullptr};
    const ShadowMaps fast(scene, options, &shader, CoveragePath::Fast);
    const ShadowMaps slow(scene, options, &shader, CoveragePath::Reference);
    ASSERT_EQ(fast.mapCount(), slow.mapCount()) << path;
    for (size_t i = 0; i < fast.mapCount(); ++i) {
      const ShadowMaps::Map& a = fast.mapAt(i);
      const ShadowMaps::Map& b = slow.mapAt(i);
      for (uint32_t o : a.depth.owner) planeBlocks += BlockDepthMap::isPlane(o);
      for (int y = 0; y < options.shadowMapSize; ++y)
        for (int x = 0; x < options.shadowMapSize; ++x)
          ASSERT_EQ(a.depth.key(x, y), b.depth.key(x, y))
              << path << " map " << i << " texel " << x << " " << y;
      ASSERT_EQ(a.attenuation.size(), b.attenuation.size()) << path;
      for (size_t tile = 0; tile < a.attenuation.size(); ++tile) {
        ASSERT_EQ(a.attenuation[tile].size(), b.attenuation[tile].size()) << path;
        for (size_t k = 0; k < a.attenuation[tile].size(); ++k) {
          ASSERT_EQ(a.attenuation[tile][k].texel, b.attenuation[tile][k].texel) << path;
          ASSERT_EQ(a.attenuation[tile][k].key, b.attenuation[tile][k].key) << path;
          ASSERT_EQ(a.attenuation[tile][k].transmittance, b.attenuation[tile][k].transmittance) << path;
        }
      }
    }
    for (uint32_t inst = 0; inst < scene.instances.size(); ++inst)
      for (uint32_t t = 0; t < scene.instances[inst].triangleCount; ++t)
        for (const glm::vec2 bary :
             {glm::vec2(0, 0), glm::vec2(1, 0), glm::vec2(0, 1), glm::vec2(1.0f / 3)}) {
          const SurfacePoint p = makeSurfacePoint(scene, SampleHit{inst, t, 0.0f, bary.x, bary.y});
          for (size_t l = 0; l < scene.lights.size(); ++l) {
            const Light& light = scene.lights[l];
            const glm::dvec3 toLight = light.type == LightType::Directional
                                           ? -light.direction
                                           : glm::normalize(light.position - p.position);
            const glm::vec3 f = fast.lightTransmittance(int(l), p.position, p.geometricNormal, toLight);
            const glm::vec3 r =
                slow.lightTransmittanceReference(int(l), p.position, p.geometricNormal, toLight);
            ASSERT_EQ(std::memcmp(&f, &r, sizeof f), 0) << path << " instance " << inst << " triangle " << t;
            ++lookups;
            dark += f == glm::vec3(0.0f);
            partial += f != glm::vec3(0.0f) && f != glm::vec3(1.0f);
          }
        }
  }
  // Not vacuous: lit scenes, planes, shadows and light through glass.
  EXPECT_GE(lit, 10u);
  EXPECT_GT(planeBlocks, 1000u);
  EXPECT_GT(dark, 100u);
  EXPECT_GT(partial, 10u);
  std::printf("%zu lit scenes, %zu plane blocks, %zu lookups (%zu dark, %zu partial)\n", lit, planeBlocks,
              lookups, dark, partial);
}
RASTRAY_TEST_LABELS_OF(ShadowMapPass, BlockMapsLookUpAsTheReferenceMapsOnTheBundledLitScenes, "slow");

// The tiles' fragment sort gives std::stable_sort's order by (texel,
// key): few fragments and many (the counting pass), every texel of a
// corner tile and of an edge tile narrower than kTileSize, equal keys at
// a texel (coplanar layers) kept in the order met.
TEST(ShadowMapPass, TileFragmentSortIsTheStableSortByTexelAndKey) {
  std::mt19937 rng(17);
  const size_t width = 150;  // tiles of 64, 64 and 22 texels across
  const TileGrid tiles(int(width), 100);
  for (int tile : {0, 2, tiles.count() - 1})
    for (size_t n :
         {size_t(0), size_t(1), size_t(40), size_t(255), size_t(256), size_t(3000), size_t(20000)}) {
      const TileRect rect = tiles.rect(tile);
      const int w = rect.x1 - rect.x0, h = rect.y1 - rect.y0;
      std::vector<ShadowMaps::Attenuation> v;
      for (size_t i = 0; i < n; ++i) {
        // A few texels hold many fragments; keys from a small set, so ties abound.
        const int x = rect.x0 + int(rng() % uint32_t(i % 3 == 0 ? 2 : w));
        const int y = rect.y0 + int(rng() % uint32_t(i % 3 == 0 ? 2 : h));
        v.push_back({uint32_t(size_t(y) * width + size_t(x)), uint32_t(rng() % 5), glm::vec3(float(i))});
      }
      std::vector<ShadowMaps::Attenuation> expected = v;
      std::stable_sort(expected.begin(), expected.end(),
                       [](const ShadowMaps::Attenuation& a, const ShadowMaps::Attenuation& b) {
                         return a.texel != b.texel ? a.texel < b.texel : a.key < b.key;
                       });
      std::vector<uint32_t> starts;
      sortTileFragments(rect, width, &v, &starts);
      ASSERT_EQ(v.size(), expected.size());
      for (size_t i = 0; i < n; ++i) {
        ASSERT_EQ(v[i].texel, expected[i].texel) << "tile " << tile << " n " << n << " at " << i;
        ASSERT_EQ(v[i].key, expected[i].key) << "tile " << tile << " n " << n << " at " << i;
        ASSERT_EQ(v[i].transmittance, expected[i].transmittance)
            << "tile " << tile << " n " << n << " at " << i;
      }
    }
}

// The tiles' texel index from the sort against each texel's first
// fragment found by a scan: no fragments (no index), one, a few, many,
// rows left empty at the top, middle and bottom, and a tile of 22 × 36
// texels at the map's corner (the slots past its edges index the next
// texel of the rect, the last the end).
TEST(ShadowMapPass, TileTexelIndexIsEachTexelsFirstFragment) {
  std::mt19937 rng(23);
  const size_t width = 150, height = 100;  // tiles of 64, 64 and 22 columns, 64 and 36 rows
  const TileGrid tiles{int(width), int(height)};
  for (int tile : {0, 2, tiles.count() - 1})
    for (size_t n : {size_t(0), size_t(1), size_t(7), size_t(500), size_t(5000)}) {
      const TileRect rect = tiles.rect(tile);
      const int w = rect.x1 - rect.x0, h = rect.y1 - rect.y0;
      std::vector<ShadowMaps::Attenuation> v;
      for (size_t i = 0; i < n; ++i) {
        // Every third row left empty.
        int y = rect.y0 + int(rng() % uint32_t(h));
        if ((y - rect.y0) % 3 == 1) y = rect.y0;
        const int x = rect.x0 + int(rng() % uint32_t(w));
        v.push_back({uint32_t(size_t(y) * width + size_t(x)), uint32_t(rng() % 5), glm::vec3(1.0f)});
      }
      std::vector<uint32_t> starts{1, 2, 3};  // replaced
      sortTileFragments(rect, width, &v, &starts);
      if (n == 0) {
        EXPECT_TRUE(starts.empty()) << "tile " << tile;
        continue;
      }
      // A fragment's slot in the tile; the fragments are sorted by texel.
      const auto slotOf = [&](const ShadowMaps::Attenuation& a) {
        return (a.texel / width - size_t(rect.y0)) * size_t(kTileSize) + (a.texel % width - size_t(rect.x0));
      };
      std::vector<uint32_t> expected(size_t(kTileSize) * kTileSize + 1);
      size_t first = 0;
      for (size_t slot = 0; slot < expected.size(); ++slot) {
        while (first < v.size() && slotOf(v[first]) < slot) ++first;
        expected[slot] = uint32_t(first);
      }
      EXPECT_EQ(starts, expected) << "tile " << tile << " n " << n;
    }
}

TEST(ShadowMapLookup, FastLookupReturnsTheReferenceBits) {
  Fixture f(200);  // not a multiple of the tile size: partial tiles in the row index
  const ShadowMaps maps(f.scene, f.options, &f.shader);
  std::mt19937 rng(17);
  const auto u = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  size_t dark = 0, partial = 0, lit = 0;
  for (int l = 0; l < 3; ++l) {
    std::vector<glm::dvec3> points, normals, toLight;
    for (int i = 0; i < 20000; ++i) {
      // Mostly on the lit surfaces (where lookups meet their own depth), some anywhere.
      const double heights[] = {0.0, 1.0, 0.6, u(-1, 4)};
      const glm::dvec3 p(u(-3.5, 3.5), heights[rng() % 4], u(-3.5, 3.5));
      const Light& light = f.scene.lights[size_t(l)];
      const glm::dvec3 d =
          light.type == LightType::Directional ? -light.direction : glm::normalize(light.position - p);
      points.push_back(p);
      // The floor's and tops' normal, some tilted, some zero (no receiver plane).
      const glm::dvec3 normals3[] = {glm::dvec3(0, 1, 0), glm::normalize(glm::dvec3(u(-1, 1), 1, u(-1, 1))),
                                     glm::dvec3(0)};
      normals.push_back(normals3[rng() % 3]);
      toLight.push_back(d);
    }
    std::vector<glm::vec3> batch(points.size());
    maps.lightTransmittances(l, points.size(), points.data(), normals.data(), toLight.data(), batch.data());
    for (size_t i = 0; i < points.size(); ++i) {
      const glm::vec3 fast = maps.lightTransmittance(l, points[i], normals[i], toLight[i]);
      const glm::vec3 ref = maps.lightTransmittanceReference(l, points[i], normals[i], toLight[i]);
      ASSERT_EQ(fast, ref) << "light " << l << " point " << points[i].x << " " << points[i].y << " "
                           << points[i].z;
      ASSERT_EQ(batch[i], fast);
      SurfacePoint sp;
      sp.position = points[i];
      sp.geometricNormal = normals[i];
      ASSERT_EQ(maps.transmittance(sp, l, toLight[i], 1.0), fast);
      if (fast == glm::vec3(0.0f))
        ++dark;
      else if (fast == glm::vec3(1.0f))
        ++lit;
      else
        ++partial;
    }
  }
  // Every kind of answer was checked.
  EXPECT_GT(dark, 1000u);
  EXPECT_GT(partial, 1000u);
  EXPECT_GT(lit, 1000u);
}

// Receiver-plane depth: a plane tilted 80° from a directional light is
// its own only occluder, so every point on it is lit. Looked up with its
// normal (the receiver plane) no point is dark under the default biases
// nor with a tenth of the slope bias; the same lookups at the point's own
// depth with that bias darken points all over it: the acne the receiver
// plane removes without pushing surfaces back by a texel of their slope.
TEST(ShadowMapLookup, ReceiverPlaneLeavesASteepPlaneLitWhereItsOwnDepthDoesNot) {
  Scene scene;
  const double tilt = 80.0 * kPi / 180.0;  // between the plane's normal and the light
  // The plane y = x·tan(tilt)... written as points (u, u·t, v): normal ∝ (−t, 1, 0).
  const double t = std::tan(tilt);
  const std::vector<glm::vec3> plane = {
      {-1.0f, float(-t), -1.0f}, {1.0f, float(t), -1.0f}, {1.0f, float(t), 1.0f}, {-1.0f, float(-t), 1.0f}};
  addMesh(scene, plane, {{0, 2, 1}, {0, 3, 2}}, colored(glm::vec4(0.8f), AlphaMode::Opaque, true));
  Light sun;
  sun.type = LightType::Directional;
  sun.direction = glm::dvec3(0, -1, 0);
  scene.lights = {sun};
  const glm::dvec3 normal = glm::normalize(glm::dvec3(-t, 1.0, 0.0));
  ASSERT_NEAR(glm::dot(normal, -sun.direction), std::cos(tilt), 1e-12);

  const auto darkPoints = [&](const RasterOptions& options, bool withNormal) {
    const ShadowMaps maps(scene, options, nullptr);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-0.95, 0.95);
    int dark = 0;
    for (int i = 0; i < 20000; ++i) {
      const double x = u(rng), z = u(rng);
      const glm::dvec3 p(x, x * double(float(t)), z);
      const glm::vec3 v =
          maps.lightTransmittance(0, p, withNormal ? normal : glm::dvec3(0.0), -sun.direction);
      dark += v == glm::vec3(0.0f) ? 1 : 0;
    }
    return dark;
  };
  RasterOptions defaults;
  defaults.shadowMapSize = 256;
  EXPECT_EQ(darkPoints(defaults, true), 0);
  // A tenth of a texel of slope covers the setup's 1/256-texel vertex snap
  // but not the half texel between a point and its texel's sample.
  RasterOptions small = defaults;
  small.shadowBiasSlope = 0.1f;
  EXPECT_EQ(darkPoints(small, true), 0);
  EXPECT_GT(darkPoints(small, false), 2000);
}

// Issue 24: a grazing light keeps its shadow. A plane 2e3 × 2e5 units, a
// wall 0.2 × 0.5 × 19950 standing on it, and a directional light 89.9°
// from the plane's normal, across the wall: the wall's shadow reaches
// 0.5·tan(89.9°) = 286.5 units from it. The mask is computed here, not by
// rastray: a floor point (x, 0, z) with −2e4 ≤ z ≤ −50 is shadowed exactly
// when −1.3 < x ≤ −1.3 + 0.5·tan(a) (the segment to the light crosses the
// wall's top corner line); the camera looks down at a 400 × 200 patch
// across the shadow. Pixels within 3 units of the shadow's edges in x are
// not judged (two pixels, and the map's texel on the plane across the
// light, 4e-3 / cos a = 2.3 units at 1024). Before the directional map was
// fitted to the scene per axis, its texels were 195 units wide and the
// whole plane lay in one texel row: every shadowed pixel was lit.
TEST(ShadowMapGrazing, AWallKeepsItsShadowOnA2e5UnitPlaneAgainstTheAnalyticMask) {
  Scene scene;
  const Material grey = colored(glm::vec4(0.8f, 0.8f, 0.8f, 1.0f));
  addMesh(scene, {{-1e3f, 0.0f, 1e4f}, {1e3f, 0.0f, 1e4f}, {1e3f, 0.0f, -1.9e5f}, {-1e3f, 0.0f, -1.9e5f}},
          {{0, 1, 2}, {0, 2, 3}}, grey);
  // The wall, a closed box.
  const float x0 = -1.5f, x1 = -1.3f, y1 = 0.5f, z0 = -2e4f, z1 = -50.0f;
  addMesh(scene,
          {{x0, 0, z0},
           {x1, 0, z0},
           {x1, y1, z0},
           {x0, y1, z0},
           {x0, 0, z1},
           {x1, 0, z1},
           {x1, y1, z1},
           {x0, y1, z1}},
          {{0, 2, 1},
           {0, 3, 2},
           {4, 5, 6},
           {4, 6, 7},
           {0, 4, 7},
           {0, 7, 3},
           {1, 2, 6},
           {1, 6, 5},
           {3, 7, 6},
           {3, 6, 2},
           {0, 1, 5},
           {0, 5, 4}},
          colored(glm::vec4(0.8f, 0.8f, 0.8f, 1.0f), AlphaMode::Opaque, true));  // no culling: winding moot
  const double a = 89.9 * kPi / 180.0;
  Light sun;
  sun.type = LightType::Directional;
  sun.direction = glm::dvec3(std::sin(a), -std::cos(a), 0.0);
  sun.intensity = float(1.0 / std::cos(a));  // the plane's unshadowed shade ≈ 0.8/π
  scene.lights = {sun};
  const SceneAnalysis analysis = analyzeScene(scene);
  const Camera camera = test::perspectiveCamera(200, 100, 2.0 * std::atan(100.0 / 300.0),
                                                glm::dvec3(140, 300, -1000), glm::dvec3(140, 0, -1001));
  RasterOptions options;  // the default map size and biases
  const RenderOutput out = renderRaster(scene, analysis, camera, options);

  const double edge = -1.3 + 0.5 * std::tan(a);
  const double lit = 0.8 / kPi * double(sun.intensity) * std::cos(a);  // Lambert, n = +y
  int shadowed = 0, litPixels = 0, wrong = 0;
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x) {
      const Ray ray = camera.primaryRay(glm::dvec2(x + 0.5, y + 0.5));
      ASSERT_LT(ray.direction.y, 0.0);
      const glm::dvec3 p = ray.origin + ray.direction * (-ray.origin.y / ray.direction.y);
      ASSERT_TRUE(p.z > -2e4 + 100 && p.z < -100) << "the patch lies beside the wall's middle";
      if (std::abs(p.x - x1) < 3.0 || std::abs(p.x - edge) < 3.0 || p.x < double(x1)) continue;
      const bool inShadow = p.x < edge;
      const glm::vec4 c = out.image.color[size_t(y) * size_t(camera.width) + size_t(x)];
      const bool rendererLit = double(c.r) > 0.5 * lit;
      (inShadow ? shadowed : litPixels) += 1;
      wrong += rendererLit == inShadow ? 1 : 0;
    }
  EXPECT_GT(shadowed, 10000);
  EXPECT_GT(litPixels, 1000);
  EXPECT_EQ(wrong, 0) << "of " << shadowed << " shadowed and " << litPixels << " lit pixels";
}

}  // namespace
}  // namespace rastray
