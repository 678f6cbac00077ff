// refineHit: the renderer's hit is kept when the triangle's plane is not
// ahead of the ray, and refined barycentrics never leave the triangle.
#include <gtest/gtest.h>

#include <cmath>

#include "common/surface.h"

namespace rastray {
namespace {

// One triangle in the z = 0 plane: v0 (−1, −1), v1 (1, −1), v2 (0, 1).
Scene triangleScene() {
  Scene s;
  s.positions = {{-1, -1, 0}, {1, -1, 0}, {0, 1, 0}};
  s.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
  s.texcoords = {{0, 0}, {1, 0}, {0, 1}};
  s.triangles = {{0, 1, 2}};
  Instance inst;
  inst.vertexCount = 3;
  inst.triangleCount = 1;
  inst.hasTexcoords = true;
  s.instances.push_back(inst);
  s.materials.push_back(Material{});
  s.bounds.extend({-1, -1, 0});
  s.bounds.extend({1, 1, 0});
  return s;
}

SampleHit rendererHit(float depth) {
  SampleHit h;
  h.instance = 0;
  h.triangle = 0;
  h.depth = depth;
  h.b1 = 0.25f;
  h.b2 = 0.25f;
  return h;
}

Ray rayThrough(const glm::dvec3& origin, const glm::dvec3& target) {
  Ray r;
  r.origin = origin;
  r.direction = glm::normalize(target - origin);
  r.depthPerT = 1.0;
  return r;
}

void expectSame(const SampleHit& a, const SampleHit& b) {
  EXPECT_EQ(a.instance, b.instance);
  EXPECT_EQ(a.triangle, b.triangle);
  EXPECT_EQ(a.depth, b.depth);
  EXPECT_EQ(a.b1, b.b1);
  EXPECT_EQ(a.b2, b.b2);
}

TEST(RefineHit, InsideTheTriangleRefinesToThePlanePoint) {
  const Scene s = triangleScene();
  const SampleHit refined = refineHit(s, rayThrough({0, 0, 2}, {0, 0, 0}), rendererHit(2.001f));
  // (0, 0) = v0 + 0.25·(2, 0) + 0.5·(1, 2).
  EXPECT_FLOAT_EQ(refined.b1, 0.25f);
  EXPECT_FLOAT_EQ(refined.b2, 0.5f);
  EXPECT_FLOAT_EQ(refined.depth, 2.0f);
}

TEST(RefineHit, APlaneBehindTheRayKeepsTheRenderersHit) {
  const Scene s = triangleScene();
  const SampleHit hit = rendererHit(0.5f);
  // Looking away from the plane: it lies at t = −1.
  Ray away;
  away.origin = {0, 0, 1};
  away.direction = {0, 0, 1};
  expectSame(refineHit(s, away, hit), hit);
  // The origin on the plane: t = 0, not ahead either.
  Ray onPlane;
  onPlane.origin = {0, 0, 0};
  onPlane.direction = glm::normalize(glm::dvec3(0, 1, 1));
  expectSame(refineHit(s, onPlane, hit), hit);
  // A depth scale that overflows: not finite, keep the hit.
  Ray huge = rayThrough({0, 0, 2}, {0, 0, 0});
  huge.depthPerT = 1e308;
  expectSame(refineHit(s, huge, hit), hit);
}

TEST(RefineHit, BarycentricsOutsideTheTriangleAreClampedIntoIt) {
  const Scene s = triangleScene();
  // Grazing rays whose plane points lie outside the triangle (the
  // renderer, rounding in float, called them inside).
  struct Case {
    glm::dvec3 planePoint;
    float b1, b2;  // after the rule in surface.h
  };
  const Case cases[] = {
      {{2.0, 0.0, 0.0}, 1.25f / 1.75f, 0.5f / 1.75f},  // b = (1.25, 0.5): beyond v1–v2, scaled
      {{0.0, -2.0, 0.0}, 0.75f, 0.0f},                 // b = (0.75, −0.5): below v0–v1
      {{-3.0, 0.0, 0.0}, 0.0f, 0.5f},                  // b = (−1.25, 0.5): left of v0–v2
      {{-3.0, -3.0, 0.0}, 0.0f, 0.0f},                 // both negative: v0
  };
  for (const Case& c : cases) {
    const glm::dvec3 origin = c.planePoint + glm::dvec3(-10.0, 3.0, 1e-3);  // nearly parallel
    const Ray ray = rayThrough(origin, c.planePoint);
    const SampleHit refined = refineHit(s, ray, rendererHit(10.0f));
    EXPECT_GE(refined.b1, 0.0f);
    EXPECT_GE(refined.b2, 0.0f);
    EXPECT_LE(double(refined.b1) + double(refined.b2), 1.0 + 1e-7);
    EXPECT_NEAR(refined.b1, c.b1, 1e-6f) << c.planePoint.x << " " << c.planePoint.y;
    EXPECT_NEAR(refined.b2, c.b2, 1e-6f) << c.planePoint.x << " " << c.planePoint.y;
    // The depth stays the ray's own plane depth.
    EXPECT_NEAR(refined.depth, glm::length(c.planePoint - origin), 1e-4);
    // Attributes interpolate inside the triangle: uv stays in [0, 1].
    const SurfacePoint p = makeSurfacePoint(s, refined);
    EXPECT_GE(p.uv.x, 0.0f);
    EXPECT_GE(p.uv.y, 0.0f);
    EXPECT_LE(p.uv.x + p.uv.y, 1.0f + 1e-6f);
  }
}

// The plane intersection is the same to the bit whatever order a
// triangle lists its corners in (canonical corner order; two corners tie
// in x and two in x and y, so every comparison of the order matters):
// the same t and the same weight for each corner; and refineHitAt from it
// is refineHit.
TEST(RefineHit, CornerOrderDoesNotChangeThePlanePoint) {
  const glm::vec3 corners[3] = {{0.5f, 2.0f, 3.0f}, {0.5f, 2.0f, -1.5f}, {-0.25f, 5.0f, 1.0f}};
  const int orders[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (const glm::dvec3 origin : {glm::dvec3(7.0, 1.0, 0.3), glm::dvec3(-4.0, 3.3, 2.0)}) {
    const Ray ray = rayThrough(origin, {0.3, 3.0, 1.1});
    double t0 = 0.0;
    // Each original corner's weight, from the first order that returns it
    // (b holds the weights of stored corners 1 and 2).
    double weight[3];
    bool seen[3] = {false, false, false};
    for (int k = 0; k < 6; ++k) {
      Scene s = triangleScene();
      for (int i = 0; i < 3; ++i) s.positions[size_t(i)] = corners[orders[k][i]];
      double t;
      glm::dvec2 b;
      ASSERT_TRUE(intersectTrianglePlane(s, 0, 0, ray, &t, &b));
      if (k == 0) t0 = t;
      EXPECT_EQ(t, t0) << "order " << k;
      for (int slot = 1; slot < 3; ++slot) {
        const int corner = orders[k][slot];
        const double w = slot == 1 ? b.x : b.y;
        if (!seen[corner]) weight[corner] = w;
        seen[corner] = true;
        EXPECT_EQ(w, weight[corner]) << "order " << k << " corner " << corner;
      }
      expectSame(refineHitAt(ray, rendererHit(1.0f), t, b), refineHit(s, ray, rendererHit(1.0f)));
    }
  }
}

}  // namespace
}  // namespace rastray
