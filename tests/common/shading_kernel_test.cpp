// The shading kernel (common/shading_kernel.h) against its double
// reference (Shader::shade): the stated error bound on the bundled and
// stiff scenes, lane independence (a hit's bits do not depend on its batch),
// the same bits on every compiled SIMD target, and the lanes that must take
// the scalar path (tracing materials, BLEND) giving the reference's bits.
#include "common/shading_kernel.h"

#include <gtest/gtest.h>

#include <hwy/targets.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "common/analysis.h"
#include "common/gltf/loader.h"
#include "common/shading.h"
#include "common/surface.h"

namespace rastray {
namespace {

// The nearest hit along `ray`, by brute force over every triangle (double,
// inside test with no tolerance): the test's own renderer.
bool nearestHit(const Scene& scene, const Ray& ray, SampleHit* out) {
  double best = std::numeric_limits<double>::infinity();
  bool found = false;
  for (uint32_t i = 0; i < scene.instances.size(); ++i)
    for (uint32_t t = 0; t < scene.instances[i].triangleCount; ++t) {
      double th;
      glm::dvec2 b;
      if (!intersectTrianglePlane(scene, i, t, ray, &th, &b)) continue;
      if (!(th > 0.0) || th >= best || b.x < 0.0 || b.y < 0.0 || b.x + b.y > 1.0) continue;
      best = th;
      *out = SampleHit{i, t, float(th * ray.depthPerT), float(b.x), float(b.y)};
      found = true;
    }
  return found;
}

// Up to `wanted` primary hits on a grid over the image (fewer on large
// scenes: the brute force stays under ~2·10⁷ triangle tests).
std::vector<ShadeHit> primaryHits(const Scene& scene, const Camera& camera, int wanted) {
  const double triangles = double(std::max<size_t>(1, scene.triangleCount()));
  const int rays = int(std::clamp(2e7 / triangles, 64.0, double(wanted)));
  const int side = std::max(2, int(std::sqrt(double(rays))));
  std::vector<ShadeHit> hits;
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) {
      const glm::dvec2 image((x + 0.37) * camera.width / side, (y + 0.61) * camera.height / side);
      const Ray ray = camera.primaryRay(image);
      SampleHit hit;
      if (nearestHit(scene, ray, &hit)) hits.push_back(refinePrimaryHit(scene, ray, hit, image));
    }
  return hits;
}

// Stands in for shadow rays: a fixed coloured transmittance, so the
// kernel's visibility callback path is exercised.
class TintedVisibility : public LightVisibility {
 public:
  glm::vec3 transmittance(const SurfacePoint&, int lightIndex, const glm::dvec3&, double) const override {
    return lightIndex % 2 == 0 ? glm::vec3(0.5f, 0.25f, 1.0f) : glm::vec3(1.0f, 0.0f, 0.75f);
  }
};

// Mirrors and glass see a constant colour.
class ConstantTracer : public SecondaryRayTracer {
 public:
  glm::vec3 radiance(const SurfacePoint&, const glm::dvec3&, RayKind, int, float) const override {
    return {0.25f, 0.5f, 0.75f};
  }
};

bool sameBits(const glm::vec4& a, const glm::vec4& b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// The bound stated in common/shading_kernel.h: per channel of the
// premultiplied colour, relative to max(1, |reference|).
constexpr float kRelativeBound = 1e-6f;

struct Comparison {
  size_t hits = 0, beyond = 0;
  float worst = 0.0f;  // largest error within the bound's scale, over the lanes inside it
};

Comparison compareToReference(const Shader& shader, const std::vector<ShadeHit>& hits) {
  std::vector<glm::vec4> kernel(hits.size()), reference(hits.size());
  shadePrimaryHits(shader, hits.data(), hits.size(), kernel.data(), ShadingPath::Kernel);
  shadePrimaryHits(shader, hits.data(), hits.size(), reference.data(), ShadingPath::Reference);
  Comparison c;
  c.hits = hits.size();
  for (size_t i = 0; i < hits.size(); ++i) {
    float error = 0.0f;
    for (int ch = 0; ch < 4; ++ch) {
      const float r = reference[i][ch], k = kernel[i][ch];
      error = std::max(error, std::abs(k - r) / std::max(1.0f, std::abs(r)));
      if (std::isnan(k) != std::isnan(r)) error = std::numeric_limits<float>::infinity();
    }
    if (error > kRelativeBound)
      ++c.beyond;
    else
      c.worst = std::max(c.worst, error);
  }
  return c;
}

std::vector<std::string> boundScenes() {
  return {"cornell-box.gltf",
          "textured-plane.gltf",
          "three-triangles.gltf",
          "vertex-colors.gltf",
          "interpenetrating.gltf",
          "cyclic-overlap.gltf",
          "stiff/far-node-1e6.gltf",
          "stiff/far-node-1e7.gltf",
          "stiff/far-baked-1e6.gltf",
          "stiff/grazing-lit-89.9.gltf",
          "stiff/grazing-textured-89.9.gltf",
          "stiff/scale-1e-4.gltf",
          "stiff/scale-1e4.gltf",
          "stiff/sliver-fan-aspect-1e6.gltf",
          "stiff/degenerate.gltf"};
}

// The stated bound, with and without a visibility callback: every lane
// within it but for decision flips at a threshold (n·l, n·d within a float
// rounding of 0), at most 1 in 1000 lanes.
TEST(ShadingKernel, FloatLanesStayWithinTheStatedBoundOfTheDoubleReference) {
  const TintedVisibility tinted;
  for (const std::string& name : boundScenes()) {
    SCOPED_TRACE(name);
    const Scene scene = loadScene(std::string(RASTRAY_SCENES) + "/" + name);
    const SceneAnalysis analysis = analyzeScene(scene);
    const Camera camera = makeCamera(scene, {}, 160, 120);
    const std::vector<ShadeHit> hits = primaryHits(scene, camera, 4096);
    ASSERT_GT(hits.size(), 0u);
    for (const LightVisibility* visibility :
         {static_cast<const LightVisibility*>(nullptr), static_cast<const LightVisibility*>(&tinted)}) {
      const Shader shader(scene, analysis, camera, {}, visibility, nullptr);
      const Comparison c = compareToReference(shader, hits);
      std::printf("%-36s %-10s %5zu hits, worst %.2e, beyond the bound %zu\n", name.c_str(),
                  visibility ? "tinted" : "unshadowed", c.hits, double(c.worst), c.beyond);
      EXPECT_LE(c.beyond * 1000, c.hits) << c.beyond << " of " << c.hits << " lanes beyond the bound";
      EXPECT_LE(c.worst, kRelativeBound);
    }
  }
}

// The kernel is not the reference: on a lit scene some lane differs, so
// the comparisons above and the switch below compare two paths.
TEST(ShadingKernel, ReferenceShadingOptionSwitchesEveryHitToTheReference) {
  const Scene scene = loadScene(std::string(RASTRAY_SCENES) + "/cornell-box.gltf");
  const SceneAnalysis analysis = analyzeScene(scene);
  const Camera camera = makeCamera(scene, {}, 64, 48);
  const std::vector<ShadeHit> hits = primaryHits(scene, camera, 1024);
  ShadingOptions options;
  const Shader kernelShader(scene, analysis, camera, options, nullptr, nullptr);
  options.referenceShading = true;
  const Shader referenceShader(scene, analysis, camera, options, nullptr, nullptr);
  std::vector<glm::vec4> kernel(hits.size()), forced(hits.size()), reference(hits.size());
  shadePrimaryHits(kernelShader, hits.data(), hits.size(), kernel.data(), ShadingPath::Kernel);
  shadePrimaryHits(referenceShader, hits.data(), hits.size(), forced.data(), ShadingPath::Kernel);
  shadePrimaryHits(kernelShader, hits.data(), hits.size(), reference.data(), ShadingPath::Reference);
  size_t differ = 0;
  for (size_t i = 0; i < hits.size(); ++i) {
    EXPECT_TRUE(sameBits(forced[i], reference[i])) << i;
    differ += sameBits(kernel[i], reference[i]) ? 0 : 1;
  }
  EXPECT_GT(differ, 0u);
}

// The reference path is Shader::shade on surfacePointOnRay's point, bit
// for bit: what the renderers did before the kernel.
TEST(ShadingKernel, ReferencePathIsShaderShadeOnTheRefinedPoint) {
  const Scene scene = loadScene(std::string(RASTRAY_SCENES) + "/textured-plane.gltf");
  const SceneAnalysis analysis = analyzeScene(scene);
  const Camera camera = makeCamera(scene, {}, 64, 48);
  const Shader shader(scene, analysis, camera, {}, nullptr, nullptr);
  for (int y = 0; y < 48; y += 5)
    for (int x = 0; x < 64; x += 5) {
      const glm::dvec2 image(x + 0.5, y + 0.5);
      const Ray ray = camera.primaryRay(image);
      SampleHit hit;
      if (!nearestHit(scene, ray, &hit)) continue;
      const SurfacePoint p = surfacePointOnRay(scene, ray, hit);
      const glm::vec4 expected = shader.shade(p, ray.direction, pixelFootprint(scene, camera, p, image));
      const ShadeHit h = refinePrimaryHit(scene, ray, hit, image);
      EXPECT_EQ(h.b1, p.b1);
      EXPECT_EQ(h.b2, p.b2);
      glm::vec4 c;
      shadePrimaryHits(shader, &h, 1, &c, ShadingPath::Reference);
      EXPECT_TRUE(sameBits(c, expected)) << x << ", " << y;
    }
}

// Lane independence: each hit shaded alone, in batches of several sizes
// and in a shuffled order gives the same bits.
TEST(ShadingKernel, AHitsColourDoesNotDependOnItsBatch) {
  const TintedVisibility tinted;
  for (const char* name : {"cornell-box.gltf", "textured-plane.gltf", "stiff/far-node-1e6.gltf"}) {
    SCOPED_TRACE(name);
    const Scene scene = loadScene(std::string(RASTRAY_SCENES) + "/" + name);
    const Camera camera = makeCamera(scene, {}, 64, 48);
    const Shader shader(scene, analyzeScene(scene), camera, {}, &tinted, nullptr);
    std::vector<ShadeHit> hits = primaryHits(scene, camera, 1024);
    ASSERT_GT(hits.size(), 100u);
    std::vector<glm::vec4> alone(hits.size());
    for (size_t i = 0; i < hits.size(); ++i)
      shadePrimaryHits(shader, &hits[i], 1, &alone[i], ShadingPath::Kernel);
    for (size_t batch : {size_t(3), size_t(17), size_t(64), size_t(100), hits.size()}) {
      std::vector<glm::vec4> batched(hits.size());
      for (size_t first = 0; first < hits.size(); first += batch)
        shadePrimaryHits(shader, &hits[first], std::min(batch, hits.size() - first), &batched[first],
                         ShadingPath::Kernel);
      for (size_t i = 0; i < hits.size(); ++i)
        EXPECT_TRUE(sameBits(batched[i], alone[i])) << batch << " " << i;
    }
    std::vector<size_t> order(hits.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::shuffle(order.begin(), order.end(), std::mt19937(7));
    std::vector<ShadeHit> shuffled;
    for (size_t i : order) shuffled.push_back(hits[i]);
    std::vector<glm::vec4> colors(hits.size());
    shadePrimaryHits(shader, shuffled.data(), shuffled.size(), colors.data(), ShadingPath::Kernel);
    for (size_t k = 0; k < order.size(); ++k) EXPECT_TRUE(sameBits(colors[k], alone[order[k]])) << k;
  }
}

// Every SIMD target compiled in and supported here gives the same bits
// (only IEEE-exact operations, no contraction): the colour does not depend
// on the machine's vector width.
TEST(ShadingKernel, EverySimdTargetGivesTheSameBits) {
  const TintedVisibility tinted;
  const Scene scene = loadScene(std::string(RASTRAY_SCENES) + "/cornell-box.gltf");
  const Camera camera = makeCamera(scene, {}, 64, 48);
  const std::vector<ShadeHit> hits = primaryHits(scene, camera, 1024);
  const std::vector<int64_t> targets = hwy::SupportedAndGeneratedTargets();
  ASSERT_GE(targets.size(), 1u);
  std::vector<std::vector<glm::vec4>> colors;
  for (const bool lit : {false, true}) {
    const Shader shader(scene, analyzeScene(scene), camera, {}, lit ? &tinted : nullptr, nullptr);
    std::vector<glm::vec4> first;
    for (int64_t target : targets) {
      SCOPED_TRACE(hwy::TargetName(target));
      hwy::SetSupportedTargetsForTest(target);
      std::vector<glm::vec4> c(hits.size());
      shadePrimaryHits(shader, hits.data(), hits.size(), c.data(), ShadingPath::Kernel);
      if (first.empty()) first = c;
      for (size_t i = 0; i < hits.size(); ++i) EXPECT_TRUE(sameBits(c[i], first[i])) << i;
    }
    hwy::SetSupportedTargetsForTest(0);
  }
  std::printf("shading kernel targets tested: %zu, running: %s\n", targets.size(), shadingKernelTarget());
}

// One triangle in the z = 0 plane facing +Z, with a material.
Scene triangleScene(const Material& m) {
  Scene s;
  s.positions = {{-1, -1, 0}, {1, -1, 0}, {0, 1, 0}};
  s.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
  s.texcoords = {{0, 0}, {1, 0}, {0, 1}};
  s.triangles = {{0, 1, 2}};
  Instance inst;
  inst.vertexCount = 3;
  inst.triangleCount = 1;
  s.instances.push_back(inst);
  s.materials.push_back(m);
  s.bounds.extend({-1, -1, 0});
  s.bounds.extend({1, 1, 0});
  Light l;
  l.position = {0.3, 0.2, 2};
  l.intensity = 4.0f;
  s.lights.push_back(l);
  return s;
}

// Lanes whose material traces secondary rays (with a tracer) or is BLEND
// take Shader::shade whole: the reference's bits. Without a tracer a
// mirror is shaded in the lanes (its mirror part black, as the reference).
TEST(ShadingKernel, TracingAndBlendMaterialsTakeTheScalarPath) {
  Material mirror;
  mirror.metallic = 1.0f;
  mirror.roughness = 0.25f;
  Material glass;
  glass.metallic = 0.0f;
  glass.transmission = 0.8f;
  Material blend;
  blend.metallic = 0.0f;
  blend.alphaMode = AlphaMode::Blend;
  blend.baseColorFactor = {1.0f, 0.5f, 0.25f, 0.4f};
  const ConstantTracer tracer;
  for (const Material& m : {mirror, glass, blend}) {
    const Scene scene = triangleScene(m);
    const Camera camera = makeCamera(scene, {}, 16, 16);
    const Shader shader(scene, analyzeScene(scene), camera, {}, nullptr, &tracer);
    std::vector<ShadeHit> hits;
    for (int k = 0; k < 20; ++k) {
      ShadeHit h;
      h.instance = h.triangle = 0;
      h.b1 = 0.05f * float(k % 10);
      h.b2 = 0.04f * float(k / 2);
      h.direction = glm::normalize(glm::dvec3(0.01 * k, -0.02 * k, -1.0));
      hits.push_back(h);
    }
    std::vector<glm::vec4> kernel(hits.size()), reference(hits.size());
    shadePrimaryHits(shader, hits.data(), hits.size(), kernel.data(), ShadingPath::Kernel);
    shadePrimaryHits(shader, hits.data(), hits.size(), reference.data(), ShadingPath::Reference);
    for (size_t i = 0; i < hits.size(); ++i) EXPECT_TRUE(sameBits(kernel[i], reference[i])) << i;
  }
  // No tracer: the mirror goes through the lanes, within the bound.
  const Scene scene = triangleScene(mirror);
  const Camera camera = makeCamera(scene, {}, 16, 16);
  const Shader shader(scene, analyzeScene(scene), camera, {}, nullptr, nullptr);
  ShadeHit h;
  h.instance = h.triangle = 0;
  h.b1 = h.b2 = 0.3f;
  glm::vec4 kernel, reference;
  shadePrimaryHits(shader, &h, 1, &kernel, ShadingPath::Kernel);
  shadePrimaryHits(shader, &h, 1, &reference, ShadingPath::Reference);
  EXPECT_GT(reference.r, 0.0f);
  EXPECT_NEAR(kernel.r, reference.r, kRelativeBound * std::max(1.0f, reference.r));
}

// PrimaryHitShader (hits as struct of arrays, in runs on one triangle, the
// rasterizer's entry) gives shadePrimaryHits' bits on the same hits, on
// every target: blocks of 1 to 64 hits, colours scattered, lanes that read
// their run's base colour and emission, lanes that need their own (vertex
// colours, a visibility callback) mixed with them in one block, the eye
// light, and BLEND lanes on the scalar path.
// Hits as the struct of arrays a PrimaryHitBlock reads (the fused pass's
// output): directions, footprint positions and barycentrics.
struct HitColumns {
  std::vector<double> dx, dy, dz, fx, fy;
  std::vector<float> b1, b2;
  explicit HitColumns(const std::vector<ShadeHit>& hits)
      : dx(hits.size()),
        dy(hits.size()),
        dz(hits.size()),
        fx(hits.size()),
        fy(hits.size()),
        b1(hits.size()),
        b2(hits.size()) {
    for (size_t i = 0; i < hits.size(); ++i) {
      dx[i] = hits[i].direction.x, dy[i] = hits[i].direction.y, dz[i] = hits[i].direction.z;
      fx[i] = hits[i].footprintPosition.x, fy[i] = hits[i].footprintPosition.y;
      b1[i] = hits[i].b1, b2[i] = hits[i].b2;
    }
  }
  // Points `block`'s per-lane inputs at the hits from `first` on.
  void into(PrimaryHitBlock& block, size_t first) {
    block.dirX = &dx[first], block.dirY = &dy[first], block.dirZ = &dz[first];
    block.b1 = &b1[first], block.b2 = &b2[first];
    block.footprintX = &fx[first], block.footprintY = &fy[first];
  }
};

// PrimaryHitShader's blocks of runs give shadePrimaryHits' bits: lights,
// a visibility callback, vertex colours and BLEND, the eye light, and
// instances of one colour (constantColour: no lanes; on an all-emissive
// scene without the per-hit inputs), on every target.
TEST(ShadingKernel, BlocksOfRunsGiveTheSameBitsAsShadeHits) {
  const TintedVisibility tinted;
  Scene base = loadScene(std::string(RASTRAY_SCENES) + "/cornell-box.gltf");
  // Vertex colours on the first instance only, BLEND on the last
  // instance's material (when it has one of its own).
  Scene mixed = base;
  mixed.colors.assign(mixed.positions.size(), glm::vec4(1.0f));
  for (size_t v = 0; v < mixed.colors.size(); ++v)
    mixed.colors[v] = glm::vec4(0.2f + 0.1f * float(v % 7), 0.9f - 0.05f * float(v % 5), 0.5f, 1.0f);
  mixed.instances.front().hasColors = true;
  Material blend = mixed.materials[mixed.instances.back().material];
  blend.alphaMode = AlphaMode::Blend;
  blend.baseColorFactor.a = 0.4f;
  mixed.materials.push_back(blend);
  mixed.instances.back().material = uint32_t(mixed.materials.size() - 1);
  Scene eyeLit = base;
  eyeLit.lights.clear();
  // Instances shaded with one colour of their material (constantColour):
  // emissive on a black base colour (some zeros negative) under the eye
  // light, on every instance or every other one; no diffuse term
  // (transmission 1) under the lights, on every other instance.
  const auto constantEvery = [](Scene scene, size_t every, bool black) {
    for (size_t i = 0; i < scene.instances.size(); i += every) {
      Material m = scene.materialOf(uint32_t(i));
      // −0 emission plus a +0 direct term is +0: the lanes' sum, not e alone.
      m.emissive = glm::vec3(i % 7 == 0 ? -0.0f : 0.1f * float(i % 7), 0.8f, 0.5f - 0.05f * float(i));
      if (black)
        m.baseColorFactor =
            i % 3 == 1 ? glm::vec4(-0.0f, 0.0f, -0.0f, 1.0f) : glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
      else
        m.transmission = 1.0f;
      scene.materials.push_back(m);
      scene.instances[i].material = uint32_t(scene.materials.size() - 1);
    }
    return scene;
  };
  const Scene emissive = constantEvery(eyeLit, 1, true), someEmissive = constantEvery(eyeLit, 2, true),
              noDiffuse = constantEvery(base, 2, false);
  struct Case {
    const char* name;
    const Scene* scene;
    const LightVisibility* visibility;
  };
  for (const Case& c :
       {Case{"plain", &base, nullptr}, Case{"visibility", &base, &tinted},
        Case{"vertex colours and blend", &mixed, nullptr}, Case{"eye light", &eyeLit, nullptr},
        Case{"emissive", &emissive, nullptr}, Case{"some emissive", &someEmissive, nullptr},
        Case{"no diffuse", &noDiffuse, nullptr}}) {
    SCOPED_TRACE(c.name);
    const Scene& scene = *c.scene;
    const Camera camera = makeCamera(scene, {}, 64, 48);
    const std::vector<ShadeHit> hits = primaryHits(scene, camera, 1500);
    ASSERT_GT(hits.size(), 500u);
    const Shader shader(scene, analyzeScene(scene), camera, {}, c.visibility, nullptr);
    std::vector<glm::vec4> expected(hits.size());
    shadePrimaryHits(shader, hits.data(), hits.size(), expected.data(), ShadingPath::Kernel);
    // Only the all-emissive scene's blocks go without per-hit inputs.
    const bool needsInputs = PrimaryHitShader(shader, ShadingPath::Kernel).needsHitInputs();
    ASSERT_EQ(needsInputs, c.scene != &emissive);
    // The hits as struct of arrays, their colours to the reversed order.
    const size_t n = hits.size();
    std::vector<int32_t> run(n);
    std::vector<uint32_t> runInstance, runTriangle, runFirst, colorIndex(n), forward(n);
    HitColumns columns(hits);
    for (size_t i = 0; i < n; ++i) {
      colorIndex[i] = uint32_t(n - 1 - i);
      forward[i] = uint32_t(i);
    }
    for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
      SCOPED_TRACE(hwy::TargetName(target));
      hwy::SetSupportedTargetsForTest(target);
      // With and without the runs' first hits (runFirst); runs of 16 or
      // more hits (a wall's row) go to the kernel's block in lanes. With
      // them, the colours go to consecutive entries (the kernel writes a
      // block's colours interleaved in lanes then), else to the reversed
      // order.
      for (const bool withRunFirst : {false, true})
        for (const size_t blockSize : {size_t(1), size_t(7), size_t(kPrimaryHitBlock)}) {
          PrimaryHitShader kernel(shader, ShadingPath::Kernel);
          std::vector<glm::vec4> got(n, glm::vec4(-1.0f));
          for (size_t first = 0; first < n; first += blockSize) {
            const size_t count = std::min(blockSize, n - first);
            // Runs within the block: a new one where the triangle changes.
            runInstance.clear();
            runTriangle.clear();
            runFirst.clear();
            for (size_t k = 0; k < count; ++k) {
              const ShadeHit& h = hits[first + k];
              if (k == 0 || h.instance != runInstance.back() || h.triangle != runTriangle.back()) {
                runInstance.push_back(h.instance);
                runTriangle.push_back(h.triangle);
                runFirst.push_back(uint32_t(k));
              }
              run[first + k] = int32_t(runInstance.size() - 1);
            }
            runFirst.push_back(uint32_t(count));
            PrimaryHitBlock block;
            block.count = count;
            block.run = &run[first];
            block.runInstance = runInstance.data();
            block.runTriangle = runTriangle.data();
            columns.into(block, first);
            if (!needsInputs) block.dirX = block.dirY = block.dirZ = nullptr, block.b1 = block.b2 = nullptr;
            block.colorIndex = withRunFirst ? &forward[first] : &colorIndex[first];
            if (withRunFirst) {
              block.runs = runInstance.size();
              block.runFirst = runFirst.data();
            }
            kernel.shade(block, got.data());
          }
          for (size_t i = 0; i < n; ++i)
            ASSERT_TRUE(sameBits(got[withRunFirst ? i : colorIndex[i]], expected[i]))
                << "block " << blockSize << " hit " << i << (withRunFirst ? " run firsts" : "");
        }
    }
    hwy::SetSupportedTargetsForTest(0);
  }
}

}  // namespace
}  // namespace rastray

