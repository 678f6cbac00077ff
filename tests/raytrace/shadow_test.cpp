// Shadow rays: the robust origin offset (no acne far from the origin) and
// a directional light's shadow edge where geometry puts it.
#include <gtest/gtest.h>

#include "common/math_constants.h"

#include <cmath>

#include "raytrace/ray_caster.h"
#include "raytrace/ray_offset.h"
#include "test_scenes.h"

#include "tests/test_labels.h"

// Tests here render on 2 or more threads (the ThreadSanitizer stage runs them), except those marked quick.
RASTRAY_TEST_LABELS("threads");

namespace rastray {
namespace {

RASTRAY_TEST_LABELS_OF(RayOffset, MovesByUlpsAlongTheNormalAndScalesWithMagnitude, "quick");
TEST(RayOffset, MovesByUlpsAlongTheNormalAndScalesWithMagnitude) {
  const glm::vec3 n(0.0f, 1.0f, 0.0f);
  for (float y : {1.0f, -1.0f, 1e5f, -1e6f}) {
    const glm::vec3 p(3.0f, y, -7.0f);
    const glm::vec3 o = floatUlpsRayOrigin(p, n);
    EXPECT_GT(o.y, p.y) << y;  // towards +normal, whatever the sign of p
    EXPECT_EQ(o.x, p.x);
    EXPECT_EQ(o.z, p.z);
    // 256 ULPs of |y| (half-size ULPs when moving down through a power of two).
    const float ulp = std::nextafter(std::fabs(p.y), INFINITY) - std::fabs(p.y);
    EXPECT_LE(o.y - p.y, 256.0f * ulp) << y;
    EXPECT_GE(o.y - p.y, 128.0f * ulp) << y;
  }
  // Near zero: the fixed float_scale offset.
  const glm::vec3 o = floatUlpsRayOrigin(glm::vec3(0.0f), n);
  EXPECT_EQ(o.y, 1.0f / 65536.0f);
}

// A lit square 100 units wide, tilted, centred `distance` from the origin,
// seen from above, lit by a directional light at `lightDegrees` from its
// normal. Every pixel that sees it must be fully lit: a shadow ray that
// re-hits the plane (acne) darkens it.
void expectNoAcne(double distance, double lightDegrees) {
  const glm::dvec3 centre = glm::normalize(glm::dvec3(1.0, 0.7, -0.4)) * distance;
  const glm::dvec3 n = glm::normalize(glm::dvec3(0.2, 1.0, 0.3));
  const glm::dvec3 u = glm::normalize(glm::cross(n, glm::dvec3(0.0, 0.0, 1.0)));
  const glm::dvec3 v = glm::cross(n, u);  // cross(u, v) = n: front side up
  test::SceneBuilder b;
  const uint32_t grey = b.addMaterial(test::SceneBuilder::lambert(glm::vec4(0.5f, 0.5f, 0.5f, 1.0f)));
  b.addQuad(centre, 50.0 * u, 50.0 * v, grey);
  const double a = lightDegrees * kPi / 180.0;
  const glm::dvec3 toLight = std::cos(a) * n + std::sin(a) * u;
  b.addDirectionalLight(-toLight, 2.0f);
  b.setCamera(Projection::Perspective, centre + 60.0 * n + 10.0 * v, centre, v, 0.9, 1.0, 1000.0);
  const Scene& scene = b.scene();

  RayCaster caster(scene, analyzeScene(scene));
  const int size = 48;
  caster.bind(makeCamera(scene, {}, size, size), RayOptions{});
  const RenderOutput out = caster.render();
  int seen = 0, dark = 0;
  for (size_t i = 0; i < out.image.color.size(); ++i) {
    if (out.image.instance[i] != 0u) continue;
    ++seen;
    // Lambert with the hit triangle's own normal (far from the origin
    // the two float triangles are not exactly coplanar).
    const glm::dvec3 ng = glm::normalize(faceNormal(scene, 0, out.image.triangle[i]));
    const float expected = float(0.5 / kPi * 2.0 * glm::dot(ng, toLight));
    ASSERT_GT(expected, 0.0f);
    if (std::abs(out.image.color[i].r - expected) > 1e-4f * expected) ++dark;
  }
  EXPECT_GT(seen, size * size / 2) << "distance " << distance;
  EXPECT_EQ(dark, 0) << "acne at distance " << distance << ", light at " << lightDegrees << " deg: " << dark
                     << " of " << seen << " pixels not fully lit";
  EXPECT_EQ(caster.counters().get("rays.shadow"), uint64_t(seen));
}

TEST(ShadowAcne, NoneOnALitPlane1e5FromTheOrigin) {
  for (double degrees : {0.0, 45.0, 80.0, 89.0}) expectNoAcne(1e5, degrees);
}

TEST(ShadowAcne, NoneOnALitPlane1e6FromTheOrigin) {
  for (double degrees : {0.0, 45.0, 80.0, 89.0}) expectNoAcne(1e6, degrees);
}

TEST(ShadowAcne, NoneNearTheOrigin) { expectNoAcne(0.0, 60.0); }

// A ground square y = 0 (x, z ∈ [−2, 2]) under a square occluder at
// height 2 (x ∈ [−1.3, −0.55], z ∈ [−0.5, 0.45]), lit along (1, −2, 0):
// the shadow is the occluder moved by +1 in x, x ∈ [−0.3, 0.45]. An
// orthographic camera looks straight down; every pixel centre on the
// ground is lit or in shadow exactly as that geometry says.
TEST(ShadowEdge, DirectionalLightShadowLandsWhereGeometrySays) {
  test::SceneBuilder b;
  const uint32_t white = b.addMaterial(test::SceneBuilder::lambert(glm::vec4(1.0f)));
  b.addQuad({0, 0, 0}, {0, 0, 2}, {2, 0, 0}, white);  // front +y
  const double ox0 = -1.3, ox1 = -0.55, oz0 = -0.5, oz1 = 0.45, height = 2.0;
  b.addQuad({0.5 * (ox0 + ox1), height, 0.5 * (oz0 + oz1)}, {0, 0, 0.5 * (oz1 - oz0)},
            {0.5 * (ox1 - ox0), 0, 0}, white);
  const glm::dvec3 travel = glm::normalize(glm::dvec3(1.0, -2.0, 0.0));
  b.addDirectionalLight(travel, 3.0f);
  b.setCamera(Projection::Orthographic, {0, 5, 0}, {0, 0, 0}, {0, 0, -1}, 2.0, 0.5, 10.0);
  const Scene& scene = b.scene();
  const int size = 64;
  RayCaster caster(scene, analyzeScene(scene));
  caster.bind(makeCamera(scene, {}, size, size), RayOptions{});
  const RenderOutput out = caster.render();
  const double shift = height * travel.x / -travel.y;  // 1
  int shadowed = 0, lit = 0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      // Camera up is −z: image x → world x, image y → world z.
      const double wx = -2.0 + 4.0 * (x + 0.5) / size, wz = -2.0 + 4.0 * (y + 0.5) / size;
      const size_t i = out.image.index(x, y);
      const bool underOccluder = wx > ox0 && wx < ox1 && wz > oz0 && wz < oz1;
      if (underOccluder) {
        EXPECT_EQ(out.image.instance[i], 1u);
        continue;
      }
      ASSERT_EQ(out.image.instance[i], 0u) << x << "," << y;
      const bool inShadow = wx > ox0 + shift && wx < ox1 + shift && wz > oz0 && wz < oz1;
      if (inShadow) {
        ++shadowed;
        EXPECT_EQ(out.image.color[i].r, 0.0f) << "pixel " << x << "," << y << " should be in shadow";
      } else {
        ++lit;
        EXPECT_GT(out.image.color[i].r, 0.1f) << "pixel " << x << "," << y << " should be lit";
      }
    }
  EXPECT_GT(shadowed, 100);
  EXPECT_GT(lit, 1000);
}

}  // namespace
}  // namespace rastray
