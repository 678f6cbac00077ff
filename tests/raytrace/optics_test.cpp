// Snell refraction and total internal reflection through the ray caster's
// ray tree: glass slab lateral shift, TIR just past the critical angle.
// The optics functions alone are tested in tests/common/optics_test.cpp.
#include <gtest/gtest.h>

#include <cmath>

#include "common/math_constants.h"
#include "raytrace/ray_caster.h"
#include "test_scenes.h"

#include "tests/test_labels.h"

// Every test here renders on 2 or more threads (the ThreadSanitizer stage runs them).
RASTRAY_TEST_LABELS("threads");

namespace rastray {
namespace {

// A closed glass slab z ∈ [−d, 0] (large in x and y) seen by an
// orthographic camera at incidence θi: the ray that leaves through the
// back face is parallel to the primary ray and shifted sideways by
// d·sin(θi − θt)/cos θt.
TEST(RayTree, GlassSlabExitIsParallelWithTheAnalyticShift) {
  const double d = 0.5, ior = 1.5;
  for (double degrees : {0.0, 20.0, 45.0, 70.0}) {
    const double thetaI = degrees * kPi / 180.0;
    test::SceneBuilder b;
    const uint32_t glass = b.addMaterial(test::SceneBuilder::glass(float(ior)));
    b.addBox({-4.0f, -4.0f, float(-d)}, {4.0f, 4.0f, 0.0f}, glass);
    const glm::dvec3 dir(std::sin(thetaI), 0.0, -std::cos(thetaI));
    const glm::dvec3 target(0.1, 0.05, 0.0);
    b.setCamera(Projection::Orthographic, target - 2.0 * dir, target, {0.0, 1.0, 0.0}, 0.25, 0.0, 10.0);
    const Scene& scene = b.scene();
    const SceneAnalysis analysis = analyzeScene(scene);
    RayCaster caster(scene, analysis);
    caster.bind(makeCamera(scene, {}, 9, 9), RayOptions{});
    const std::vector<RayRecord> tree = caster.traceDebugPixel({4, 4});
    ASSERT_FALSE(tree.empty());
    const RayRecord& primary = tree.front();
    ASSERT_EQ(primary.kind, RayKind::Primary);
    ASSERT_EQ(primary.instance, 0u);
    const RayRecord* exit = nullptr;
    for (const RayRecord& r : tree)
      if (r.kind == RayKind::Refraction && r.depth == 2) {
        exit = &r;
        break;
      }
    ASSERT_NE(exit, nullptr) << "no refraction ray out of the slab at " << degrees << " deg";
    // Parallel to the entry.
    EXPECT_LT(glm::length(glm::cross(exit->direction, primary.direction)), 1e-9) << degrees << " deg";
    EXPECT_GT(glm::dot(exit->direction, primary.direction), 0.0);
    // Lateral shift: the distance between the two lines.
    const double thetaT = std::asin(std::sin(thetaI) / ior);
    const double expected = d * std::sin(thetaI - thetaT) / std::cos(thetaT);
    const double shift = glm::length(glm::cross(exit->origin - primary.origin, primary.direction));
    EXPECT_NEAR(shift, expected, 5e-5) << degrees << " deg";
    // The exit ray starts on the back face (z = −d), just outside it.
    EXPECT_NEAR(exit->origin.z, -d, 5e-5);
    EXPECT_LT(exit->origin.z, -d);
  }
}

// A ray inside glass meets the glass/air boundary (the back of a glass
// quad, so it is leaving): past the critical angle only a reflection ray
// is traced; just before it, a refraction ray too, obeying Snell's law.
TEST(RayTree, TotalInternalReflectionAtTheCriticalAngle) {
  const double ior = 1.5;
  const double critical = std::asin(1.0 / ior);
  for (double delta : {-0.5, 0.5}) {
    const double thetaI = critical + delta * kPi / 180.0;
    test::SceneBuilder b;
    const uint32_t glass = b.addMaterial(test::SceneBuilder::glass(float(ior)));
    // Front faces −z: the camera (looking down −z) sees its back.
    b.addQuad({0.0, 0.0, 0.0}, {0.0, 3.0, 0.0}, {3.0, 0.0, 0.0}, glass);
    const glm::dvec3 dir(std::sin(thetaI), 0.0, -std::cos(thetaI));
    b.setCamera(Projection::Orthographic, -2.0 * dir, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, 0.25, 0.0, 10.0);
    const Scene& scene = b.scene();
    RayCaster caster(scene, analyzeScene(scene));
    caster.bind(makeCamera(scene, {}, 5, 5), RayOptions{});
    const std::vector<RayRecord> tree = caster.traceDebugPixel({2, 2});
    ASSERT_FALSE(tree.empty());
    ASSERT_EQ(tree.front().instance, 0u);
    int reflections = 0, refractions = 0;
    for (const RayRecord& r : tree) {
      if (r.depth != 1) continue;
      if (r.kind == RayKind::Reflection) ++reflections;
      if (r.kind == RayKind::Refraction) {
        ++refractions;
        const double sinT = std::sqrt(r.direction.x * r.direction.x + r.direction.y * r.direction.y);
        EXPECT_NEAR(sinT, ior * std::sin(thetaI), 1e-9);
        EXPECT_LT(r.direction.z, 0.0);  // out through the boundary
      }
    }
    EXPECT_EQ(reflections, 1) << "delta " << delta;
    EXPECT_EQ(refractions, delta > 0.0 ? 0 : 1) << "delta " << delta;
  }
}

}  // namespace
}  // namespace rastray
