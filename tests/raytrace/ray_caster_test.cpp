// The ray caster on the bundled scenes: IDs and depths (SPEC §1, §4),
// front-to-back transparency against a brute-force reference, deep
// samples, packets against single rays, counters (SPEC §8), NaN-free
// output, degenerate triangles, and the hybrid interfaces.
#include "raytrace/ray_caster.h"

#include <gtest/gtest.h>

#include "common/math_constants.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "common/error.h"
#include "common/gltf/loader.h"
#include "common/parallel.h"
#include "common/sampling.h"
#include "common/shading.h"
#include "common/trace.h"
#include "test_scenes.h"

#include "tests/test_labels.h"

// Every test here renders on 2 or more threads (the ThreadSanitizer stage runs them).
RASTRAY_TEST_LABELS("threads");

namespace rastray {
namespace {

using test::scenePath;

RenderOutput renderScene(const Scene& scene, int w, int h, RayOptions options = {}) {
  const SceneAnalysis analysis = analyzeScene(scene);
  RayCaster caster(scene, analysis);
  caster.bind(makeCamera(scene, {}, w, h), options);
  return caster.render();
}

const char* kRayCounters[] = {"rays.primary", "rays.shadow", "rays.reflection", "rays.refraction",
                              "rays.transparency"};

bool hasCounter(const CounterSet& set, const std::string& name) {
  for (const auto& [n, v] : set.values)
    if (n == name) return true;
  return false;
}

// --- three-triangles: IDs and exact depths -------------------------------------

struct Tri2 {
  glm::dvec2 a, b, c;
  double depth;
  glm::vec3 color;
};

double edge(glm::dvec2 a, glm::dvec2 b, glm::dvec2 p) {
  return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
}

TEST(ThreeTriangles, IdsAndDepthsMapToSpecInstances) {
  const Scene scene = loadScene(scenePath("three-triangles.gltf"));
  // From the scene's README: instance 0 yellow at z = −0.5, 1 blue at
  // −0.75, 2 red at −0.25 (the camera sits at the origin looking down −z).
  const Tri2 tris[3] = {{{-0.625, -0.375}, {0.625, -0.375}, {0.0, 0.75}, 0.5, {1, 1, 0}},
                        {{-0.375, -0.75}, {0.875, -0.5}, {0.25, 0.5}, 0.75, {0, 0, 1}},
                        {{-0.875, -0.5}, {0.375, -0.75}, {-0.25, 0.5}, 0.25, {1, 0, 0}}};
  const int size = 64;
  const RenderOutput out = renderScene(scene, size, size);
  int checked = 0, covered[3] = {0, 0, 0};
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      // Orthographic xmag = ymag = 1: NDC is world x, y.
      const glm::dvec2 p(2.0 * (x + 0.5) / size - 1.0, 1.0 - 2.0 * (y + 0.5) / size);
      int front = -1;
      bool onEdge = false;
      for (int i = 0; i < 3; ++i) {
        const double e0 = edge(tris[i].a, tris[i].b, p), e1 = edge(tris[i].b, tris[i].c, p),
                     e2 = edge(tris[i].c, tris[i].a, p);
        if (e0 == 0.0 || e1 == 0.0 || e2 == 0.0) onEdge = true;
        const bool inside = (e0 > 0 && e1 > 0 && e2 > 0) || (e0 < 0 && e1 < 0 && e2 < 0);
        if (inside && (front < 0 || tris[i].depth < tris[front].depth)) front = i;
      }
      if (onEdge) continue;
      ++checked;
      const size_t i = out.image.index(x, y);
      if (front < 0) {
        EXPECT_EQ(out.image.instance[i], kNoId) << x << "," << y;
        EXPECT_EQ(out.image.triangle[i], kNoId);
        EXPECT_TRUE(std::isinf(out.image.depth[i]));
        EXPECT_EQ(out.image.color[i], glm::vec4(0.0f));
        continue;
      }
      ++covered[front];
      ASSERT_EQ(out.image.instance[i], uint32_t(front)) << "pixel " << x << "," << y;
      EXPECT_EQ(out.image.triangle[i], 0u);
      EXPECT_EQ(out.image.depth[i], float(tris[front].depth)) << "pixel " << x << "," << y;
      // Eye light, facing the camera: the base colour itself.
      EXPECT_NEAR(out.image.color[i].r, tris[front].color.r, 1e-6);
      EXPECT_NEAR(out.image.color[i].g, tris[front].color.g, 1e-6);
      EXPECT_NEAR(out.image.color[i].b, tris[front].color.b, 1e-6);
      EXPECT_EQ(out.image.color[i].a, 1.0f);
    }
  EXPECT_GT(checked, size * size * 9 / 10);
  for (int i = 0; i < 3; ++i) EXPECT_GT(covered[i], 50) << "instance " << i;
}

TEST(Counters, OnlyPrimaryRaysForThreeTriangles) {
  const Scene scene = loadScene(scenePath("three-triangles.gltf"));
  RayOptions options;
  options.spp = 4;
  const RenderOutput out = renderScene(scene, 32, 32, options);
  for (const char* name : kRayCounters) EXPECT_TRUE(hasCounter(out.counters, name)) << name;
  EXPECT_EQ(out.counters.get("rays.primary"), 32u * 32u * 4u);
  EXPECT_EQ(out.counters.get("rays.shadow"), 0u);
  EXPECT_EQ(out.counters.get("rays.reflection"), 0u);
  EXPECT_EQ(out.counters.get("rays.refraction"), 0u);
  EXPECT_EQ(out.counters.get("rays.transparency"), 0u);
}

TEST(Counters, EachSceneCountsOnlyWhatItNeeds) {
  {
    const RenderOutput out = renderScene(loadScene(scenePath("cornell-box.gltf")), 32, 32);
    EXPECT_EQ(out.counters.get("rays.primary"), 32u * 32u);
    EXPECT_GT(out.counters.get("rays.shadow"), 0u);
    EXPECT_GT(out.counters.get("rays.reflection"), 0u);
    EXPECT_GT(out.counters.get("rays.refraction"), 0u);
    EXPECT_EQ(out.counters.get("rays.transparency"), 0u);
  }
  {
    const RenderOutput out = renderScene(loadScene(scenePath("transparent-layers.gltf")), 32, 32);
    EXPECT_GT(out.counters.get("rays.shadow"), 0u);
    EXPECT_EQ(out.counters.get("rays.reflection"), 0u);
    EXPECT_EQ(out.counters.get("rays.refraction"), 0u);
    EXPECT_GT(out.counters.get("rays.transparency"), 0u);
  }
}

TEST(Counters, MaxDepthZeroTracesNoSecondaryRays) {
  const Scene scene = loadScene(scenePath("cornell-box.gltf"));
  RayOptions options;
  options.shading.maxDepth = 0;
  const RenderOutput zero = renderScene(scene, 32, 32, options);
  EXPECT_EQ(zero.counters.get("rays.reflection"), 0u);
  EXPECT_EQ(zero.counters.get("rays.refraction"), 0u);
  options.shading.maxDepth = 1;
  const RenderOutput one = renderScene(scene, 32, 32, options);
  options.shading.maxDepth = 8;
  const RenderOutput eight = renderScene(scene, 32, 32, options);
  EXPECT_GT(one.counters.get("rays.refraction"), 0u);
  EXPECT_LT(one.counters.get("rays.refraction"), eight.counters.get("rays.refraction"));
}

// --- transparent-layers against a brute-force reference ------------------------------

// Shadow transmittance by testing every triangle in double precision.
// The source surface's own instance is skipped: every instance in the
// scene is planar (checked), so it cannot shadow itself.
class NaiveVisibility : public LightVisibility {
 public:
  NaiveVisibility(const Scene& scene) : scene_(scene) {}
  void setShader(const Shader* shader) { shader_ = shader; }
  mutable bool ambiguous = false;

