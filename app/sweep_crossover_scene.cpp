#include "app/sweep_crossover_scene.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rastray::crossover {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kAmplitude = 0.06, kWavelength = 0.5;
constexpr double kYfov = 0.8;  // radians
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

// The footprint of the 16:9 view on y = 0: where the rays through the image
// corners meet the plane, as an x-z bounding box, widened by a margin that
// keeps the bumps (±A) from showing the background at the edges.
struct Footprint {
  double x0, x1, z0, z1;
};

Footprint viewFootprint() {
  const glm::dvec3 f = glm::normalize(kTarget - kEye);
  const glm::dvec3 r = glm::normalize(glm::cross(f, glm::dvec3(0, 1, 0)));
  const glm::dvec3 u = glm::cross(r, f);
  const double ty = std::tan(kYfov / 2), tx = ty * 16.0 / 9.0;
  Footprint fp{1e300, -1e300, 1e300, -1e300};
  for (double sx : {-1.0, 1.0})
    for (double sy : {-1.0, 1.0}) {
      const glm::dvec3 d = f + sx * tx * r + sy * ty * u;  // every corner ray points down (d.y < 0)
      const double t = -kEye.y / d.y;
      const glm::dvec3 p = kEye + t * d;
      fp.x0 = std::min(fp.x0, p.x);
      fp.x1 = std::max(fp.x1, p.x);
      fp.z0 = std::min(fp.z0, p.z);
      fp.z1 = std::max(fp.z1, p.z);
    }
  const double margin = 0.15;
  return {fp.x0 - margin, fp.x1 + margin, fp.z0 - margin, fp.z1 + margin};
}

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
  const uint64_t lo = std::max<uint64_t>(1, uint64_t(ideal / 2)),
                 hi = std::min<uint64_t>(quads, uint64_t(ideal * 2) + 1);
  for (uint64_t c = lo; c <= hi; ++c)
    if (quads % c == 0) {
      const double ratio = std::max(double(c) / ideal, ideal / double(c));
      if (ratio < bestRatio) {
        bestRatio = ratio;
        best = c;
      }
    }
  g.columns = best ? best : std::min<uint64_t>(quads, uint64_t(std::llround(ideal)));
  g.rows = quads / g.columns;
  g.partialQuads = quads % g.columns;
  return g;
}

GltfScene crossoverScene(uint64_t triangles, bool lit) {
  if (triangles > 400'000'000ull)
    throw std::invalid_argument("crossover: at most 4e8 triangles (a .glb holds at most 4 GiB)");
  const Footprint fp = viewFootprint();
  const double width = fp.x1 - fp.x0, depth = fp.z1 - fp.z0;
  const GridShape g = gridShape(triangles, width / depth);

  // Vertex rows: the full grid's rows + 1, and one more row beyond the far
  // edge (z0) when a partial row or the odd triangle needs it.
  const bool beyond = g.partialQuads > 0 || g.extraTriangle;
  const uint64_t cols = g.columns + 1;
  const uint64_t fullRows = std::max<uint64_t>(g.rows, 1);  // spacing even when all quads are partial
  const double dx = width / double(g.columns), dz = depth / double(fullRows);
  GltfMesh mesh;
  const uint64_t vertexRows = g.rows + 1 + (beyond ? 1 : 0);
  mesh.positions.reserve(vertexRows * cols);
  mesh.normals.reserve(vertexRows * cols);
  // Row i of the grid sits at z0 + i·dz; the row beyond, at z0 − dz, comes first.
  const int64_t firstRow = beyond ? -1 : 0;
  for (int64_t i = firstRow; i <= int64_t(g.rows); ++i)
    for (uint64_t j = 0; j < cols; ++j) {
      const double x = fp.x0 + double(j) * dx, z = fp.z0 + double(i) * dz;
      mesh.positions.emplace_back(float(x), float(height(x, z)), float(z));
      mesh.normals.emplace_back(glm::vec3(normalAt(x, z)));
    }
  auto vertex = [&](int64_t row, uint64_t col) { return uint32_t(uint64_t(row - firstRow) * cols + col); };
  mesh.indices.reserve(size_t(g.triangles()) * 3);
  // Counter-clockwise seen from +y: (row, col), (row + 1, col), (row, col + 1).
  auto quad = [&](int64_t i, uint64_t j, bool both) {
    mesh.indices.insert(mesh.indices.end(), {vertex(i, j), vertex(i + 1, j), vertex(i, j + 1)});
    if (both)
      mesh.indices.insert(mesh.indices.end(), {vertex(i, j + 1), vertex(i + 1, j), vertex(i + 1, j + 1)});
  };
  for (uint64_t i = 0; i < g.rows; ++i)
    for (uint64_t j = 0; j < g.columns; ++j) quad(int64_t(i), j, true);
  for (uint64_t j = 0; j < g.partialQuads; ++j) quad(-1, j, true);
  if (g.extraTriangle) quad(-1, g.partialQuads, false);

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
  scene.meshes.push_back(std::move(mesh));
  GltfCamera camera;
  camera.eye = kEye;
  camera.target = kTarget;
  camera.yfov = kYfov;
  camera.znear = 0.1;
  double farthest = 0;
  for (double x : {fp.x0, fp.x1})
    for (double z : {fp.z0 - dz, fp.z1})
      farthest = std::max(farthest, glm::length(glm::dvec3(x, 0, z) - kEye));
  camera.zfar = farthest * 1.25;
  scene.camera = camera;
  return scene;
}

}  // namespace rastray::crossover
