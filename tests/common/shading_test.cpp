#include "common/shading.h"

#include <gtest/gtest.h>

#include "common/math_constants.h"

namespace rastray {
namespace {

// One triangle in the z = 0 plane facing +Z, with a material.
Scene triangleScene(const Material& m) {
  Scene s;
  s.positions = {{-1, -1, 0}, {1, -1, 0}, {0, 1, 0}};
  s.normals = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  s.texcoords = {{0, 0}, {0, 0}, {0, 0}};
  s.triangles = {{0, 1, 2}};
  Instance inst;
  inst.vertexCount = 3;
  inst.triangleCount = 1;
  s.instances.push_back(inst);
  s.materials.push_back(m);
  s.bounds.extend({-1, -1, 0});
  s.bounds.extend({1, 1, 0});
  return s;
}

SurfacePoint centre(const Scene& s) {
  SampleHit hit;
  hit.instance = 0;
  hit.triangle = 0;
  hit.b1 = hit.b2 = 1.0f / 3.0f;
  return makeSurfacePoint(s, hit);
}

TEST(Shading, DefaultMaterialUnderTheEyeLightIsWhite) {
  const Scene s = triangleScene(Material{});  // glTF default: metallic 1, roughness 1
  const Camera cam = makeCamera(s, {}, 8, 8);
  const Shader shader(s, analyzeScene(s), cam, {}, nullptr, nullptr);
  const glm::vec4 c = shader.shade(centre(s), {0, 0, -1}, {});
  EXPECT_NEAR(c.r, 1.0f, 1e-6f);
  EXPECT_NEAR(c.a, 1.0f, 1e-6f);
}

TEST(Shading, BlendLayersArePremultiplied) {
  Material m;
  m.alphaMode = AlphaMode::Blend;
  m.baseColorFactor = {1, 0, 0, 0.5f};
  const Scene s = triangleScene(m);
  const Camera cam = makeCamera(s, {}, 8, 8);
  const Shader shader(s, analyzeScene(s), cam, {}, nullptr, nullptr);
  const glm::vec4 c = shader.shade(centre(s), {0, 0, -1}, {});
  EXPECT_NEAR(c.r, 0.5f, 1e-6f);
  EXPECT_NEAR(c.a, 0.5f, 1e-6f);
  EXPECT_NEAR(shader.shadowTransmittance(centre(s)).r, 0.5f, 1e-6f);
}

TEST(Shading, PointLightFollowsTheInverseSquareLaw) {
  Material m;
  m.metallic = 0.0f;
  Scene s = triangleScene(m);
  Light l;
  l.position = {0, 0, 2};
  l.intensity = 4.0f;
  s.lights.push_back(l);
  const Camera cam = makeCamera(s, {}, 8, 8);
  const Shader shader(s, analyzeScene(s), cam, {}, nullptr, nullptr);
  const SurfacePoint p = centre(s);  // (0, -1/3, 0)
  const glm::dvec3 d = l.position - p.position;
  const double cosTheta = d.z / glm::length(d);
  const double expected = 4.0 / glm::dot(d, d) * cosTheta / kPi;
  EXPECT_NEAR(shader.shade(p, {0, 0, -1}, {}).r, expected, 1e-6);
  // Seen from behind, the light on the front side does not reach the viewer's side.
  EXPECT_NEAR(shader.shade(p, {0, 0, 1}, {}).r, 0.0, 1e-9);
}

// A tracer that returns a constant radiance and records what it was asked.
class ConstantTracer : public SecondaryRayTracer {
 public:
  glm::vec3 radiance(const SurfacePoint&, const glm::dvec3& direction, RayKind kind, int,
                     float) const override {
    last.push_back({kind, direction});
    return kind == RayKind::Reflection ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
  }
  mutable std::vector<std::pair<RayKind, glm::dvec3>> last;
};

TEST(Shading, GlassSplitsByFresnel) {
  Material glass;
  glass.metallic = 0.0f;
  glass.roughness = 0.0f;
  glass.transmission = 1.0f;
  glass.ior = 1.5f;
  const Scene s = triangleScene(glass);
  const Camera cam = makeCamera(s, {}, 8, 8);
  ConstantTracer tracer;
  const Shader shader(s, analyzeScene(s), cam, {}, nullptr, &tracer);
  const glm::vec4 c = shader.shade(centre(s), {0, 0, -1}, {});
  // Normal incidence: R = 0.04 reflected (red), T = 0.96 refracted (green).
  EXPECT_NEAR(c.r, 0.04f, 1e-6f);
  EXPECT_NEAR(c.g, 0.96f, 1e-6f);
  ASSERT_EQ(tracer.last.size(), 2u);
  EXPECT_EQ(tracer.last[0].first, RayKind::Reflection);
  EXPECT_NEAR(tracer.last[0].second.z, 1.0, 1e-12);
  EXPECT_EQ(tracer.last[1].first, RayKind::Refraction);
  EXPECT_NEAR(tracer.last[1].second.z, -1.0, 1e-12);
}

TEST(Shading, MaxDepthStopsSecondaryRays) {
  Material mirror;
  mirror.metallic = 1.0f;
  mirror.roughness = 0.0f;
  const Scene s = triangleScene(mirror);
  const Camera cam = makeCamera(s, {}, 8, 8);
  ConstantTracer tracer;
  ShadingOptions o;
  o.maxDepth = 2;
  const Shader shader(s, analyzeScene(s), cam, o, nullptr, &tracer);
  EXPECT_NEAR(shader.shade(centre(s), {0, 0, -1}, {}, 1).r, 1.0f, 1e-6f);
  EXPECT_EQ(tracer.last.size(), 1u);
  EXPECT_NEAR(shader.shade(centre(s), {0, 0, -1}, {}, 2).r, 0.0f, 1e-6f);
  EXPECT_EQ(tracer.last.size(), 1u);  // no ray at the depth limit
}

// Energy conservation: in a white furnace (every secondary ray sees
// radiance 1, the eye light gives |n·d|) a white surface returns at most 1,
// whatever its mirror weight and transmission.
class WhiteSurround : public SecondaryRayTracer {
 public:
  glm::vec3 radiance(const SurfacePoint&, const glm::dvec3&, RayKind, int, float) const override {
    return glm::vec3(1.0f);
  }
};

glm::vec4 shadeCentre(const Material& m, const glm::dvec3& direction) {
  const Scene s = triangleScene(m);
  const Camera cam = makeCamera(s, {}, 8, 8);
  const WhiteSurround white;
  const Shader shader(s, analyzeScene(s), cam, {}, nullptr, &white);
  SampleHit hit;
  hit.instance = 0;
  hit.triangle = 0;
  hit.b1 = hit.b2 = 1.0f / 3.0f;
  return shader.shade(makeSurfacePoint(s, hit), direction, {});
}

TEST(ShadingEnergy, MirrorAndGlassTogetherReturnExactlyWhatArrives) {
  // w = 0.5, t = 0.5, seen head-on: diffuse (1 − w)(1 − t) = 0.25 under the
  // eye light (|n·d| = 1), mirror w = 0.5, glass (1 − w)t = 0.25 split by
  // Fresnel into reflection and refraction, each seeing radiance 1.
  Material m;
  m.metallic = 0.5f;
  m.roughness = 0.0f;
  m.transmission = 0.5f;
  const glm::vec4 c = shadeCentre(m, {0, 0, -1});
  EXPECT_NEAR(c.r, 1.0f, 1e-5f);
  EXPECT_NEAR(c.g, 1.0f, 1e-5f);
  EXPECT_NEAR(c.b, 1.0f, 1e-5f);
}

TEST(ShadingEnergy, NoMaterialReturnsMoreThanArrives) {
  const glm::dvec3 directions[] = {{0, 0, -1},
                                   glm::normalize(glm::dvec3(0.6, 0.0, -0.8)),
                                   glm::normalize(glm::dvec3(0.0, 0.99, -0.1)),
                                   {0, 0, 1}};
  for (float metallic : {0.0f, 0.25f, 0.5f, 0.75f, 1.0f})
    for (float roughness : {0.0f, 0.5f, 1.0f})
      for (float transmission : {0.0f, 0.3f, 0.7f, 1.0f})
        for (const glm::dvec3& d : directions) {
          Material m;
          m.metallic = metallic;
          m.roughness = roughness;
          m.transmission = transmission;
          const glm::vec4 c = shadeCentre(m, d);
          for (int i = 0; i < 3; ++i)
            EXPECT_LE(c[i], 1.0f + 1e-5f)
                << "metallic " << metallic << " roughness " << roughness << " transmission " << transmission
                << " direction " << d.x << " " << d.y << " " << d.z;
        }
}

// Mip chains are built once per scene: every Shader made from one analysis
// (or a copy of it: the frame, the shadow maps' unlit shader, the ray
// caster) shares one TextureSet; a different scene gets its own.
TEST(Shading, ShadersOfOneAnalysisShareTheSceneTextures) {
  Material m;
  m.baseColorTexture = 0;
  Scene s = triangleScene(m);
  TextureImage img;
  img.width = 8;
  img.height = 4;
  img.rgba8.assign(size_t(8 * 4 * 4), 200);
  s.images.push_back(img);
  Texture t;
  t.image = 0;
  s.textures.push_back(t);
  const SceneAnalysis analysis = analyzeScene(s);
  ASSERT_TRUE(analysis.textures);
  const Camera cam = makeCamera(s, {}, 8, 8);
  const Shader a(s, analysis, cam, {}, nullptr, nullptr);
  const SceneAnalysis copy = analysis;
  const Shader b(s, copy, cam, {}, nullptr, nullptr);
  EXPECT_EQ(&a.textures(), &b.textures());
  EXPECT_EQ(a.textures().levelCount(0), 4u);  // 8x4, 4x2, 2x1, 1x1
  const Scene other = s;                      // same content, another scene: not the cached set
  const Shader c(other, analysis, cam, {}, nullptr, nullptr);
  EXPECT_NE(&a.textures(), &c.textures());
  EXPECT_EQ(c.textures().levelCount(0), 4u);
  // No textures needed: an empty set, nothing decoded.
  const Scene plain = triangleScene(Material{});
  EXPECT_TRUE(Shader(plain, analyzeScene(plain), cam, {}, nullptr, nullptr).textures().empty());
}

}  // namespace
}  // namespace rastray