  glm::vec3 transmittance(const SurfacePoint& p, int, const glm::dvec3& toLight,
                          double distance) const override {
    Ray ray;
    ray.origin = p.position;
    ray.direction = toLight;
    glm::vec3 t(1.0f);
    for (const test::NaiveHit& h : test::intersectNaive(scene_, ray, 0.0, distance)) {
      if (h.instance == p.instance) continue;
      if (std::abs(h.margin) < 1e-5) ambiguous = true;
      if (h.t < 1e-9) ambiguous = true;  // the sheets cut each other: a contact line
      SampleHit sh;
      sh.instance = h.instance;
      sh.triangle = h.triangle;
      sh.b1 = float(h.b1);
      sh.b2 = float(h.b2);
      t *= shader_->shadowTransmittance(makeSurfacePoint(scene_, sh));
    }
    return t;
  }

 private:
  const Scene& scene_;
  const Shader* shader_ = nullptr;
};

TEST(TransparentLayers, FrontToBackCompositingMatchesBruteForceReference) {
  const Scene scene = loadScene(scenePath("transparent-layers.gltf"));
  for (uint32_t i = 0; i < scene.instances.size(); ++i) {
    const glm::dvec3 n0 = glm::normalize(faceNormal(scene, i, 0));
    for (uint32_t t = 1; t < scene.instances[i].triangleCount; ++t)
      ASSERT_NEAR(glm::dot(glm::normalize(faceNormal(scene, i, t)), n0), 1.0, 1e-9) << "instance " << i;
  }
  const SceneAnalysis analysis = analyzeScene(scene);
  const int w = 80, h = 60;
  const Camera camera = makeCamera(scene, {}, w, h);
  RayCaster caster(scene, analysis);
  RayOptions options;
  options.keepSamples = true;
  caster.bind(camera, options);
  const RenderOutput out = caster.render();

  NaiveVisibility visibility(scene);
  const Shader shader(scene, analysis, camera, options.shading, &visibility, nullptr);
  visibility.setShader(&shader);

  int compared = 0, multiLayer = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const glm::dvec2 position(x + 0.5, y + 0.5);
      const Ray ray = camera.primaryRay(position);
      const std::vector<test::NaiveHit> hits = test::intersectNaive(scene, ray, ray.tNear, ray.tFar);
      bool ambiguous = false;
      for (size_t i = 0; i < hits.size(); ++i) {
        if (std::abs(hits[i].margin) < 1e-5) ambiguous = true;
        if (i > 0 && hits[i].t - hits[i - 1].t < 1e-9) ambiguous = true;
      }
      // Hand compositing: premultiplied `over`, front to back, until the
      // first opaque surface.
      visibility.ambiguous = false;
      glm::vec4 reference(0.0f);
      int layers = 0;
      for (const test::NaiveHit& hit : hits) {
        SampleHit sh;
        sh.instance = hit.instance;
        sh.triangle = hit.triangle;
        sh.b1 = float(hit.b1);
        sh.b2 = float(hit.b2);
        sh.depth = float(hit.t * ray.depthPerT);
        const SurfacePoint p = makeSurfacePoint(scene, sh);
        const float remaining = 1.0f - reference.a;
        const glm::vec4 c =
            shader.shade(p, ray.direction, pixelFootprint(scene, camera, p, position), 0, remaining);
        reference += remaining * c;
        ++layers;
        if (scene.materialOf(hit.instance).alphaMode != AlphaMode::Blend) break;
      }
      if (ambiguous || visibility.ambiguous) continue;
      ++compared;
      if (layers >= 3) ++multiLayer;
      const glm::vec4 got = out.image.color[out.image.index(x, y)];
      for (int k = 0; k < 4; ++k)
        ASSERT_NEAR(got[k], reference[k], 1e-5) << "pixel " << x << "," << y << " channel " << k;
      if (!hits.empty()) {
        EXPECT_EQ(out.image.instance[out.image.index(x, y)], hits.front().instance);
        EXPECT_EQ(out.image.triangle[out.image.index(x, y)], hits.front().triangle);
      }
      // Deep: one entry per composited layer, front to back.
      const size_t begin = out.samples.offsets[out.image.index(x, y)];
      const size_t end = out.samples.offsets[out.image.index(x, y) + 1];
      EXPECT_EQ(end - begin, size_t(layers)) << "pixel " << x << "," << y;
    }
  EXPECT_GT(compared, w * h * 3 / 4);
  EXPECT_GT(multiLayer, 100);
}

