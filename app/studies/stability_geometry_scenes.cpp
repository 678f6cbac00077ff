#include "app/studies/stability_geometry_scenes.h"

#include <algorithm>
#include <cmath>

#include "common/math_constants.h"

namespace rastray::stability {

namespace {

// splitmix64: a fixed, portable sequence (std:: distributions are not).
class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(seed) {}
  uint64_t next() {
    uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform() { return double(next() >> 11) * 0x1.0p-53; }  // [0, 1)
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  int pick(int n) { return int(next() % uint64_t(n)); }

 private:
  uint64_t state_;
};

glm::vec3 f3(const glm::dvec3& p) { return glm::vec3(p); }

// Adds the triangles of an axis-aligned box (outward CCW faces).
void addBox(GltfMesh* m, const glm::dvec3& lo, const glm::dvec3& hi) {
  const auto base = uint32_t(m->positions.size());
  for (int i = 0; i < 8; ++i)
    m->positions.push_back(f3({(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z}));
  // Corner index bits: x = 1, y = 2, z = 4. Each face as a CCW quad seen from outside.
  const uint32_t faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& f : faces)
    m->indices.insert(m->indices.end(),
                      {base + f[0], base + f[1], base + f[2], base + f[0], base + f[2], base + f[3]});
}

// A closed UV sphere: `segments` around, segments/2 rings, shared vertices
// (one per pole), outward CCW.
void addSphere(GltfMesh* m, const glm::dvec3& centre, double radius, int segments) {
  const int rings = segments / 2;
  const auto base = uint32_t(m->positions.size());
  m->positions.push_back(f3(centre + glm::dvec3(0, radius, 0)));  // north pole
  for (int r = 1; r < rings; ++r) {
    const double theta = kPi * r / rings;
    for (int s = 0; s < segments; ++s) {
      const double phi = 2.0 * kPi * s / segments;
      m->positions.push_back(f3(centre + radius * glm::dvec3(std::sin(theta) * std::cos(phi), std::cos(theta),
                                                             -std::sin(theta) * std::sin(phi))));
    }
  }
  m->positions.push_back(f3(centre - glm::dvec3(0, radius, 0)));  // south pole
  const uint32_t south = uint32_t(m->positions.size()) - 1;
  auto at = [&](int r, int s) { return base + 1 + uint32_t((r - 1) * segments + (s % segments)); };
  for (int s = 0; s < segments; ++s) m->indices.insert(m->indices.end(), {base, at(1, s), at(1, s + 1)});
  for (int r = 1; r + 1 < rings; ++r)
    for (int s = 0; s < segments; ++s)
      m->indices.insert(m->indices.end(),
                        {at(r, s), at(r + 1, s), at(r + 1, s + 1), at(r, s), at(r + 1, s + 1), at(r, s + 1)});
  for (int s = 0; s < segments; ++s)
    m->indices.insert(m->indices.end(), {at(rings - 1, s), south, at(rings - 1, s + 1)});
}

GltfMaterial blendHalf(glm::vec3 colour) {
  GltfMaterial m;
  m.baseColor = glm::vec4(colour, 0.5f);
  m.alphaMode = "BLEND";
  m.doubleSided = true;
  return m;
}

}  // namespace

GltfCamera PixelFrame::camera() const {
  GltfCamera c;
  c.orthographic = true;
  c.xmag = width / 2.0;
  c.ymag = height / 2.0;
  c.eye = glm::dvec3(0.0);
  c.target = glm::dvec3(0.0, 0.0, -1.0);
  c.znear = 0.5;
  c.zfar = 2.0;
  return c;
}

GltfScene subpixelScene(int sphereSegments, int dustCount, uint32_t seed) {
  GltfScene s;
  GltfMaterial grey;
  grey.baseColor = {0.7f, 0.7f, 0.7f, 1.0f};
  GltfMaterial orange;
  orange.baseColor = {1.0f, 0.5f, 0.1f, 1.0f};
  orange.doubleSided = true;
  s.materials = {grey, orange};
  GltfMesh sphere;
  addSphere(&sphere, glm::dvec3(0.0), 0.8, sphereSegments);
  s.meshes.push_back(sphere);

  GltfCamera cam;
  cam.eye = {0.0, 0.0, 3.0};
  cam.yfov = 0.8;
  cam.znear = 0.1;
  s.camera = cam;
  // One pixel at view depth d spans d · 2 tan(yfov/2) / 96 world units.
  const double pixelPerDepth = 2.0 * std::tan(cam.yfov / 2.0) / kSubpixelImageSize;
  Rng rng(seed);
  GltfMesh dust;
  dust.material = 1;
  for (int i = 0; i < dustCount; ++i) {
    const glm::dvec3 c(rng.uniform(-0.6, 0.6), rng.uniform(-0.6, 0.6), rng.uniform(0.9, 1.6));
    const double edgePixels = std::pow(10.0, rng.uniform(-3.0, 0.0));
    const double size = edgePixels * (cam.eye.z - c.z) * pixelPerDepth;
    // Three corners at random directions `size`/√3 from the centre: edges
    // about `size` long, any orientation (edge-on to the camera included).
    const auto base = uint32_t(dust.positions.size());
    for (int k = 0; k < 3; ++k) {
      glm::dvec3 d(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
      if (glm::length(d) < 1e-3) d = glm::dvec3(1, 0, 0);
      dust.positions.push_back(f3(c + glm::normalize(d) * (size / std::sqrt(3.0))));
    }
    dust.indices.insert(dust.indices.end(), {base, base + 1, base + 2});
  }
  s.meshes.push_back(dust);
  return s;
}

GltfScene sliverScene(SliverLayout* layout) {
  const SliverLayout& L = *layout;
  GltfScene s;
  s.materials = {blendHalf({1.0f, 0.6f, 0.2f}), blendHalf({0.2f, 0.6f, 1.0f})};
  s.camera = L.frame.camera();

  // The fan: every 15°, the multiples of 45° at exact lattice points (axes
  // and diagonals through sample positions), with sliver clusters of apex
  // angles 1e-2 .. minAngle on both sides of each.
  std::vector<glm::dvec2> boundary;
  for (int k = 0; k < 24; ++k) {
    const double theta = kPi * k / 12.0;
    const bool lattice = k % 3 == 0;
    const double r =
        lattice && (k / 3) % 2 == 1 ? std::round(L.radius / std::sqrt(2.0)) * std::sqrt(2.0) : L.radius;
    auto at = [&](double angle) { return L.fanCentre + r * glm::dvec2(std::cos(angle), std::sin(angle)); };
    std::vector<double> offsets;  // cumulative apex angles of the cluster's slivers
    if (lattice)
      for (double a = L.minAngle, sum = 0.0; a <= 1e-2 * 1.0000001; a *= 10.0) offsets.push_back(sum += a);
    for (auto it = offsets.rbegin(); it != offsets.rend(); ++it) boundary.push_back(at(theta - *it));
    if (lattice) {
      const glm::dvec2 dir = k % 6 == 0
                                 ? glm::dvec2(std::round(std::cos(theta)), std::round(std::sin(theta)))
                                 : glm::dvec2(std::cos(theta) > 0 ? 1 : -1, std::sin(theta) > 0 ? 1 : -1);
      const double steps = k % 6 == 0 ? L.radius : std::round(L.radius / std::sqrt(2.0));
      boundary.push_back(L.fanCentre + steps * dir);  // exact: integer steps from a pixel centre
    } else {
      boundary.push_back(at(theta));
    }
    for (double o : offsets) boundary.push_back(at(theta + o));
  }
  layout->fanBoundary.clear();
  GltfMesh fan;
  fan.positions.push_back(glm::vec3(float(L.fanCentre.x), float(L.fanCentre.y), -1.0f));
  for (const glm::dvec2& p : boundary) {
    const glm::vec3 q(float(p.x), float(p.y), -1.0f);
    fan.positions.push_back(q);
    layout->fanBoundary.push_back({q.x, q.y});  // as stored (float)
  }
  const auto n = uint32_t(boundary.size());
  for (uint32_t i = 0; i < n; ++i) fan.indices.insert(fan.indices.end(), {0, 1 + i, 1 + (i + 1) % n});
  s.meshes.push_back(fan);

  // The bands: rows of samples at y = 1.5, 0.5, −0.5 (near the camera, so
  // a height of 2e-6 survives the rounding to float), x from 4.5 to 76.5.
  const double heights[3] = {2e-2, 2e-4, 2e-6};
  for (int b = 0; b < 3; ++b) {
    const double y = 1.5 - b, h = heights[b];
    GltfMesh band;
    band.material = 1;
    const int columns = 37;  // vertices 2 pixels apart: x = 4.5 + 2i
    for (int i = 0; i < columns; ++i) {
      const float x = float(4.5 + 2.0 * i);
      band.positions.push_back({x, float(y + h / 2), -1.0f});
      band.positions.push_back({x, float(y - h / 2), -1.0f});
    }
    for (uint32_t i = 0; i + 1 < uint32_t(columns); ++i) {
      const uint32_t t0 = 2 * i, b0 = 2 * i + 1, t1 = 2 * i + 2, b1 = 2 * i + 3;
      // The diagonal t0–b1 crosses the row at x = 5.5 + 2i: a sample.
      band.indices.insert(band.indices.end(), {t0, b0, b1, t0, b1, t1});
    }
    s.meshes.push_back(band);
  }
  return s;
}

GltfScene pixelAlignedScene(TilingLayout* layout, uint32_t seed) {
  TilingLayout& L = *layout;
  GltfScene s;
  s.materials = {blendHalf({0.3f, 0.9f, 0.4f})};
  s.camera = L.frame.camera();
  const int nx = int(std::lround((L.hi.x - L.lo.x) / L.cell)),
            ny = int(std::lround((L.hi.y - L.lo.y) / L.cell));
  Rng rng(seed);
  auto jitter = [&] { return 0.5 * (rng.pick(3) - 1); };  // −1/2, 0, +1/2
  std::vector<glm::dvec2> nodes;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      glm::dvec2 p = L.lo + L.cell * glm::dvec2(i, j);
      const bool edgeX = i == 0 || i == nx, edgeY = j == 0 || j == ny;
      // Boundary nodes move only along the boundary, corners not at all:
      // the outline stays the rectangle.
      const double jx = jitter(), jy = jitter();
      if (!edgeX) p.x += jx;
      if (!edgeY) p.y += jy;
      nodes.push_back(p);
    }
  GltfMesh m;
  for (const glm::dvec2& p : nodes) m.positions.push_back({float(p.x), float(p.y), -1.0f});
  L.triangles.clear();
  auto node = [&](int i, int j) { return uint32_t(j * (nx + 1) + i); };
  auto add = [&](uint32_t a, uint32_t b, uint32_t c) {
    // Alternate triangles wound clockwise: the fill rule must not depend
    // on the winding.
    if (L.triangles.size() % 2 == 1) std::swap(b, c);
    m.indices.insert(m.indices.end(), {a, b, c});
    L.triangles.push_back({nodes[a], nodes[b], nodes[c]});
  };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const uint32_t a = node(i, j), b = node(i + 1, j), c = node(i + 1, j + 1), d = node(i, j + 1);
      if ((i + j) % 2 == 0) {
        add(a, b, c);
        add(a, c, d);
      } else {
        add(a, b, d);
        add(b, c, d);
      }
    }
  s.meshes.push_back(m);
  return s;
}

