// Synthetic frames for the compare tests: the three-triangles scene
// (scenes/three-triangles.gltf) "rendered" at pixel centres by a few lines
// of exact point-in-triangle tests, independent of both renderers, and a
// two-triangle quad built in code for shared edges.
//
// three-triangles: ortho camera at the origin looking down −Z, xmag = ymag
// = 1, znear 0.125, zfar 1. At 8×8 a pixel is 0.25 world units and pixel
// (x, y) has its centre at (−1 + (x + ½)/4, 1 − (y + ½)/4), so the centres
// of row 5 lie exactly on the yellow triangle's bottom edge y = −0.375.
#pragma once

#include <atomic>
#include <filesystem>
#include <glm/glm.hpp>
#include <string>

#include "common/camera.h"
#include "common/image.h"
#include "common/scene.h"
#include "tests/test_files.h"

namespace rastray::test {

struct FlatTriangle {
  glm::dvec2 v[3];
  double depth;
  glm::vec4 color;
};

inline const FlatTriangle kThreeTriangles[3] = {
    {{{-0.625, -0.375}, {0.625, -0.375}, {0.0, 0.75}}, 0.5, {1, 1, 0, 1}},  // 0 yellow
    {{{-0.375, -0.75}, {0.875, -0.5}, {0.25, 0.5}}, 0.75, {0, 0, 1, 1}},    // 1 blue
    {{{-0.875, -0.5}, {0.375, -0.75}, {-0.25, 0.5}}, 0.25, {1, 0, 0, 1}},   // 2 red
};

inline bool insideInclusive(const FlatTriangle& t, glm::dvec2 p) {
  double s[3];
  for (int i = 0; i < 3; ++i) {
    const glm::dvec2 a = t.v[i], b = t.v[(i + 1) % 3];
    s[i] = (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
  }
  return (s[0] >= 0 && s[1] >= 0 && s[2] >= 0) || (s[0] <= 0 && s[1] <= 0 && s[2] <= 0);
}

// The nearest triangle at each pixel centre (inclusive edges), n×n pixels.
inline FlatImage threeTrianglesFrame(int n = 8) {
  FlatImage f(n, n);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const glm::dvec2 p(-1.0 + (x + 0.5) * 2.0 / n, 1.0 - (y + 0.5) * 2.0 / n);
      const size_t i = f.index(x, y);
      for (uint32_t t = 0; t < 3; ++t)
        if (insideInclusive(kThreeTriangles[t], p) && kThreeTriangles[t].depth < f.depth[i]) {
          f.instance[i] = t;
          f.triangle[i] = 0;
          f.depth[i] = float(kThreeTriangles[t].depth);
          f.color[i] = kThreeTriangles[t].color;
        }
    }
  return f;
}

inline void setHit(FlatImage& f, int x, int y, uint32_t instance, uint32_t triangle, float depth) {
  const size_t i = f.index(x, y);
  f.instance[i] = instance;
  f.triangle[i] = triangle;
  f.depth[i] = depth;
}

inline void setEmpty(FlatImage& f, int x, int y) {
  setHit(f, x, y, kNoId, kNoId, std::numeric_limits<float>::infinity());
}

// A unit quad at view depth 0.5 split along its diagonal (−½, −½)–(½, ½):
// triangle 0 = (0, 1, 2) below it, 1 = (0, 2, 3) above it; one instance.
// `duplicated`: every triangle has its own vertices (no index sharing), so
// the shared edge is found by position only. Ortho camera as in
// three-triangles.
inline Scene quadScene(bool duplicated) {
  Scene s;
  s.path = duplicated ? "quad-duplicated" : "quad";
  const glm::vec3 p[4] = {
      {-0.5f, -0.5f, -0.5f}, {0.5f, -0.5f, -0.5f}, {0.5f, 0.5f, -0.5f}, {-0.5f, 0.5f, -0.5f}};
  if (duplicated) {
    s.positions = {p[0], p[1], p[2], p[0], p[2], p[3]};
    s.triangles = {{0, 1, 2}, {3, 4, 5}};
  } else {
    s.positions = {p[0], p[1], p[2], p[3]};
    s.triangles = {{0, 1, 2}, {0, 2, 3}};
  }
  Instance inst;
  inst.vertexCount = uint32_t(s.positions.size());
  inst.triangleCount = 2;
  s.instances = {inst};
  s.materials = {Material{}};
  CameraModel cam;
  cam.projection = Projection::Orthographic;
  cam.xmag = cam.ymag = 1.0;
  cam.znear = 0.125;
  cam.zfar = 1.0;
  s.camera = cam;
  for (const glm::vec3& v : s.positions) s.bounds.extend(glm::dvec3(v));
  return s;
}

// A fresh folder in the running test's scratch directory (test_files.h:
// kept when the test fails).
inline std::string makeTempDir(const std::string& name) {
  static std::atomic<int> counter{0};
  const std::filesystem::path dir = scratchDir() / (name + "_" + std::to_string(counter++));
  std::filesystem::create_directories(dir);
  return dir.string();
}

}  // namespace rastray::test
