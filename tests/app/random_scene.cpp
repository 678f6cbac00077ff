#include "random_scene.h"

#include <cmath>

#include "common/math_constants.h"

namespace rastray::test {

uint64_t SceneRandom::next() {
  uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

double SceneRandom::uniform(double lo, double hi) {
  return lo + (hi - lo) * double(next() >> 11) * 0x1.0p-53;
}

int SceneRandom::below(int n) { return int(next() % uint64_t(n)); }

glm::vec3 SceneRandom::point(double extent) {
  return glm::vec3(glm::dvec3(uniform(-extent, extent), uniform(-extent, extent), uniform(-extent, extent)));
}

glm::dvec3 SceneRandom::direction() {
  for (;;) {
    const glm::dvec3 d(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1));
    const double l = glm::length(d);
    if (l > 0.1 && l <= 1.0) return d / l;
  }
}

namespace {

// A random rotation (orthonormal columns) for placing boxes and fans.
glm::dmat3 randomRotation(SceneRandom& rng) {
  const glm::dvec3 a = rng.direction();
  glm::dvec3 b = glm::normalize(glm::cross(a, rng.direction()));
  return glm::dmat3(a, b, glm::cross(a, b));
}

void addTriangle(GltfMesh* m, glm::vec3 a, glm::vec3 b, glm::vec3 c) {
  const uint32_t base = uint32_t(m->positions.size());
  m->positions.insert(m->positions.end(), {a, b, c});
  m->indices.insert(m->indices.end(), {base, base + 1, base + 2});
}

GltfMesh randomTriangles(SceneRandom& rng) {
  GltfMesh m;
  const int n = 1 + rng.below(8);
  for (int i = 0; i < n; ++i) {
    const glm::vec3 c = rng.point(1.0);
    const float size = float(rng.uniform(0.05, 1.2));
    addTriangle(&m, c + size * rng.point(1.0), c + size * rng.point(1.0), c + size * rng.point(1.0));
  }
  return m;
}

GltfMesh box(const glm::dvec3& centre, const glm::dvec3& half, const glm::dmat3& rotation) {
  GltfMesh m;
  for (int i = 0; i < 8; ++i) {
    const glm::dvec3 corner(i & 1 ? half.x : -half.x, i & 2 ? half.y : -half.y, i & 4 ? half.z : -half.z);
    m.positions.emplace_back(centre + rotation * corner);
  }
  // Outward-facing when the rotation is proper (it is: det = +1).
  m.indices = {0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4,
               2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5};
  return m;
}

// Triangles around one shared centre vertex: every ray near the centre
// or a spoke crosses a shared vertex or edge.
GltfMesh fan(SceneRandom& rng) {
  GltfMesh m;
  const glm::dmat3 r = randomRotation(rng);
  const glm::dvec3 c = glm::dvec3(rng.point(0.8));
  const double radius = rng.uniform(0.2, 1.2), bump = rng.chance(0.5) ? rng.uniform(-0.3, 0.3) : 0.0;
  const int k = 3 + rng.below(10);
  m.positions.emplace_back(c + r * glm::dvec3(0.0, 0.0, bump));
  for (int i = 0; i < k; ++i) {
    const double a = 2.0 * kPi * i / k;
    m.positions.emplace_back(c + r * glm::dvec3(radius * std::cos(a), radius * std::sin(a), 0.0));
  }
  for (int i = 0; i < k; ++i)
    m.indices.insert(m.indices.end(), {0u, uint32_t(1 + i), uint32_t(1 + (i + 1) % k)});
  return m;
}

// A height field: a grid of shared edges and vertices.
GltfMesh grid(SceneRandom& rng) {
  GltfMesh m;
  const glm::dmat3 r = randomRotation(rng);
  const glm::dvec3 c = glm::dvec3(rng.point(0.5));
  const int n = 2 + rng.below(6);
  const double size = rng.uniform(0.5, 2.0), rough = rng.uniform(0.0, 0.3);
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x)
      m.positions.emplace_back(c + r * glm::dvec3(size * (double(x) / n - 0.5), size * (double(y) / n - 0.5),
                                                  rng.uniform(-rough, rough)));
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const uint32_t a = uint32_t(y * (n + 1) + x), b = a + 1, d = a + uint32_t(n + 1), e = d + 1;
      m.indices.insert(m.indices.end(), {a, b, e, a, e, d});
    }
  return m;
}

// The same triangles listed twice (and sometimes a third time reversed, as
// exporters write double-sided sheets).
GltfMesh duplicated(SceneRandom& rng) {
  GltfMesh m = rng.chance(0.5) ? grid(rng) : randomTriangles(rng);
  const std::vector<uint32_t> once = m.indices;
  m.indices.insert(m.indices.end(), once.begin(), once.end());
  if (rng.chance(0.5))
    for (size_t i = 0; i < once.size(); i += 3)
      m.indices.insert(m.indices.end(), {once[i], once[i + 2], once[i + 1]});
  return m;
}

