#include "app/studies/stability_far_scene.h"

#include <cmath>

#include "common/math_constants.h"

namespace rastray::stability {

namespace {

void addQuad(GltfMesh& m, const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& p2,
             const glm::dvec3& p3, const glm::dvec3& offset, bool baked) {
  const uint32_t base = uint32_t(m.positions.size());
  for (const glm::dvec3& p : {p0, p1, p2, p3}) m.positions.push_back(glm::vec3(baked ? p + offset : p));
  for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) m.indices.push_back(base + i);
}

GltfMesh meshAt(const glm::dvec3& offset, bool baked, int material) {
  GltfMesh m;
  m.material = material;
  if (!baked) m.translation = offset;
  return m;
}

GltfMesh box(const glm::dvec3& lo, const glm::dvec3& hi, const glm::dvec3& offset, bool baked, int material) {
  GltfMesh m = meshAt(offset, baked, material);
  const auto c = [&](int x, int y, int z) {
    return glm::dvec3(x ? hi.x : lo.x, y ? hi.y : lo.y, z ? hi.z : lo.z);
  };
  // Each face counter-clockwise seen from outside.
  addQuad(m, c(0, 0, 1), c(1, 0, 1), c(1, 1, 1), c(0, 1, 1), offset, baked);  // +z
  addQuad(m, c(1, 0, 0), c(0, 0, 0), c(0, 1, 0), c(1, 1, 0), offset, baked);  // -z
  addQuad(m, c(1, 0, 1), c(1, 0, 0), c(1, 1, 0), c(1, 1, 1), offset, baked);  // +x
  addQuad(m, c(0, 0, 0), c(0, 0, 1), c(0, 1, 1), c(0, 1, 0), offset, baked);  // -x
  addQuad(m, c(0, 1, 1), c(1, 1, 1), c(1, 1, 0), c(0, 1, 0), offset, baked);  // +y
  addQuad(m, c(0, 0, 0), c(1, 0, 0), c(1, 0, 1), c(0, 0, 1), offset, baked);  // -y
  return m;
}

GltfMesh sphere(const glm::dvec3& centre, double radius, const glm::dvec3& offset, bool baked, int material) {
  GltfMesh m = meshAt(offset, baked, material);
  constexpr int kSegments = 24, kRings = 12;
  for (int i = 0; i <= kRings; ++i)
    for (int j = 0; j <= kSegments; ++j) {
      const double theta = kPi * i / kRings, phi = 2.0 * kPi * j / kSegments;
      const glm::dvec3 p = centre + radius * glm::dvec3(std::sin(theta) * std::cos(phi), std::cos(theta),
                                                        -std::sin(theta) * std::sin(phi));
      m.positions.push_back(glm::vec3(baked ? p + offset : p));
    }
  const auto at = [](int i, int j) { return uint32_t(i * (kSegments + 1) + j); };
  for (int i = 0; i < kRings; ++i)
    for (int j = 0; j < kSegments; ++j) {
      // Counter-clockwise seen from outside; the pole rows have one triangle.
      if (i > 0) m.indices.insert(m.indices.end(), {at(i, j), at(i + 1, j), at(i, j + 1)});
      if (i + 1 < kRings) m.indices.insert(m.indices.end(), {at(i, j + 1), at(i + 1, j), at(i + 1, j + 1)});
    }
  return m;
}

}  // namespace

GltfScene farScene(const FarSceneLayout& layout) {
  const glm::dvec3& offset = layout.offset;
  const bool baked = layout.baked;
  const double lift = layout.lift;
  GltfScene s;
  GltfMaterial floor, boxMaterial, sphereMaterial;
  floor.baseColor = {0.8f, 0.8f, 0.8f, 1.0f};
  boxMaterial.baseColor = {0.8f, 0.3f, 0.2f, 1.0f};
  sphereMaterial.baseColor = {0.3f, 0.5f, 0.9f, 1.0f};
  s.materials = {floor, boxMaterial, sphereMaterial};

  GltfMesh floorMesh = meshAt(offset, baked, 0);
  addQuad(floorMesh, {-6, 0, 6}, {6, 0, 6}, {6, 0, -6}, {-6, 0, -6}, offset, baked);
  s.meshes.push_back(floorMesh);
  s.meshes.push_back(box({-3.0, lift, -0.75}, {-1.5, 1.5 + lift, 0.75}, offset, baked, 1));
  s.meshes.push_back(sphere({1.5, 1.5 + lift, 0.0}, 1.5, offset, baked, 2));
  if (layout.mirror) {
    GltfMaterial mirror;
    mirror.baseColor = {0.9f, 0.9f, 0.9f, 1.0f};
    mirror.metallic = 1.0f;
    mirror.roughness = 0.0f;
    s.materials.push_back(mirror);
    GltfMesh mirrorMesh = meshAt(offset, baked, 3);
    addQuad(mirrorMesh, {-4, 0.2, -3}, {4, 0.2, -3}, {4, 3.5, -3}, {-4, 3.5, -3}, offset, baked);
    s.meshes.push_back(mirrorMesh);
  }

  GltfCamera camera;
  camera.eye = offset + glm::dvec3(0.0, 4.0, 8.0);
  camera.target = offset + glm::dvec3(0.0, 0.8, 0.0);
  camera.yfov = 0.8;
  camera.znear = 0.1;
  camera.zfar = 100.0;
  s.camera = camera;
  GltfLight light;
  light.direction = glm::normalize(glm::dvec3(-0.5, -1.0, -0.3));
  light.intensity = 3.0f;
  s.lights = {light};
  return s;
}

}  // namespace rastray::stability