// Compositing a pixel's deep layers with `over`, front to back per sample,
// then box-filtering the samples, reproduces the flat pixel.
TEST(DeepSamples, LayersCompositeToTheFlatPixel) {
  for (const char* name : {"transparent-layers.gltf", "cyclic-overlap.gltf", "cornell-box.gltf"}) {
    const Scene scene = loadScene(scenePath(name));
    RayOptions options;
    options.spp = 4;
    options.keepSamples = true;
    const RenderOutput out = renderScene(scene, 40, 30, options);
    ASSERT_TRUE(out.hasSamples);
    ASSERT_EQ(out.samples.offsets.size(), size_t(40 * 30 + 1));
    size_t layered = 0;
    for (size_t p = 0; p < size_t(40 * 30); ++p) {
      glm::vec4 perSample[4] = {};
      int lastSample = -1;
      float lastDepth = 0.0f;
      for (size_t i = out.samples.offsets[p]; i < out.samples.offsets[p + 1]; ++i) {
        const DeepSample& s = out.samples.samples[i];
        ASSERT_LT(s.sample, 4u);
        ASSERT_GE(int(s.sample), lastSample) << "deep samples out of order";
        if (int(s.sample) == lastSample) {
          EXPECT_GE(s.depth, lastDepth) << "layers not front to back";
          ++layered;
        }
        lastSample = int(s.sample);
        lastDepth = s.depth;
        glm::vec4& acc = perSample[s.sample];
        acc += (1.0f - acc.a) * s.color;
      }
      const glm::vec4 pixel = (perSample[0] + perSample[1] + perSample[2] + perSample[3]) / 4.0f;
      for (int k = 0; k < 4; ++k)
        ASSERT_NEAR(pixel[k], out.image.color[p][k], 1e-6) << name << " pixel " << p;
    }
    if (std::string(name) != "cornell-box.gltf") {
      EXPECT_GT(layered, 20u) << name;
    }
  }
}