// Two overlapping triangles in one plane: a depth tie wherever they overlap.
GltfMesh coplanarPair(SceneRandom& rng) {
  GltfMesh m;
  const glm::dmat3 r = randomRotation(rng);
  const glm::dvec3 c = glm::dvec3(rng.point(0.7));
  for (int t = 0; t < 2; ++t) {
    glm::vec3 p[3];
    for (glm::vec3& q : p)
      q = glm::vec3(c + r * glm::dvec3(rng.uniform(-0.7, 0.7), rng.uniform(-0.7, 0.7), 0.0));
    addTriangle(&m, p[0], p[1], p[2]);
  }
  return m;
}

GltfMaterial randomMaterial(SceneRandom& rng, RandomSceneSummary* s) {
  GltfMaterial m;
  m.baseColor = glm::vec4(rng.uniform(0.1, 1.0), rng.uniform(0.1, 1.0), rng.uniform(0.1, 1.0), 1.0);
  m.doubleSided = rng.chance(0.5);
  const double kind = rng.uniform();
  if (kind < 0.25) {
    m.alphaMode = "BLEND";
    m.baseColor.a = float(rng.uniform(0.1, 0.9));
    ++s->blend;
  } else if (kind < 0.35) {
    m.alphaMode = "MASK";  // uniform alpha: the whole surface is there or not
    m.baseColor.a = float(rng.uniform(0.0, 1.0));
    m.alphaCutoff = float(rng.uniform(0.2, 0.8));
    ++s->mask;
  } else if (kind < 0.45) {
    m.transmission = 1.0f;
    m.ior = float(rng.uniform(1.1, 2.0));
    ++s->glass;
  } else if (kind < 0.55) {
    m.metallic = 1.0f;
    m.roughness = float(rng.uniform(0.0, 0.5));
  }
  return m;
}

}  // namespace

GltfScene randomScene(uint64_t seed, RandomSceneSummary* summary) {
  SceneRandom rng(seed);
  RandomSceneSummary local;
  RandomSceneSummary& s = summary ? *summary : local;
  s = {};
  GltfScene scene;
  const int objects = 1 + rng.below(6);
  for (int i = 0; i < objects; ++i) {
    GltfMesh m;
    switch (rng.below(6)) {
      case 0:
        m = randomTriangles(rng);
        break;
      case 1:
        m = box(glm::dvec3(rng.point(0.8)),
                glm::dvec3(rng.uniform(0.1, 0.8), rng.uniform(0.1, 0.8), rng.uniform(0.1, 0.8)),
                randomRotation(rng));
        break;
      case 2:
        m = fan(rng);
        break;
      case 3:
        m = grid(rng);
        break;
      case 4:
        m = duplicated(rng);
        break;
      default:
        m = coplanarPair(rng);
        break;
    }
    scene.materials.push_back(randomMaterial(rng, &s));
    m.material = int(scene.materials.size() - 1);
    s.triangles += int(m.indices.size() / 3);
    scene.meshes.push_back(std::move(m));
  }
  s.objects = objects;

  GltfCamera camera;
  camera.target = glm::dvec3(rng.point(0.5));
  if (rng.chance(0.15)) {
    // Inside geometry: a box around the eye (single- or double-sided).
    s.cameraInside = true;
    camera.eye = glm::dvec3(rng.point(0.5));
    GltfMesh room = box(camera.eye, glm::dvec3(rng.uniform(0.3, 1.5)), randomRotation(rng));
    scene.materials.push_back(randomMaterial(rng, &s));
    room.material = int(scene.materials.size() - 1);
    scene.meshes.push_back(std::move(room));
  } else {
    camera.eye = camera.target + rng.direction() * rng.uniform(1.5, 5.0);
  }
  if (glm::length(camera.target - camera.eye) < 1e-3) camera.target = camera.eye + glm::dvec3(0.0, 0.0, -1.0);
  camera.yfov = rng.uniform(0.3, 1.6);
  // Near planes from tiny to ones that cut through the scene.
  const double nears[] = {1e-3, 0.05, 0.3, 1.0, 2.0};
  camera.znear = nears[rng.below(5)];
  if (rng.chance(0.3)) camera.zfar = camera.znear + rng.uniform(0.5, 6.0);
  scene.camera = camera;
  if (rng.chance(0.3)) {
    GltfLight light;
    light.direction = rng.direction();
    scene.lights.push_back(light);
    s.lights = 1;
  }
  return scene;
}

}  // namespace rastray::test
