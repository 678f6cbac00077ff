// The scene model's own operations (common/scene.h): normals, the
// degenerate-triangle test, rebasing to a render origin, names.
#include "common/scene.h"

#include <cmath>
#include <limits>

#include "common/error.h"

namespace rastray {

glm::dvec3 faceNormal(const Scene& scene, uint32_t instance, uint32_t tri) {
  const glm::uvec3 t = scene.triangle(instance, tri);
  const glm::dvec3 a(scene.positions[t.x]), b(scene.positions[t.y]), c(scene.positions[t.z]);
  return glm::cross(b - a, c - a);
}

TextureTransform::TextureTransform(glm::dvec2 offset_, double rotation, glm::dvec2 scale)
    : offset(offset_), identity(offset_ == glm::dvec2(0.0) && rotation == 0.0 && scale == glm::dvec2(1.0)) {
  const double c = std::cos(rotation), s = std::sin(rotation);
  // Columns (c, −s) and (s, c): u' = c·u + s·v, v' = −s·u + c·v; then scale first.
  linear = glm::dmat2(c, -s, s, c) * glm::dmat2(scale.x, 0.0, 0.0, scale.y);
}

bool isDegenerate(const Scene& scene, size_t storedTriangle) {
  const glm::uvec3 t = scene.triangles[storedTriangle];
  const glm::dvec3 a(scene.positions[t.x]), b(scene.positions[t.y]), c(scene.positions[t.z]);
  return glm::cross(b - a, c - a) == glm::dvec3(0.0);
}

void rebaseScene(Scene& scene, const glm::dvec3& origin) {
  RASTRAY_CHECK(scene.worldPositions.size() == scene.positions.size(), "rebaseScene needs worldPositions");
  if (!(std::isfinite(origin.x) && std::isfinite(origin.y) && std::isfinite(origin.z)))
    throw InputError("command line", "--origin", "the render origin is not finite");
  const glm::dvec3 shift = origin - scene.origin;
  constexpr double kFloatMax = std::numeric_limits<float>::max();
  Bounds bounds;
  for (size_t i = 0; i < scene.positions.size(); ++i) {
    const glm::dvec3 p = scene.worldPositions[i] - origin;
    if (!(std::abs(p.x) <= kFloatMax && std::abs(p.y) <= kFloatMax && std::abs(p.z) <= kFloatMax))
      throw InputError(scene.path, "vertex " + std::to_string(i),
                       "does not fit a float relative to the render origin");
    scene.positions[i] = glm::vec3(p);
    bounds.extend(glm::dvec3(scene.positions[i]));
  }
  scene.bounds = bounds;
  for (Light& light : scene.lights) light.position -= shift;
  if (scene.camera) scene.camera->worldFromCamera[3] -= glm::dvec4(shift, 0.0);
  for (CameraModel& camera : scene.cameras) camera.worldFromCamera[3] -= glm::dvec4(shift, 0.0);
  for (Instance& inst : scene.instances) {
    inst.degenerateCount = 0;
    for (uint32_t t = 0; t < inst.triangleCount; ++t)
      if (isDegenerate(scene, inst.firstTriangle + t)) ++inst.degenerateCount;
  }
  scene.origin = origin;
}

std::string IgnoredFeature::describe() const {
  const std::string plural = count == 1 ? "" : "s";
  if (unit.empty()) return std::to_string(count) + " " + feature + plural;
  return feature + " on " + std::to_string(count) + " " + unit + plural;
}

const char* toString(AlphaMode mode) {
  switch (mode) {
    case AlphaMode::Opaque:
      return "OPAQUE";
    case AlphaMode::Mask:
      return "MASK";
    case AlphaMode::Blend:
      return "BLEND";
  }
  return "?";
}

const char* toString(LightType type) {
  switch (type) {
    case LightType::Point:
      return "point";
    case LightType::Spot:
      return "spot";
    case LightType::Directional:
      return "directional";
  }
  return "?";
}

const char* toString(Projection projection) {
  return projection == Projection::Perspective ? "perspective" : "orthographic";
}

}  // namespace rastray
