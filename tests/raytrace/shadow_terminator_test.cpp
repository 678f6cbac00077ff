// The shadow terminator on a low-poly smooth sphere, against an analytic
// mask of the smooth sphere it stands for (raytrace/ray_offset.h, "The
// shadow terminator"): where the smooth sphere faces the light, no pixel
// may be shadowed. The reference is the sphere's equation, not rastray.
#include <gtest/gtest.h>

#include <cmath>

#include "common/math_constants.h"
#include "raytrace/ray_caster.h"
#include "raytrace/ray_offset.h"
#include "test_scenes.h"

namespace rastray {
namespace {

// A UV sphere of radius 1 at the origin: `segments` around, `rings` from
// pole to pole, vertices on the sphere, normals the sphere's (authored).
void addSmoothSphere(test::SceneBuilder& b, int segments, int rings, uint32_t material) {
  std::vector<glm::vec3> p;
  std::vector<glm::uvec3> t;
  for (int r = 0; r <= rings; ++r)
    for (int s = 0; s <= segments; ++s) {
      const double theta = kPi * r / rings, phi = 2.0 * kPi * s / segments;
      p.emplace_back(std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi));
    }
  const auto at = [&](int r, int s) { return uint32_t(r * (segments + 1) + s); };
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      // CCW seen from outside; the pole rows have one triangle each.
      if (r > 0) t.emplace_back(at(r, s), at(r + 1, s), at(r, s + 1));
      if (r + 1 < rings) t.emplace_back(at(r, s + 1), at(r + 1, s), at(r + 1, s + 1));
    }
  const uint32_t instance = b.addMesh(p, t, material);
  Scene& scene = b.scene();
  Instance& inst = scene.instances[instance];
  inst.normals = NormalSource::Authored;
  for (uint32_t i = 0; i < inst.vertexCount; ++i)
    scene.normals[inst.firstVertex + i] = glm::normalize(scene.positions[inst.firstVertex + i]);
}

struct TerminatorCount {
  int sphere = 0;          // pixels on the sphere
  int litSide = 0;         // of them, where the smooth sphere faces the light by more than the margin
  int shadowedOnLit = 0;   // of those, shadowed (below 0.6 of the unshadowed shading)
  int unlitButBright = 0;  // where the smooth sphere faces away by more than the margin, yet lit
};

// Renders the sphere under a directional light with `terminator` and
// without shadows, and counts against the smooth sphere's mask: lit where
// dot(n, toLight) > margin at the point where the pixel's ray meets the
// unit sphere.
TerminatorCount countTerminator(ShadowTerminator terminator, RayOffsetMethod offset, double margin) {
  test::SceneBuilder b;
  const uint32_t grey = b.addMaterial(test::SceneBuilder::lambert(glm::vec4(0.8f, 0.8f, 0.8f, 1.0f)));
  addSmoothSphere(b, 12, 8, grey);
  const glm::dvec3 toLight = glm::normalize(glm::dvec3(1.0, 0.35, 0.25));
  b.addDirectionalLight(-toLight, 3.0f);
  b.setCamera(Projection::Orthographic, glm::dvec3(0.0, 0.0, 5.0), glm::dvec3(0.0), glm::dvec3(0.0, 1.0, 0.0),
              1.1, 0.1, 20.0);
  const Scene& scene = b.scene();
  const int size = 160;
  const Camera camera = makeCamera(scene, {}, size, size);
  RayCaster caster(scene, analyzeScene(scene));
  RayOptions options;
  options.terminator = terminator;
  options.offset = offset;
  caster.bind(camera, options);
  const RenderOutput lit = caster.render();
  options.shadows = false;
  caster.bind(camera, options);
  const RenderOutput unshadowed = caster.render();

  TerminatorCount c;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const size_t i = size_t(y) * size + size_t(x);
      if (lit.image.instance[i] != 0u) continue;
      ++c.sphere;
      const Ray ray = camera.primaryRay(glm::dvec2(x + 0.5, y + 0.5));
      // The smooth sphere along the ray: |o + t·d| = 1, the nearer root.
      const double bq = glm::dot(ray.origin, ray.direction), cq = glm::dot(ray.origin, ray.origin) - 1.0;
      const double disc = bq * bq - cq;
      if (disc < 0.0) continue;  // the facets stick out nowhere, but be safe
      const glm::dvec3 n = ray.origin + (-bq - std::sqrt(disc)) * ray.direction;
      const double facing = glm::dot(n, toLight);
      const float with = lit.image.color[i].r, without = unshadowed.image.color[i].r;
      if (facing > margin) {
        ++c.litSide;
        if (with < 0.6f * without) ++c.shadowedOnLit;
      } else if (facing < -margin && with > 1e-6f) {
        ++c.unlitButBright;
      }
    }
  return c;
}