GltfScene grazingScene(bool textured, double angleDegrees, double yfovDegrees) {
  GltfScene s;
  GltfMaterial plane;
  plane.baseColor = {0.8f, 0.8f, 0.8f, 1.0f};
  if (textured) {
    GltfTexture checker;
    checker.width = checker.height = 16;
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) {
        const unsigned char v = ((x / 8) + (y / 8)) % 2 ? 230 : 40;
        checker.rgb.insert(checker.rgb.end(), {v, v, v});
      }
    s.textures.push_back(checker);
    plane.baseColor = glm::vec4(1.0f);
    plane.baseColorTexture = 0;
  }
  s.materials.push_back(plane);
  GltfMesh p;
  const double xs = 1e3, zNear = 10.0, zFar = -1e5;
  p.positions = {{float(-xs), 0.0f, float(zNear)},
                 {float(xs), 0.0f, float(zNear)},
                 {float(xs), 0.0f, float(zFar)},
                 {float(-xs), 0.0f, float(zFar)}};
  p.indices = {0, 1, 2, 0, 2, 3};
  p.normals.assign(4, glm::vec3(0.0f, 1.0f, 0.0f));
  if (textured)  // one checker square (half a texture repeat) per unit
    for (const glm::vec3& q : p.positions) p.texcoords.push_back({0.5f * q.x, 0.5f * q.z});
  s.meshes.push_back(p);

  const double a = angleDegrees * kPi / 180.0;
  GltfCamera cam;
  cam.eye = {0.0, 1.0, 0.0};
  cam.target = cam.eye + glm::dvec3(0.0, -std::cos(a), -std::sin(a));
  cam.yfov = yfovDegrees * kPi / 180.0;
  cam.znear = 0.01;
  s.camera = cam;

  if (textured) {
    GltfLight sun;  // straight down, so the checker shows (an eye light would give C·|n·d| ≈ 0.002)
    sun.direction = {0.0, -1.0, 0.0};
    s.lights = {sun};
  } else {
    // A low wall along the view, left of it, and two lights from the left:
    // one 45° from the normal (a shadow band 0.5 wide beside the wall),
    // one at the view's angle from the normal (grazing light, made bright
    // enough, intensity × cos 89.9° ≈ 0.7, for its acne and its shadow,
    // 286 units wide, to show).
    GltfMaterial wall;
    wall.baseColor = {0.9f, 0.3f, 0.2f, 1.0f};
    s.materials.push_back(wall);
    GltfMesh b;
    b.material = 1;
    addBox(&b, {-1.5, 0.0, -2e4}, {-1.3, 0.5, -50.0});
    s.meshes.push_back(b);
    GltfLight high, grazing;
    high.direction = {std::sin(kPi / 4), -std::cos(kPi / 4), 0.0};
    grazing.direction = {std::sin(a), -std::cos(a), 0.0};
    high.intensity = 1.5f;
    grazing.intensity = float(0.7 / std::cos(a));
    s.lights = {high, grazing};
  }
  return s;
}