// --- packets against single rays ------------------------------------------------------

// Every packet width, at 1 and 4 spp (packets then hold whole pixels'
// samples in Morton order), gives the scalar reference path's hits:
// colours, Z, IDs, every deep sample, and the counters. The one exception
// is Embree's: when a ray meets two triangles at exactly the same t (a ray
// through a shared edge or a corner where walls meet, which pixel centres
// at 1 spp on the symmetric Cornell box do), the first one its traversal
// finds is kept, and packet and single-ray traversal visit nodes in
// different orders. Such samples have the same Z and other IDs; the 4 spp
// sample positions meet no tie on these scenes, so there everything agrees.
TEST(Packets, AgreeWithSingleRays) {
  for (const char* name :
       {"cornell-box.gltf", "transparent-layers.gltf", "three-triangles.gltf", "textured-plane.gltf"}) {
    const Scene scene = loadScene(scenePath(name));
    for (int spp : {1, 4}) {
      RayOptions options;
      options.spp = spp;
      options.keepSamples = true;
      options.packets = false;
      const RenderOutput single = renderScene(scene, 48, 40, options);
      for (int width : {4, 8, 16}) {
        options.packets = true;
        options.forcePackets = true;
        options.packetWidth = width;
        const RenderOutput packets = renderScene(scene, 48, 40, options);
        const std::string what =
            std::string(name) + " spp " + std::to_string(spp) + " width " + std::to_string(width);
        size_t differ = 0, ties = 0;
        for (size_t i = 0; i < packets.image.color.size(); ++i) {
          const bool sameIds = packets.image.instance[i] == single.image.instance[i] &&
                               packets.image.triangle[i] == single.image.triangle[i];
          const bool sameDepth = packets.image.depth[i] == single.image.depth[i] ||
                                 (std::isinf(packets.image.depth[i]) && std::isinf(single.image.depth[i]));
          if (sameIds && sameDepth && packets.image.color[i] == single.image.color[i]) continue;
          const bool tie = !sameIds && sameDepth && std::isfinite(packets.image.depth[i]) &&
                           packets.image.instance[i] != kNoId && single.image.instance[i] != kNoId;
          ties += tie;
          differ += !tie;
        }
        EXPECT_EQ(differ, 0u) << what << ": pixels differ other than by an exact tie";
        if (spp == 4) {
          EXPECT_EQ(ties, 0u) << what;
        }
        EXPECT_EQ(packets.samples.offsets, single.samples.offsets) << what;
        ASSERT_EQ(packets.samples.samples.size(), single.samples.samples.size()) << what;
        size_t deepDiffer = 0;
        for (size_t i = 0; i < packets.samples.samples.size(); ++i) {
          const DeepSample &a = packets.samples.samples[i], &b = single.samples.samples[i];
          const bool same = a.color == b.color && a.depth == b.depth && a.instance == b.instance &&
                            a.triangle == b.triangle && a.sample == b.sample && a.cutOff == b.cutOff;
          const bool tie = a.depth == b.depth && a.sample == b.sample &&
                           (a.instance != b.instance || a.triangle != b.triangle);
          deepDiffer += !same && !(spp == 1 && tie);
        }
        EXPECT_EQ(deepDiffer, 0u) << what;
        for (const char* counter : kRayCounters)
          EXPECT_EQ(packets.counters.get(counter), single.counters.get(counter)) << what << " " << counter;
      }
    }
  }
}

// --- IDs map back to the triangle store ------------------------------------------------

// Every hit's (instance, triangle) is a stored triangle the primary ray
// really crosses at the reported depth: strips, fans and multi-primitive
// meshes included.
TEST(Ids, EveryHitIsTheStoredTriangleTheRayCrosses) {
  for (const std::string& path :
       {std::string(RASTRAY_TEST_DATA) + "/real-world/MeshPrimitiveModes.gltf",
        std::string(RASTRAY_TEST_DATA) + "/real-world/SimpleMeshes.gltf", scenePath("cornell-box.gltf")}) {
    const Scene scene = loadScene(path);
    const Camera camera = makeCamera(scene, {}, 64, 64);
    RayCaster caster(scene, analyzeScene(scene));
    caster.bind(camera, RayOptions{});
    const RenderOutput out = caster.render();
    int hits = 0;
    for (int y = 0; y < 64; ++y)
      for (int x = 0; x < 64; ++x) {
        const size_t i = out.image.index(x, y);
        if (out.image.instance[i] == kNoId) continue;
        ++hits;
        ASSERT_LT(out.image.instance[i], scene.instances.size()) << path;
        ASSERT_LT(out.image.triangle[i], scene.instances[out.image.instance[i]].triangleCount) << path;
        const Ray ray = camera.primaryRay({x + 0.5, y + 0.5});
        double t;
        glm::dvec2 b;
        ASSERT_TRUE(intersectTrianglePlane(scene, out.image.instance[i], out.image.triangle[i], ray, &t, &b));
        EXPECT_GE(std::min({b.x, b.y, 1.0 - b.x - b.y}), -1e-5) << path << " pixel " << x << "," << y;
        EXPECT_NEAR(out.image.depth[i], t * ray.depthPerT, 1e-5 * t) << path;
      }
    EXPECT_GT(hits, 100) << path;
  }
}