TEST(ShadowTerminator, NoShadowOnTheSmoothSpheresLitSide) {
  for (RayOffsetMethod offset : {RayOffsetMethod::ErrorBound, RayOffsetMethod::FloatUlps}) {
    const TerminatorCount before = countTerminator(ShadowTerminator::None, offset, 0.02);
    const TerminatorCount after = countTerminator(ShadowTerminator::ShadingNormal, offset, 0.02);
    // The artifact is there without the lift (the test can fail)...
    EXPECT_GT(before.shadowedOnLit, 20) << toString(offset);
    EXPECT_GT(after.litSide, after.sphere / 3);
    // ...and gone with it; the dark side stays dark.
    EXPECT_EQ(after.shadowedOnLit, 0) << toString(offset) << ": of " << after.litSide << " lit-side pixels";
    EXPECT_EQ(after.unlitButBright, 0) << toString(offset);
    std::printf("%s: lit-side pixels shadowed: %d without the lift, %d with it (of %d)\n", toString(offset),
                before.shadowedOnLit, after.shadowedOnLit, after.litSide);
  }
}

// The lift itself: zero on flat-shaded triangles and on concave ones,
// positive towards the side of the normals on convex ones, and within the
// bound the header states (edge length × sin of the normals' tilt).
TEST(ShadowTerminator, LiftIsZeroOnFlatAndConcaveTrianglesAndBoundedOnConvex) {
  const FloatTriangle tri = {glm::vec3(0.0f, 0.0f, 0.0f), glm::vec3(1.0f, 0.0f, 0.0f),
                             glm::vec3(0.0f, 1.0f, 0.0f)};
  const glm::dvec3 p(0.25, 0.25, 0.0);
  const VertexNormals flat = {glm::vec3(0, 0, 1), glm::vec3(0, 0, 1), glm::vec3(0, 0, 1)};
  EXPECT_EQ(terminatorLift(tri, flat, p, 0.25, 0.25, 1.0), glm::dvec3(0.0));
  // Normals tilted away from the centre: a convex bump.
  const double tilt = 0.2;
  const glm::dvec3 c(1.0 / 3.0, 1.0 / 3.0, 0.0);
  VertexNormals convex, concave;
  for (size_t i = 0; i < 3; ++i) {
    const glm::dvec3 out = glm::normalize(glm::dvec3(tri[i]) - c);
    convex[i] = glm::vec3(glm::normalize(glm::dvec3(0, 0, 1) + tilt * out));
    concave[i] = glm::vec3(glm::normalize(glm::dvec3(0, 0, 1) - tilt * out));
  }
  const glm::dvec3 up = terminatorLift(tri, convex, p, 0.25, 0.25, 1.0);
  EXPECT_GT(up.z, 0.0);
  EXPECT_LE(glm::length(up), std::sqrt(2.0) * std::sin(std::atan(tilt)));
  EXPECT_EQ(terminatorLift(tri, concave, p, 0.25, 0.25, 1.0), glm::dvec3(0.0));
  // At a vertex the point is on that vertex's tangent plane: no lift.
  EXPECT_EQ(terminatorLift(tri, convex, glm::dvec3(tri[0]), 0.0, 0.0, 1.0), glm::dvec3(0.0));
  // From the back side (s = −1) the convex bump is concave.
  EXPECT_EQ(terminatorLift(tri, convex, p, 0.25, 0.25, -1.0), glm::dvec3(0.0));
}

}  // namespace
}  // namespace rastray