GltfScene scaledScene(double scale) {
  GltfScene s;
  GltfMaterial floor, box, ball;
  floor.baseColor = {0.8f, 0.8f, 0.8f, 1.0f};
  box.baseColor = {0.9f, 0.3f, 0.2f, 1.0f};
  ball.baseColor = {0.2f, 0.5f, 0.9f, 1.0f};
  s.materials = {floor, box, ball};
  auto scaled = [&](GltfMesh m) {
    for (glm::vec3& p : m.positions) p = glm::vec3(glm::dvec3(p) * scale);
    return m;
  };
  GltfMesh f;  // 8×8 floor in 4×4 quads
  for (int j = 0; j <= 4; ++j)
    for (int i = 0; i <= 4; ++i) f.positions.push_back({-4.0f + 2.0f * i, 0.0f, -4.0f + 2.0f * j});
  for (uint32_t j = 0; j < 4; ++j)
    for (uint32_t i = 0; i < 4; ++i) {
      const uint32_t a = j * 5 + i, b = a + 1, c = a + 6, d = a + 5;
      f.indices.insert(f.indices.end(), {a, d, c, a, c, b});  // CCW from above (+y)
    }
  GltfMesh b;
  b.material = 1;
  addBox(&b, {-2.1, 0.0, -0.1}, {-0.9, 1.2, 1.1});
  GltfMesh sphere;
  sphere.material = 2;
  addSphere(&sphere, {1.2, 0.8, -0.5}, 0.8, 32);
  // Build in unit coordinates (float), then scale in double: every scale
  // rounds the same unit positions once.
  for (GltfMesh* m : {&f, &b, &sphere}) {
    s.meshes.push_back(scaled(*m));
  }
  GltfCamera cam;
  cam.eye = glm::dvec3(3.5, 3.0, 5.5) * scale;
  cam.target = glm::dvec3(0.0, 0.5, 0.0) * scale;
  cam.yfov = 0.7;
  cam.znear = 0.05 * scale;
  s.camera = cam;
  GltfLight sun;
  sun.direction = {-0.4, -1.0, -0.3};
  s.lights = {sun};
  return s;
}

}  // namespace rastray::stability
