#include "app/bench/terrain_scene.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/math_constants.h"

namespace rastray::crossover {

namespace {

constexpr double kAmplitude = 0.06, kWavelength = 0.5;
constexpr double kYfov = 0.8;  // radians
// Screen margin beyond the image on each side, as a fraction of its width
// or height: the bumps move a vertex by at most about 2% of the image.
constexpr double kMargin = 0.03;
const glm::dvec3 kEye{0.0, 2.0, 1.2}, kTarget{0.0, 0.0, 0.0};

double height(double x, double z) {
  return kAmplitude * std::sin(2 * kPi * x / kWavelength) * std::cos(2 * kPi * z / kWavelength);
}

glm::dvec3 normalAt(double x, double z) {
  const double k = 2 * kPi / kWavelength;
  const double dx = kAmplitude * k * std::cos(k * x) * std::cos(k * z);
  const double dz = -kAmplitude * k * std::sin(k * x) * std::sin(k * z);
  return glm::normalize(glm::dvec3(-dx, 1.0, -dz));
}

// Where the ray through screen point (s, t) meets y = 0: s and t in [0, 1]
// across the image (left to right, bottom to top), beyond it for the margin.
// Every point used lies below the horizon (the top margin row looks 33°
// down, the row beyond it less than a degree higher).
struct ScreenToGround {
  glm::dvec3 f, r, u;
  double tx, ty;
  explicit ScreenToGround(double aspect) {
    f = glm::normalize(kTarget - kEye);
    r = glm::normalize(glm::cross(f, glm::dvec3(0, 1, 0)));
    u = glm::cross(r, f);
    ty = std::tan(kYfov / 2);
    tx = ty * aspect;
  }
  glm::dvec2 operator()(double s, double t) const {
    const glm::dvec3 d = f + (2 * s - 1) * tx * r + (2 * t - 1) * ty * u;
    const double along = -kEye.y / d.y;
    return {kEye.x + along * d.x, kEye.z + along * d.z};
  }
};

}  // namespace

GridShape gridShape(uint64_t triangles, double aspect) {
  if (triangles == 0) throw std::invalid_argument("crossover: a mesh needs at least one triangle");
  GridShape g;
  const uint64_t quads = triangles / 2;
  g.extraTriangle = triangles % 2 == 1;
  if (quads == 0) {
    g.columns = 1;
    return g;
  }
  // The column count whose quads are closest to square: columns/rows ≈ aspect.
  const double ideal = std::max(1.0, std::sqrt(double(quads) * aspect));
  // A divisor of `quads` within a factor 2 of the ideal gives a full rectangle.
  uint64_t best = 0;
  double bestRatio = 2.0;
  const uint64_t lo = std::max<uint64_t>(1, uint64_t(ideal / 2));
  const uint64_t hi = std::min<uint64_t>(quads, uint64_t(ideal * 2) + 1);
  for (uint64_t c = lo; c <= hi; ++c)
    if (quads % c == 0) {
      const double ratio = std::max(double(c) / ideal, ideal / double(c));
      if (ratio < bestRatio) {
        bestRatio = ratio;
        best = c;
      }
    }
  g.columns = best ? best : std::clamp<uint64_t>(uint64_t(std::llround(ideal)), 1, quads);
  g.rows = quads / g.columns;
  g.partialQuads = quads % g.columns;
  return g;
}

GltfScene crossoverScene(uint64_t triangles, bool lit, double aspect) {
  if (triangles > 400'000'000ull)
    throw std::invalid_argument("crossover: at most 4e8 triangles (a .glb holds at most 4 GiB)");
  if (!(aspect >= 0.1 && aspect <= 10)) throw std::invalid_argument("crossover: aspect must be 0.1 to 10");
  const GridShape g = gridShape(triangles, aspect);
  const ScreenToGround ground(aspect);

  // Vertex rows: the full grid's rows + 1 over the image and its margin, and
  // one more row just beyond the top margin (out of view) when a partial row
  // or the odd triangle needs it.
  const bool beyond = g.partialQuads > 0 || g.extraTriangle;
  const uint64_t cols = g.columns + 1;
  const uint64_t fullRows = std::max<uint64_t>(g.rows, 1);
  const double span = 1 + 2 * kMargin;
  GltfMesh mesh;
  const uint64_t vertexRows = g.rows + 1 + (beyond ? 1 : 0);
  mesh.positions.reserve(vertexRows * cols);
  mesh.normals.reserve(vertexRows * cols);
  // Row i (0 at the bottom of the image) at t = −margin + i·span/rows; the
  // row beyond at 1 + margin + 0.01, stored last.
  for (uint64_t i = 0; i < vertexRows; ++i) {
    const double t = i <= g.rows ? -kMargin + span * double(i) / double(fullRows) : 1 + kMargin + 0.01;
    for (uint64_t j = 0; j < cols; ++j) {
      const double s = -kMargin + span * double(j) / double(g.columns);
      const glm::dvec2 p = ground(s, t);
      mesh.positions.emplace_back(float(p.x), float(height(p.x, p.y)), float(p.y));
      mesh.normals.emplace_back(glm::vec3(normalAt(p.x, p.y)));
    }
  }
  auto vertex = [&](uint64_t row, uint64_t col) { return uint32_t(row * cols + col); };
  mesh.indices.reserve(size_t(g.triangles()) * 3);
  // Rows go from near (bottom of the image, larger z) to far (smaller z), so
  // (i, j), (i, j + 1), (i + 1, j) is counter-clockwise seen from +y.
  auto quad = [&](uint64_t i, uint64_t j, bool both) {
    mesh.indices.insert(mesh.indices.end(), {vertex(i, j), vertex(i, j + 1), vertex(i + 1, j)});
    if (both)
      mesh.indices.insert(mesh.indices.end(), {vertex(i, j + 1), vertex(i + 1, j + 1), vertex(i + 1, j)});
  };
  for (uint64_t i = 0; i < g.rows; ++i)
    for (uint64_t j = 0; j < g.columns; ++j) quad(i, j, true);
  for (uint64_t j = 0; j < g.partialQuads; ++j) quad(g.rows, j, true);
  if (g.extraTriangle) quad(g.rows, g.partialQuads, false);

  GltfScene scene;
  GltfMaterial m;
  if (lit) {
    m.baseColor = {0.8f, 0.8f, 0.8f, 1.0f};
    GltfLight light;
    light.type = "directional";
    light.direction = glm::normalize(glm::dvec3(-0.5, -0.6, -0.6));
    light.intensity = 3.0f;
    scene.lights.push_back(light);
  } else {
    m.baseColor = {0.0f, 0.0f, 0.0f, 1.0f};
    m.emissive = {0.8f, 0.8f, 0.8f};
  }
  scene.materials.push_back(m);
  GltfCamera camera;
  camera.eye = kEye;
  camera.target = kTarget;
  camera.yfov = kYfov;
  camera.znear = 0.1;
  double farthest = 0;
  for (const glm::vec3& p : mesh.positions) farthest = std::max(farthest, glm::length(glm::dvec3(p) - kEye));
  camera.zfar = farthest * 1.25;
  scene.camera = camera;
  scene.meshes.push_back(std::move(mesh));
  return scene;
}

}  // namespace rastray::crossover