namespace rastray {
namespace {

// A caller's per-run corners and face normals (PrimaryHitBlock::runCorners,
// raster setup's) give the kernel's own bits: runs with and without them
// mixed in a block, the eye light and lights, every target. And the kernel
// reads them: a wrong normal given changes the colours.
TEST(ShadingKernel, RunCornersAndFaceNormalsGivenGiveTheKernelsOwnBits) {
  Scene lit = loadScene(std::string(RASTRAY_SCENES) + "/cornell-box.gltf");
  Scene eyeLit = lit;
  eyeLit.lights.clear();
  for (const Scene* scene : {&lit, &eyeLit}) {
    SCOPED_TRACE(scene == &lit ? "lights" : "eye light");
    const Camera camera = makeCamera(*scene, {}, 64, 48);
    const std::vector<ShadeHit> hits = primaryHits(*scene, camera, 1500);
    ASSERT_GT(hits.size(), 500u);
    const Shader shader(*scene, analyzeScene(*scene), camera, {}, nullptr, nullptr);
    const size_t n = hits.size();
    std::vector<glm::vec4> expected(n);
    shadePrimaryHits(shader, hits.data(), n, expected.data(), ShadingPath::Kernel);
    std::vector<int32_t> run(n);
    std::vector<uint32_t> colorIndex(n);
    HitColumns columns(hits);
    for (size_t i = 0; i < n; ++i) colorIndex[i] = uint32_t(i);
    // wrong: every run given a wrong normal (its components rotated: the
    // liveness check; a reversed one would be faced back towards the eye).
    const auto shadeGiven = [&](bool wrong) {
      PrimaryHitShader kernel(shader, ShadingPath::Kernel);
      std::vector<glm::vec4> got(n, glm::vec4(-1.0f));
      std::vector<uint32_t> runInstance, runTriangle;
      std::vector<glm::uvec3> corners;
      std::vector<glm::dvec3> normals;
      for (size_t first = 0; first < n; first += kPrimaryHitBlock) {
        const size_t count = std::min(kPrimaryHitBlock, n - first);
        runInstance.clear(), runTriangle.clear(), corners.clear(), normals.clear();
        for (size_t k = 0; k < count; ++k) {
          const ShadeHit& h = hits[first + k];
          if (k == 0 || h.instance != runInstance.back() || h.triangle != runTriangle.back()) {
            runInstance.push_back(h.instance);
            runTriangle.push_back(h.triangle);
            // Every third run without: the kernel's own values.
            const bool given = wrong || runInstance.size() % 3 != 0;
            corners.push_back(given ? scene->triangle(h.instance, h.triangle) : glm::uvec3(kNoId));
            const glm::dvec3 ng = triangleFaceNormal(*scene, h.instance, h.triangle);
            normals.push_back(wrong ? glm::dvec3(ng.y, ng.z, ng.x) : ng);
          }
          run[first + k] = int32_t(runInstance.size() - 1);
        }
        PrimaryHitBlock block;
        block.count = count;
        block.run = &run[first];
        block.runInstance = runInstance.data();
        block.runTriangle = runTriangle.data();
        block.runCorners = corners.data();
        block.runFaceNormal = normals.data();
        columns.into(block, first);
        block.colorIndex = &colorIndex[first];
        kernel.shade(block, got.data());
      }
      return got;
    };
    for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
      SCOPED_TRACE(hwy::TargetName(target));
      hwy::SetSupportedTargetsForTest(target);
      const std::vector<glm::vec4> got = shadeGiven(false);
      for (size_t i = 0; i < n; ++i) ASSERT_TRUE(sameBits(got[i], expected[i])) << "hit " << i;
    }
    hwy::SetSupportedTargetsForTest(0);
    const std::vector<glm::vec4> wrong = shadeGiven(true);
    size_t changed = 0;
    for (size_t i = 0; i < n; ++i) changed += !sameBits(wrong[i], expected[i]);
    EXPECT_GT(changed, n / 4);
  }
}

// The two-pass lanes (blocks whose lights need no visibility callback)
// give the separate passes' bits: the eye light; point, spot and
// directional lights with a range window; vertex colours (lanes that read
// their own colours); authored normals (the Cornell box's); through both
// entries (ShadeHits and blocks of runs) and blocks read in place (the
// fused pass's), on every target.
TEST(ShadingKernel, TwoPassLanesGiveTheSeparatePassesBits) {
  Scene lit = loadScene(std::string(RASTRAY_SCENES) + "/cornell-box.gltf");
  Scene eyeLit = lit;
  eyeLit.lights.clear();
  Scene many = lit;
  Light spot = many.lights.front();
  spot.type = LightType::Spot;
  spot.range = 4.5f;
  spot.innerConeAngle = 0.3f;
  spot.outerConeAngle = 0.9f;
  spot.direction = glm::normalize(glm::dvec3(0.2, -1.0, -0.3));
  spot.color = glm::vec3(0.9f, 0.6f, 0.3f);
  Light sun = spot;
  sun.type = LightType::Directional;
  sun.direction = glm::normalize(glm::dvec3(-0.4, -0.5, -1.0));
  many.lights.front().range = 2.5f;
  many.lights.push_back(spot);
  many.lights.push_back(sun);
  many.colors.assign(many.positions.size(), glm::vec4(1.0f));
  for (size_t v = 0; v < many.colors.size(); ++v)
    many.colors[v] = glm::vec4(0.3f + 0.1f * float(v % 5), 0.8f - 0.05f * float(v % 7), 0.6f, 1.0f);
  many.instances.front().hasColors = true;
  for (const Scene* scene : {&lit, &eyeLit, &many}) {
    SCOPED_TRACE(scene == &lit ? "light" : scene == &eyeLit ? "eye light" : "lights and vertex colours");
    const Camera camera = makeCamera(*scene, {}, 64, 48);
    const std::vector<ShadeHit> hits = primaryHits(*scene, camera, 1500);
    ASSERT_GT(hits.size(), 500u);
    const Shader shader(*scene, analyzeScene(*scene), camera, {}, nullptr, nullptr);
    const size_t n = hits.size();
    std::vector<int32_t> run(n);
    std::vector<uint32_t> colorIndex(n);
    HitColumns columns(hits);
    for (size_t i = 0; i < n; ++i) colorIndex[i] = uint32_t(i);
    const auto shadeBoth = [&](std::vector<glm::vec4>* viaHits, std::vector<glm::vec4>* viaBlocks) {
      viaHits->assign(n, glm::vec4(-1.0f));
      viaBlocks->assign(n, glm::vec4(-1.0f));
      shadePrimaryHits(shader, hits.data(), n, viaHits->data(), ShadingPath::Kernel);
      PrimaryHitShader kernel(shader, ShadingPath::Kernel);
      std::vector<uint32_t> runInstance, runTriangle;
      for (size_t first = 0; first < n; first += kPrimaryHitBlock) {
        const size_t count = std::min(kPrimaryHitBlock, n - first);
        runInstance.clear(), runTriangle.clear();
        for (size_t k = 0; k < count; ++k) {
          const ShadeHit& h = hits[first + k];
          if (k == 0 || h.instance != runInstance.back() || h.triangle != runTriangle.back()) {
            runInstance.push_back(h.instance);
            runTriangle.push_back(h.triangle);
          }
          run[first + k] = int32_t(runInstance.size() - 1);
        }
        PrimaryHitBlock block;
        block.count = count;
        block.run = &run[first];
        block.runInstance = runInstance.data();
        block.runTriangle = runTriangle.data();
        columns.into(block, first);
        block.colorIndex = &colorIndex[first];
        kernel.shade(block, viaBlocks->data());
      }
    };
    // Blocks whose inputs the kernel reads in place (run64, lanes, runFirst,
    // 64-byte aligned, padded with the last hit: the fused pass's block),
    // colours to consecutive entries or scattered (reversed).
    struct alignas(64) InPlace {
      alignas(64) int32_t run[kPrimaryHitBlock];
      alignas(64) int64_t run64[kPrimaryHitBlock];
      alignas(64) double dx[kPrimaryHitBlock], dy[kPrimaryHitBlock], dz[kPrimaryHitBlock];
      alignas(64) float b1[kPrimaryHitBlock], b2[kPrimaryHitBlock];
    };
    const auto shadeInPlace = [&](bool scattered) {
      std::vector<glm::vec4> got(n, glm::vec4(-1.0f));
      PrimaryHitShader kernel(shader, ShadingPath::Kernel);
      auto in = std::make_unique<InPlace>();
      std::vector<uint32_t> runInstance, runTriangle, runFirst, out(kPrimaryHitBlock);
      for (size_t first = 0; first < n; first += kPrimaryHitBlock) {
        const size_t count = std::min(kPrimaryHitBlock, n - first);
        runInstance.clear(), runTriangle.clear(), runFirst.clear();
        for (size_t k = 0; k < kPrimaryHitBlock; ++k) {
          const ShadeHit& h = hits[first + std::min(k, count - 1)];  // padding: the last hit
          if (k < count && (k == 0 || h.instance != runInstance.back() || h.triangle != runTriangle.back())) {
            runInstance.push_back(h.instance);
            runTriangle.push_back(h.triangle);
            runFirst.push_back(uint32_t(k));
          }
          in->run[k] = int32_t(runInstance.size() - 1);
          in->run64[k] = int64_t(runInstance.size() - 1);
          in->dx[k] = h.direction.x, in->dy[k] = h.direction.y, in->dz[k] = h.direction.z;
          in->b1[k] = h.b1, in->b2[k] = h.b2;
          out[k] = uint32_t(scattered ? n - 1 - (first + k) : first + k);
        }
        runFirst.push_back(uint32_t(count));
        PrimaryHitBlock block;
        block.count = count;
        block.run = in->run;
        block.run64 = in->run64;
        block.lanes = kPrimaryHitBlock;
        block.runs = runInstance.size();
        block.runFirst = runFirst.data();
        block.runInstance = runInstance.data();
        block.runTriangle = runTriangle.data();
        block.dirX = in->dx, block.dirY = in->dy, block.dirZ = in->dz;
        block.b1 = in->b1, block.b2 = in->b2;
        block.footprintX = &columns.fx[first], block.footprintY = &columns.fy[first];
        block.colorIndex = out.data();
        kernel.shade(block, got.data());
      }
      if (scattered) std::reverse(got.begin(), got.end());
      return got;
    };
    for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
      SCOPED_TRACE(hwy::TargetName(target));
      hwy::SetSupportedTargetsForTest(target);
      std::vector<glm::vec4> passesHits, passesBlocks, twoHits, twoBlocks;
      setTwoPassShadingForTest(false);
      shadeBoth(&passesHits, &passesBlocks);
      setTwoPassShadingForTest(true);
      shadeBoth(&twoHits, &twoBlocks);
      const std::vector<glm::vec4> inPlace = shadeInPlace(false), inPlaceScattered = shadeInPlace(true);
      for (size_t i = 0; i < n; ++i) {
        ASSERT_TRUE(sameBits(twoHits[i], passesHits[i])) << "hit " << i;
        ASSERT_TRUE(sameBits(twoBlocks[i], passesBlocks[i])) << "hit " << i;
        ASSERT_TRUE(sameBits(inPlace[i], passesHits[i])) << "in place, hit " << i;
        ASSERT_TRUE(sameBits(inPlaceScattered[i], passesHits[i])) << "in place, scattered, hit " << i;
      }
    }
    hwy::SetSupportedTargetsForTest(0);
  }
}

}  // namespace
}  // namespace rastray