// A zero-area triangle keeps its ID but covers nothing (SPEC §1), even for
// rays exactly along the segment it collapses to.
TEST(Degenerate, ZeroAreaTrianglesCoverNothing) {
  test::SceneBuilder b;
  const uint32_t white = b.addMaterial(test::SceneBuilder::lambert(glm::vec4(1.0f)));
  // Collinear along y = 0 at z = −0.5; every camera ray of the middle row
  // (odd height: NDC y = 0) runs through it. Triangle 1 is a real one.
  b.addMesh({{-0.9f, 0.0f, -0.5f}, {0.9f, 0.0f, -0.5f}, {0.1f, 0.0f, -0.5f}, {-0.5f, 0.5f, -0.5f}},
            {{0, 1, 2}, {0, 2, 3}}, white);
  b.setCamera(Projection::Orthographic, {0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 1.0, 0.0, 2.0);
  const Scene& scene = b.scene();
  ASSERT_EQ(scene.instances[0].degenerateCount, 1u);
  const RenderOutput out = renderScene(scene, 33, 33);
  int covered = 0;
  for (size_t i = 0; i < out.image.triangle.size(); ++i) {
    EXPECT_NE(out.image.triangle[i], 0u) << "pixel " << i;
    if (out.image.triangle[i] == 1u) ++covered;
  }
  EXPECT_GT(covered, 20);
}

// --- no NaN or Inf ------------------------------------------------------------------------

void expectFinite(const RenderOutput& out, const std::string& what) {
  for (size_t i = 0; i < out.image.color.size(); ++i) {
    for (int k = 0; k < 4; ++k) ASSERT_TRUE(std::isfinite(out.image.color[i][k])) << what << " pixel " << i;
    ASSERT_FALSE(std::isnan(out.image.depth[i])) << what;
    ASSERT_TRUE(std::isfinite(out.image.depth[i]) || out.image.depth[i] > 0.0f) << what;
  }
  for (const DeepSample& s : out.samples.samples) {
    for (int k = 0; k < 4; ++k) ASSERT_TRUE(std::isfinite(s.color[k])) << what;
    ASSERT_TRUE(std::isfinite(s.depth)) << what;
  }
}

TEST(Grazing, NoNanOrInfOnGrazingRays) {
  // The camera's eye lies in the plane of a lit quad, so the middle rows
  // graze it; the light grazes it too.
  for (double lightAngle : {89.9, 90.0}) {
    test::SceneBuilder b;
    const uint32_t white = b.addMaterial(test::SceneBuilder::lambert(glm::vec4(0.8f)));
    Material mirror = test::SceneBuilder::lambert(glm::vec4(0.9f));
    mirror.metallic = 1.0f;
    mirror.roughness = 0.0f;
    const uint32_t mirrorId = b.addMaterial(mirror);
    const uint32_t glass = b.addMaterial(test::SceneBuilder::glass(1.5f));
    b.addQuad({0, 0, 0}, {0, 0, 5}, {5, 0, 0}, white);  // y = 0, front +y
    b.addQuad({0, 0.5, -3}, {0, 0, 1}, {1, 0, 0}, mirrorId);
    b.addBox({0.5f, 0.0f, -2.0f}, {1.0f, 0.5f, -1.5f}, glass);
    const double a = lightAngle * kPi / 180.0;
    b.addDirectionalLight({std::sin(a), -std::cos(a), 0.0}, 3.0f);
    b.setCamera(Projection::Perspective, {0, 0, 4}, {0, 0, 0}, {0, 1, 0}, 0.8, 0.01, 100.0);
    RayOptions options;
    options.spp = 4;
    options.keepSamples = true;
    expectFinite(renderScene(b.scene(), 33, 33, options), "grazing quad");
  }
  for (const char* name : {"textured-plane.gltf", "cornell-box.gltf", "transparent-layers.gltf"}) {
    RayOptions options;
    options.spp = 4;
    options.keepSamples = true;
    expectFinite(renderScene(loadScene(scenePath(name)), 40, 30, options), name);
  }
}

// --- hybrid interfaces ------------------------------------------------------------------------

// radiance() and transmittance() are called from the rasterizer's threads:
// the same answers in parallel as serially, and every call counted.
TEST(Hybrid, SecondaryRayInterfacesAreThreadSafeAndCounted) {
  const Scene scene = loadScene(scenePath("cornell-box.gltf"));
  const Camera camera = makeCamera(scene, {}, 32, 32);
  RayCaster caster(scene, analyzeScene(scene));
  caster.bind(camera, RayOptions{});
  // Surface points: what the primary rays of a 32×32 image hit.
  const RenderOutput out = caster.render();
  std::vector<SurfacePoint> points;
  std::vector<glm::dvec3> directions;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) {
      const size_t i = out.image.index(x, y);
      if (out.image.instance[i] == kNoId) continue;
      const Ray ray = camera.primaryRay({x + 0.5, y + 0.5});
      SampleHit h;
      h.instance = out.image.instance[i];
      h.triangle = out.image.triangle[i];
      const SurfacePoint p = makeSurfacePoint(scene, refineHit(scene, ray, h));
      points.push_back(p);
      directions.push_back(reflect(ray.direction, p.geometricNormal));
    }
  ASSERT_GT(points.size(), 500u);
  const CounterSet before = caster.counters();
  const glm::dvec3 light = scene.lights.at(0).position;
  std::vector<glm::vec3> serialRadiance(points.size()), serialShadow(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    serialRadiance[i] = caster.radiance(points[i], directions[i], RayKind::Reflection, 1, 1.0f);
    serialShadow[i] = caster.transmittance(points[i], 0, glm::normalize(light - points[i].position),
                                           glm::length(light - points[i].position));
  }
  std::vector<glm::vec3> parallelRadiance(points.size()), parallelShadow(points.size());
  parallelFor(size_t(0), points.size(), [&](size_t i) {
    parallelRadiance[i] = caster.radiance(points[i], directions[i], RayKind::Reflection, 1, 1.0f);
    parallelShadow[i] = caster.transmittance(points[i], 0, glm::normalize(light - points[i].position),
                                             glm::length(light - points[i].position));
  });
  for (size_t i = 0; i < points.size(); ++i) {
    EXPECT_EQ(serialRadiance[i], parallelRadiance[i]) << i;
    EXPECT_EQ(serialShadow[i], parallelShadow[i]) << i;
  }
  const CounterSet after = caster.counters();
  EXPECT_GE(after.get("rays.reflection") - before.get("rays.reflection"), 2 * points.size());
  EXPECT_EQ(after.get("rays.shadow") - before.get("rays.shadow") >= 2 * points.size(), true);
}

