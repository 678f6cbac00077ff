// Scenes built in code for the ray caster tests, and a brute-force
// double-precision reference tracer (Mitsuba's `ray_intersect_naive` idea):
// every triangle tested against every ray, no Embree.
#pragma once

#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <string>
#include <vector>

#include "common/analysis.h"
#include "common/camera.h"
#include "common/scene.h"
#include "common/surface.h"

namespace rastray::test {

inline std::string scenePath(const std::string& name) { return std::string(RASTRAY_SCENES) + "/" + name; }

class SceneBuilder {
 public:
  SceneBuilder() { scene_.path = "built-in-test-scene"; }

  uint32_t addMaterial(const Material& m) {
    scene_.materials.push_back(m);
    return uint32_t(scene_.materials.size() - 1);
  }
  static Material lambert(glm::vec4 color) {
    Material m;
    m.baseColorFactor = color;
    m.metallic = 0.0f;
    m.roughness = 1.0f;
    return m;
  }
  static Material glass(float ior) {
    Material m = lambert(glm::vec4(1.0f));
    m.transmission = 1.0f;
    m.ior = ior;
    return m;
  }

  // One instance (its own node and mesh); triangles CCW seen from the front.
  uint32_t addMesh(const std::vector<glm::vec3>& positions, const std::vector<glm::uvec3>& triangles,
                   uint32_t material) {
    Instance inst;
    inst.node = inst.mesh = uint32_t(scene_.instances.size());
    inst.material = material;
    inst.firstVertex = uint32_t(scene_.positions.size());
    inst.vertexCount = uint32_t(positions.size());
    inst.firstTriangle = uint32_t(scene_.triangles.size());
    inst.triangleCount = uint32_t(triangles.size());
    for (const glm::vec3& p : positions) {
      scene_.positions.push_back(p);
      scene_.normals.emplace_back(0.0f);
      scene_.texcoords.emplace_back(0.0f);
      scene_.bounds.extend(glm::dvec3(p));
    }
    for (const glm::uvec3& t : triangles) {
      scene_.triangles.push_back(t + glm::uvec3(inst.firstVertex));
      const glm::dvec3 a(positions[t.x]), b(positions[t.y]), c(positions[t.z]);
      if (glm::cross(b - a, c - a) == glm::dvec3(0.0)) ++inst.degenerateCount;
    }
    scene_.instances.push_back(inst);
    return uint32_t(scene_.instances.size() - 1);
  }

  // A quad centre ± u ± v, front side along cross(u, v).
  uint32_t addQuad(glm::dvec3 centre, glm::dvec3 u, glm::dvec3 v, uint32_t material) {
    const std::vector<glm::vec3> p = {glm::vec3(centre - u - v), glm::vec3(centre + u - v),
                                      glm::vec3(centre + u + v), glm::vec3(centre - u + v)};
    return addMesh(p, {{0, 1, 2}, {0, 2, 3}}, material);
  }

  // An axis-aligned box, faces outward.
  uint32_t addBox(glm::vec3 lo, glm::vec3 hi, uint32_t material) {
    std::vector<glm::vec3> p;
    for (int i = 0; i < 8; ++i) p.emplace_back(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
    const std::vector<glm::uvec3> t = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6},   // -z, +z
                                       {0, 1, 5}, {0, 5, 4}, {2, 6, 7}, {2, 7, 3},   // -y, +y
                                       {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};  // -x, +x
    return addMesh(p, t, material);
  }

  void addDirectionalLight(glm::dvec3 travel, float intensity) {
    Light l;
    l.type = LightType::Directional;
    l.direction = glm::normalize(travel);
    l.intensity = intensity;
    scene_.lights.push_back(l);
  }

  void setCamera(Projection projection, glm::dvec3 eye, glm::dvec3 target, glm::dvec3 up, double yfovOrYmag,
                 double znear, double zfar) {
    CameraModel c;
    c.projection = projection;
    c.yfov = yfovOrYmag;
    c.xmag = c.ymag = yfovOrYmag;
    c.znear = znear;
    c.zfar = zfar;
    c.worldFromCamera = glm::inverse(glm::lookAt(eye, target, up));
    c.origin = "test";
    scene_.camera = c;
  }

  Scene& scene() { return scene_; }

 private:
  Scene scene_;
};

// A brute-force hit: every triangle whose plane the ray crosses inside
// [tMin, tMax] with barycentrics inside the triangle.
struct NaiveHit {
  uint32_t instance, triangle;
  double t, b1, b2;
  double margin;  // distance of the barycentrics from the triangle's border (small: edge tie)
};

inline std::vector<NaiveHit> intersectNaive(const Scene& scene, const Ray& ray, double tMin, double tMax) {
  std::vector<NaiveHit> hits;
  for (uint32_t i = 0; i < scene.instances.size(); ++i)
    for (uint32_t t = 0; t < scene.instances[i].triangleCount; ++t) {
      double th;
      glm::dvec2 b;
      if (!intersectTrianglePlane(scene, i, t, ray, &th, &b)) continue;
      if (!(th >= tMin && th <= tMax)) continue;
      const double margin = std::min({b.x, b.y, 1.0 - b.x - b.y});
      if (margin < -1e-6) continue;
      hits.push_back({i, t, th, b.x, b.y, margin});
    }
  std::sort(hits.begin(), hits.end(), [](const NaiveHit& a, const NaiveHit& b) {
    if (a.t != b.t) return a.t < b.t;
    if (a.instance != b.instance) return a.instance < b.instance;
    return a.triangle < b.triangle;
  });
  return hits;
}

}  // namespace rastray::test
