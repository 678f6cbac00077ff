// Concave seams (raytrace/ray_offset.h, "Concave seams"): a box standing in
// a room of separate floor, wall and ceiling meshes, a point light under the
// ceiling. The reference is analytic: a visible point is shadowed exactly
// when the segment to the light passes through the box (the room's inside
// is convex, so nothing else can block). The camera sits on the room's axis
// with square pixels, so the pixels on the image diagonals see the
// floor/wall and ceiling/wall edges exactly: points on two planes at once.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "raytrace/ray_caster.h"
#include "test_scenes.h"

namespace rastray {
namespace {

const glm::dvec3 kBoxLo(-0.45, -1.0, -0.5), kBoxHi(0.05, -0.3, 0.0);  // stands on the floor
const glm::dvec3 kLight(0.35, 0.9, -0.7);

// The entry and exit of segment o + t·d, t in [0, 1], through the box
// grown by `grow` on every side; false when it misses.
bool segmentMeetsBox(const glm::dvec3& o, const glm::dvec3& d, double grow, double tMin) {
  double t0 = tMin, t1 = 1.0;
  for (int k = 0; k < 3; ++k) {
    const double lo = kBoxLo[k] - grow, hi = kBoxHi[k] + grow;
    if (d[k] == 0.0) {
      if (o[k] < lo || o[k] > hi) return false;
      continue;
    }
    double a = (lo - o[k]) / d[k], b = (hi - o[k]) / d[k];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
  }
  return t0 <= t1;
}

// Where a camera ray first meets the room or the box, in double: the box
// (slabs) if it is hit, else the room's inside (−1..1, open at z = +1).
glm::dvec3 analyticHit(const Ray& ray, bool* onBox) {
  double t0 = 0.0, t1 = 1e30;
  for (int k = 0; k < 3; ++k) {
    double a = (kBoxLo[k] - ray.origin[k]) / ray.direction[k],
           b = (kBoxHi[k] - ray.origin[k]) / ray.direction[k];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
  }
  *onBox = t0 <= t1;
  if (*onBox) return ray.origin + t0 * ray.direction;
  double t = 1e30;
  for (int k = 0; k < 3; ++k) {
    if (ray.direction[k] > 0.0 && k != 2) t = std::min(t, (1.0 - ray.origin[k]) / ray.direction[k]);
    if (ray.direction[k] < 0.0) t = std::min(t, (-1.0 - ray.origin[k]) / ray.direction[k]);
  }
  return ray.origin + t * ray.direction;
}

TEST(ShadowSeams, NoDarkLinesWhereSurfacesMeetAgainstAnAnalyticMask) {
  test::SceneBuilder b;
  const uint32_t white = b.addMaterial(test::SceneBuilder::lambert(glm::vec4(0.7f, 0.7f, 0.7f, 1.0f)));
  // Each face of the room its own mesh (a seam between two meshes), facing in.
  b.addQuad({0.0, -1.0, 0.0}, {0.0, 0.0, 1.0}, {1.0, 0.0, 0.0}, white);  // floor, up
  b.addQuad({0.0, 1.0, 0.0}, {1.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, white);   // ceiling, down
  b.addQuad({0.0, 0.0, -1.0}, {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, white);  // back, +z
  b.addQuad({-1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}, white);  // left, +x
  b.addQuad({1.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, {0.0, 1.0, 0.0}, white);   // right, −x
  const uint32_t box = b.addBox(glm::vec3(kBoxLo), glm::vec3(kBoxHi), white);
  Light light;
  light.position = kLight;
  light.intensity = 3.0f;
  b.scene().lights.push_back(light);
  b.setCamera(Projection::Perspective, {0.0, 0.0, 3.5}, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, 0.7853981633974483,
              0.1, 100.0);
  const Scene& scene = b.scene();
  for (size_t i = 0; i < 5; ++i) {
    const glm::dvec3 n = glm::normalize(faceNormal(scene, uint32_t(i), 0));
    ASSERT_GT(glm::dot(n, -glm::dvec3(scene.positions[scene.triangles[scene.instances[i].firstTriangle].x])),
              0.0)
        << "room face " << i << " must face in";
  }

  const int width = 240, height = 160;
  const Camera camera = makeCamera(scene, {}, width, height);
  RayCaster caster(scene, analyzeScene(scene));
  RayOptions options;
  caster.bind(camera, options);
  const RenderOutput lit = caster.render();
  options.shadows = false;
  caster.bind(camera, options);
  const RenderOutput unshadowed = caster.render();

  int definite = 0, shadowedAnalytic = 0, disagree = 0, seams = 0, seamsDark = 0;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const size_t i = size_t(y) * width + size_t(x);
      const Ray ray = camera.primaryRay(glm::dvec2(x + 0.5, y + 0.5));
      bool onBox = false;
      const glm::dvec3 p = analyticHit(ray, &onBox);
      // The renderer must see the same kind of surface (box edges may tie).
      if ((lit.image.instance[i] == box) != onBox || lit.image.instance[i] == kNoId) continue;
      const float without = unshadowed.image.color[i].r;
      if (!(without > 1e-4f)) continue;  // facing away from the light: nothing to shadow
      // Definite: the segment clearly misses or clearly crosses the box
      // (0.002 units either way; the box's own faces are left out by tMin).
      const glm::dvec3 d = kLight - p;
      const double tMin = onBox ? 1e-3 : 0.0;
      const bool grown = segmentMeetsBox(p, d, 2e-3, tMin), shrunk = segmentMeetsBox(p, d, -2e-3, tMin);
      if (grown != shrunk) continue;
      ++definite;
      shadowedAnalytic += shrunk;
      const bool dark = lit.image.color[i].r < 0.6f * without;
      disagree += dark != shrunk;
      // On two room planes at once (within 1e-9): the seams.
      int planes = 0;
      for (int k = 0; k < 3; ++k) planes += std::abs(std::abs(p[k]) - 1.0) < 1e-9;
      if (!onBox && planes >= 2) {
        ++seams;
        seamsDark += dark;
      }
    }
  EXPECT_GT(definite, width * height / 2);
  EXPECT_GT(shadowedAnalytic, 300);  // the box's shadow is there
  EXPECT_GT(seams, 100);             // and the diagonals do run along the room's edges
  EXPECT_EQ(seamsDark, 0) << "of " << seams << " seam pixels";
  EXPECT_EQ(disagree, 0) << "of " << definite << " pixels away from the shadow's edge";
}

}  // namespace
}  // namespace rastray