// --- debug pixel ------------------------------------------------------------------------------------

TEST(DebugPixel, RayTreeOfAGlassPixel) {
  const Scene scene = loadScene(scenePath("cornell-box.gltf"));
  const Camera camera = makeCamera(scene, {}, 64, 64);
  RayCaster caster(scene, analyzeScene(scene));
  RayOptions options;
  caster.bind(camera, options);
  const RenderOutput out = caster.render();
  // A pixel on the glass sphere.
  uint32_t glass = kNoId;
  for (uint32_t i = 0; i < scene.instances.size(); ++i)
    if (scene.materialOf(i).isRefractive()) glass = i;
  ASSERT_NE(glass, kNoId);
  glm::ivec2 pixel(-1);
  for (int y = 0; y < 64 && pixel.x < 0; ++y)
    for (int x = 0; x < 64; ++x)
      if (out.image.instance[out.image.index(x, y)] == glass) {
        pixel = {x, y};
        break;
      }
  ASSERT_GE(pixel.x, 0);
  const std::vector<RayRecord> tree = caster.traceDebugPixel(pixel);
  ASSERT_FALSE(tree.empty());
  EXPECT_EQ(tree.front().kind, RayKind::Primary);
  EXPECT_EQ(tree.front().instance, glass);
  bool refraction = false, reflection = false;
  for (const RayRecord& r : tree) {
    refraction |= r.kind == RayKind::Refraction;
    reflection |= r.kind == RayKind::Reflection;
  }
  EXPECT_TRUE(refraction);
  EXPECT_TRUE(reflection);
  // The primary contribution is the rendered pixel (1 spp).
  const glm::vec4 c = out.image.color[out.image.index(pixel.x, pixel.y)];
  for (int k = 0; k < 4; ++k) EXPECT_EQ(tree.front().contribution[k], c[k]);
  // The trace does not count rays.
  EXPECT_EQ(caster.counters().get("rays.primary"), 64u * 64u);

  // render() with a trace request records the same tree into the sink, one
  // Ray event per ray with its fields, and counts as before.
  TraceLog log;
  options.trace = {&log, pixel};
  caster.bind(camera, options);
  const RenderOutput traced = caster.render();
  EXPECT_EQ(traced.counters.get("rays.primary"), 64u * 64u);
  const std::vector<TraceEvent> events = log.events();
  ASSERT_EQ(events.size(), tree.size());
  for (size_t i = 0; i < tree.size(); ++i) {
    const RayRecord& r = tree[i];
    const TraceEvent& e = events[i];
    EXPECT_EQ(e.stage, TraceStage::Ray);
    EXPECT_EQ(e.sample, r.sample);
    EXPECT_EQ(e.instance, r.instance);
    EXPECT_EQ(e.triangle, r.triangle);
    EXPECT_EQ(e.depth, r.kind == RayKind::Shadow ? r.depth + 1 : r.depth);
    ASSERT_FALSE(e.values.empty());
    EXPECT_EQ(e.values.front(), std::make_pair(std::string("kind"), std::string(toString(r.kind))));
    if (r.kind != RayKind::Shadow) {
      EXPECT_EQ(e.outcome, r.instance == kNoId ? "miss" : "hit");
    }
  }
  EXPECT_EQ(events.front().outcome, "hit");
  // A pixel outside the image is refused, not ignored.
  options.trace = {&log, {64, 0}};
  caster.bind(camera, options);
  EXPECT_THROW(caster.render(), InputError);
}

