// Helpers for the raster tests: scenes built in code and cameras.
#pragma once

#include "common/math_constants.h"

#include <algorithm>
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "common/analysis.h"
#include "common/camera.h"
#include "common/scene.h"
#include "raster/rasterizer.h"

namespace rastray::test {

inline std::string scenePath(const std::string& name) { return std::string(RASTRAY_SCENES) + "/" + name; }

// Appends one instance with its own material; returns the instance index.
inline uint32_t addMesh(Scene& scene, const std::vector<glm::vec3>& positions,
                        const std::vector<glm::uvec3>& tris, Material material = Material{}) {
  Instance inst;
  inst.node = uint32_t(scene.instances.size());
  inst.material = uint32_t(scene.materials.size());
  scene.materials.push_back(material);
  inst.firstVertex = uint32_t(scene.positions.size());
  inst.vertexCount = uint32_t(positions.size());
  inst.firstTriangle = uint32_t(scene.triangles.size());
  inst.triangleCount = uint32_t(tris.size());
  for (const glm::vec3& p : positions) {
    scene.positions.push_back(p);
    scene.normals.push_back(glm::vec3(0.0f));
    scene.texcoords.push_back(glm::vec2(0.0f));
    scene.bounds.extend(glm::dvec3(p));
  }
  for (const glm::uvec3& t : tris) {
    scene.triangles.push_back(t + glm::uvec3(inst.firstVertex));
    // As the loader counts them (the rasterizer's fast setup relies on it).
    if (isDegenerate(scene, scene.triangles.size() - 1)) ++inst.degenerateCount;
  }
  scene.instances.push_back(inst);
  return uint32_t(scene.instances.size() - 1);
}

// Appends each instance of `from` with every vertex moved to z <= zMax
// (behind an occluder the caller puts in front), keeping its triangles.
inline void addPushedBehind(Scene& scene, const Scene& from, float zMax) {
  for (const Instance& inst : from.instances) {
    std::vector<glm::vec3> p(from.positions.begin() + inst.firstVertex,
                             from.positions.begin() + inst.firstVertex + inst.vertexCount);
    for (glm::vec3& v : p) v.z = std::min(v.z, zMax);
    std::vector<glm::uvec3> t;
    for (uint32_t i = 0; i < inst.triangleCount; ++i)
      t.push_back(from.triangles[inst.firstTriangle + i] - glm::uvec3(inst.firstVertex));
    addMesh(scene, p, t);
  }
}

inline Material colored(glm::vec4 c, AlphaMode mode = AlphaMode::Opaque, bool doubleSided = false) {
  Material m;
  m.baseColorFactor = c;
  m.alphaMode = mode;
  m.doubleSided = doubleSided;
  m.metallic = 0.0f;
  return m;
}

// An orthographic camera at the origin looking down −Z: image position
// (x, y) sees world (x − W/2, H/2 − y)·(2·mag/W) when W == H.
inline Camera orthoCamera(int size, double mag, double znear = 0.0, double zfar = 100.0) {
  Camera c;
  c.projection = Projection::Orthographic;
  c.width = c.height = size;
  c.xmag = c.ymag = mag;
  c.znear = znear;
  c.zfar = zfar;
  return c;
}

inline Camera perspectiveCamera(int w, int h, double yfovRadians, glm::dvec3 eye, glm::dvec3 target,
                                double znear = 0.01, double zfar = std::numeric_limits<double>::infinity()) {
  Scene empty;
  CameraOverrides o;
  o.eye = eye;
  o.target = target;
  o.up = glm::dvec3(0, 1, 0);
  o.yfovDegrees = yfovRadians * 180.0 / kPi;
  o.znear = znear;
  o.zfar = zfar;
  return makeCamera(empty, o, w, h);
}

// A closed UV sphere, CCW seen from outside.
inline void addSphere(Scene& scene, glm::dvec3 centre, double radius, int slices, int stacks,
                      Material m = colored(glm::vec4(1.0f))) {
  std::vector<glm::vec3> p;
  std::vector<glm::uvec3> t;
  p.push_back(glm::vec3(centre + glm::dvec3(0, radius, 0)));
  for (int i = 1; i < stacks; ++i) {
    const double th = kPi * i / stacks;
    for (int j = 0; j < slices; ++j) {
      const double ph = 2.0 * kPi * j / slices;
      p.push_back(glm::vec3(centre + radius * glm::dvec3(std::sin(th) * std::cos(ph), std::cos(th),
                                                         -std::sin(th) * std::sin(ph))));
    }
  }
  p.push_back(glm::vec3(centre - glm::dvec3(0, radius, 0)));
  const uint32_t bottom = uint32_t(p.size() - 1);
  const auto ring = [&](int i, int j) { return uint32_t(1 + (i - 1) * slices + (j % slices)); };
  for (int j = 0; j < slices; ++j) t.push_back({0u, ring(1, j), ring(1, j + 1)});
  for (int i = 1; i + 1 < stacks; ++i)
    for (int j = 0; j < slices; ++j) {
      t.push_back({ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)});
      t.push_back({ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)});
    }
  for (int j = 0; j < slices; ++j) t.push_back({ring(stacks - 1, j), bottom, ring(stacks - 1, j + 1)});
  addMesh(scene, p, t, m);
}

inline RenderOutput render(const Scene& scene, const Camera& camera, RasterOptions options) {
  const SceneAnalysis analysis = analyzeScene(scene);
  return renderRaster(scene, analysis, camera, options);
}

}  // namespace rastray::test
