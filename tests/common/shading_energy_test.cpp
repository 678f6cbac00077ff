// Energy conservation of the shared shading model: in a white furnace (every
// secondary ray sees radiance 1, the eye light gives |n·d|) a white surface
// returns at most 1, whatever its mirror weight and transmission.
#include <gtest/gtest.h>

#include "common/shading.h"

namespace rastray {
namespace {

// One white triangle in the z = 0 plane facing +Z.
Scene whiteTriangle(const Material& m) {
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

class WhiteSurround : public SecondaryRayTracer {
 public:
  glm::vec3 radiance(const SurfacePoint&, const glm::dvec3&, RayKind, int, float) const override {
    return glm::vec3(1.0f);
  }
};

glm::vec4 shadeCentre(const Material& m, const glm::dvec3& direction) {
  const Scene s = whiteTriangle(m);
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

}  // namespace
}  // namespace rastray