// Each ray's record follows the ray whose surface spawned it: a shadow
// ray's depth is the lit surface's, so it comes after a ray of that depth
// and belongs to the same sample; every secondary ray follows a ray one
// depth up.
TEST(DebugPixel, RayTreeIsInTreeOrder) {
  const Scene scene = loadScene(scenePath("cornell-box.gltf"));
  const Camera camera = makeCamera(scene, {}, 32, 32);
  RayCaster caster(scene, analyzeScene(scene));
  RayOptions options;
  options.spp = 4;
  caster.bind(camera, options);
  int shadows = 0, secondaries = 0;
  for (int y = 0; y < 32; y += 5)
    for (int x = 0; x < 32; x += 5) {
      const std::vector<RayRecord> tree = caster.traceDebugPixel({x, y});
      std::vector<int> open;  // depths of the non-shadow rays so far, per sample: a stack
      int sample = -1;
      for (const RayRecord& r : tree) {
        if (r.kind == RayKind::Primary) {
          EXPECT_EQ(r.sample, sample + 1);
          sample = r.sample;
          open = {0};
          continue;
        }
        ASSERT_EQ(r.sample, sample);
        ASSERT_FALSE(open.empty());
        if (r.kind == RayKind::Shadow) {
          ++shadows;
          EXPECT_LE(r.depth, open.back());
          continue;
        }
        ++secondaries;
        while (!open.empty() && open.back() >= r.depth) open.pop_back();
        ASSERT_FALSE(open.empty());
        EXPECT_EQ(open.back(), r.depth - 1);
        open.push_back(r.depth);
      }
      EXPECT_EQ(sample, 3);
    }
  EXPECT_GT(shadows, 0);
  EXPECT_GT(secondaries, 0);
}

}  // namespace
}  // namespace rastray

