// ShadowMaps (raster/shadow_map.h): the maps rendered through the fast
// depth-only pass equal those of the reference walk, texel for texel and
// fragment for fragment, and the fast lookup returns the reference
// lookup's bits, one point at a time and in batches.
#include <gtest/gtest.h>

#include <random>

#include "common/analysis.h"
#include "common/shading.h"
#include "raster/shadow_map.h"
#include "raster_test_util.h"

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
      const size_t n = size_t(size) * size_t(size);
      ASSERT_TRUE(std::equal(a.depth.keys.get(), a.depth.keys.get() + n, b.depth.keys.get())) << "map " << i;
      ASSERT_EQ(a.attenuation.size(), b.attenuation.size()) << "map " << i;
      for (size_t k = 0; k < a.attenuation.size(); ++k) {
        EXPECT_EQ(a.attenuation[k].texel, b.attenuation[k].texel);
        EXPECT_EQ(a.attenuation[k].key, b.attenuation[k].key);
        EXPECT_EQ(a.attenuation[k].transmittance, b.attenuation[k].transmittance);
      }
      EXPECT_EQ(a.attenuationRows, b.attenuationRows) << "map " << i;
    }
  }
}

TEST(ShadowMapLookup, FastLookupReturnsTheReferenceBits) {
  Fixture f(200);  // not a multiple of the tile size: partial tiles in the row index
  const ShadowMaps maps(f.scene, f.options, &f.shader);
  std::mt19937 rng(17);
  const auto u = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  size_t dark = 0, partial = 0, lit = 0;
  for (int l = 0; l < 3; ++l) {
    std::vector<glm::dvec3> points, toLight;
    for (int i = 0; i < 20000; ++i) {
      // Mostly on the lit surfaces (where lookups meet their own depth), some anywhere.
      const double heights[] = {0.0, 1.0, 0.6, u(-1, 4)};
      const glm::dvec3 p(u(-3.5, 3.5), heights[rng() % 4], u(-3.5, 3.5));
      const Light& light = f.scene.lights[size_t(l)];
      const glm::dvec3 d =
          light.type == LightType::Directional ? -light.direction : glm::normalize(light.position - p);
      points.push_back(p);
      toLight.push_back(d);
    }
    std::vector<glm::vec3> batch(points.size());
    maps.lightTransmittances(l, points.size(), points.data(), toLight.data(), batch.data());
    for (size_t i = 0; i < points.size(); ++i) {
      const glm::vec3 fast = maps.lightTransmittance(l, points[i], toLight[i]);
      const glm::vec3 ref = maps.lightTransmittanceReference(l, points[i], toLight[i]);
      ASSERT_EQ(fast, ref) << "light " << l << " point " << points[i].x << " " << points[i].y << " "
                           << points[i].z;
      ASSERT_EQ(batch[i], fast);
      SurfacePoint sp;
      sp.position = points[i];
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

}  // namespace
}  // namespace rastray