namespace rastray {
namespace {

// Rays exactly through the diagonal shared by the two triangles of a BLEND
// sheet: the sheet is composited once, and the shadow ray (light straight
// down, through the same diagonal) attenuates once, so diagonal pixels
// look like their neighbours.
TEST(SharedEdges, ARayThroughASharedEdgeCrossesTheSurfaceOnce) {
  test::SceneBuilder b;
  Material sheet = test::SceneBuilder::lambert(glm::vec4(0.2f, 0.4f, 0.9f, 0.5f));
  sheet.alphaMode = AlphaMode::Blend;
  sheet.doubleSided = true;
  const uint32_t sheetId = b.addMaterial(sheet);
  const uint32_t floorId = b.addMaterial(test::SceneBuilder::lambert(glm::vec4(0.8f, 0.8f, 0.8f, 1.0f)));
  // Triangles (0, 1, 2) and (0, 2, 3): the diagonal is y = x.
  b.addMesh({{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}, {{0, 1, 2}, {0, 2, 3}}, sheetId);
  b.addQuad({0, 0, -1}, {2, 0, 0}, {0, 2, 0}, floorId);
  b.addDirectionalLight({0, 0, -1}, 2.0f);
  b.setCamera(Projection::Orthographic, {0, 0, 1}, {0, 0, 0}, {0, 1, 0}, 1.5, 0.5, 3.0);
  const int size = 24;
  const RenderOutput out = renderScene(b.scene(), size, size);
  // Pixel centres with i + j = size − 1 lie exactly on y = x (NDC values
  // are exact binary fractions here).
  int checked = 0;
  for (int i = 1; i + 1 < size; ++i) {
    const int j = size - 1 - i;
    const double x = 1.5 * (2.0 * (i + 0.5) / size - 1.0), xBeside = 1.5 * (2.0 * (i + 1.5) / size - 1.0);
    if (std::abs(x) >= 1.0 || std::abs(xBeside) >= 1.0) continue;  // outside the sheet
    const glm::vec4 diagonal = out.image.color[out.image.index(i, j)];
    const glm::vec4 beside = out.image.color[out.image.index(i + 1, j)];
    ASSERT_EQ(out.image.instance[out.image.index(i, j)], 0u);
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(diagonal[k], beside[k], 1e-6) << "pixel " << i << "," << j;
    if (std::getenv("RT_DEBUG") && diagonal != beside) {
      RayCaster caster(b.scene(), analyzeScene(b.scene()));
      caster.bind(makeCamera(b.scene(), {}, size, size), RayOptions{});
      for (const glm::ivec2 p : {glm::ivec2(i, j), glm::ivec2(i + 1, j)}) {
        std::vector<TraceEvent> events;
        for (const RayRecord& r : caster.traceDebugPixel(p)) events.push_back(rayTraceEvent(r));
        std::fprintf(stderr, "pixel (%d, %d)\n%s", p.x, p.y, traceText(events).c_str());
      }
    }
    ++checked;
  }
  EXPECT_GT(checked, 10);
}

}  // namespace
}  // namespace rastray

namespace rastray {
namespace {

// geomID == instance index even when an instance has no triangles (it gets
// no Embree geometry, and the IDs after it do not shift).
TEST(Ids, EmptyInstancesDoNotShiftIds) {
  test::SceneBuilder b;
  const uint32_t white = b.addMaterial(test::SceneBuilder::lambert(glm::vec4(1.0f)));
  b.addMesh({}, {}, white);
  b.addQuad({0.5, 0, -1}, {0.5, 0, 0}, {0, 1, 0}, white);
  b.addMesh({}, {}, white);
  b.addQuad({-0.5, 0, -1}, {0.5, 0, 0}, {0, 1, 0}, white);
  b.setCamera(Projection::Orthographic, {0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 1.0, 0.0, 2.0);
  const RenderOutput out = renderScene(b.scene(), 8, 8);
  EXPECT_EQ(out.image.instance[out.image.index(6, 4)], 1u);
  EXPECT_EQ(out.image.instance[out.image.index(1, 4)], 3u);
}

// MASK (SPEC §5): alpha below the cutoff is no surface at all (for primary
// and shadow rays), at or above it an opaque one.
TEST(Mask, AlphaBelowTheCutoffIsIgnoredAboveItCovers) {
  for (float alpha : {0.3f, 0.7f}) {
    test::SceneBuilder b;
    Material leaf = test::SceneBuilder::lambert(glm::vec4(1.0f, 0.0f, 0.0f, alpha));
    leaf.alphaMode = AlphaMode::Mask;
    leaf.alphaCutoff = 0.5f;
    const uint32_t leafId = b.addMaterial(leaf);
    const uint32_t floorId = b.addMaterial(test::SceneBuilder::lambert(glm::vec4(0.0f, 1.0f, 0.0f, 1.0f)));
    b.addQuad({0, 0, 0}, {0.5, 0, 0}, {0, 0.5, 0}, leafId);
    b.addQuad({0, 0, -1}, {2, 0, 0}, {0, 2, 0}, floorId);
    b.addDirectionalLight({0.5, 0, -1}, 2.0f);  // the leaf's shadow falls at x ∈ [0, 1]
    b.setCamera(Projection::Orthographic, {0, 0, 1}, {0, 0, 0}, {0, 1, 0}, 1.5, 0.5, 3.0);
    const int size = 24;
    const RenderOutput out = renderScene(b.scene(), size, size);
    const size_t centre = out.image.index(size / 2 - 1, size / 2 - 1);  // world (−0.06, 0.06): on the leaf
    const size_t shadow = out.image.index(size * 3 / 4, size / 2);      // world (0.8, −0.06): leaf's shadow
    if (alpha < 0.5f) {
      EXPECT_EQ(out.image.instance[centre], 1u);
      EXPECT_GT(out.image.color[shadow].g, 0.1f);
    } else {
      EXPECT_EQ(out.image.instance[centre], 0u);
      EXPECT_GT(out.image.color[centre].r, 0.1f);
      EXPECT_EQ(out.image.color[shadow].g, 0.0f);
    }
  }
}

}  // namespace
}  // namespace rastray
