// refineHit: the renderer's hit is kept when the triangle's plane is not
// ahead of the ray, and refined barycentrics never leave the triangle.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

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

// The plane point and face normal as computed before the per-thread memo
// of the last triangle (common/surface.cpp): every call from scratch.
bool referencePlanePoint(const Scene& scene, uint32_t tri, const Ray& ray, double* t, glm::dvec2* b) {
  const glm::uvec3 v = scene.triangles[tri];
  std::array<glm::dvec3, 3> corner = {glm::dvec3(scene.positions[v.x]), glm::dvec3(scene.positions[v.y]),
                                      glm::dvec3(scene.positions[v.z])};
  auto less = [&](int i, int j) {
    const glm::dvec3 &p = corner[size_t(i)], &q = corner[size_t(j)];
    if (p.x != q.x) return p.x < q.x;
    if (p.y != q.y) return p.y < q.y;
    return p.z < q.z;
  };
  std::array<int, 3> order = {0, 1, 2};
  if (less(order[1], order[0])) std::swap(order[0], order[1]);
  if (less(order[2], order[1])) std::swap(order[1], order[2]);
  if (less(order[1], order[0])) std::swap(order[0], order[1]);
  const glm::dvec3 &a = corner[size_t(order[0])], &bb = corner[size_t(order[1])],
                   &c = corner[size_t(order[2])];
  const glm::dvec3 e1 = bb - a, e2 = c - a;
  const glm::dvec3 p = glm::cross(ray.direction, e2);
  const double det = glm::dot(e1, p);
  if (!(std::abs(det) > 0.0)) return false;
  const double inv = 1.0 / det;
  const glm::dvec3 s = ray.origin - a;
  const double u = glm::dot(s, p) * inv;
  const glm::dvec3 q = glm::cross(s, e1);
  const double w = glm::dot(ray.direction, q) * inv;
  *t = glm::dot(e2, q) * inv;
  std::array<double, 3> weight{};
  weight[size_t(order[0])] = 1.0 - u - w;
  weight[size_t(order[1])] = u;
  weight[size_t(order[2])] = w;
  *b = glm::dvec2(weight[1], weight[2]);
  return std::isfinite(*t) && std::isfinite(u) && std::isfinite(w);
}

glm::dvec3 referenceFaceNormal(const Scene& scene, uint32_t tri) {
  const glm::uvec3 v = scene.triangles[tri];
  const glm::dvec3 p0(scene.positions[v.x]), p1(scene.positions[v.y]), p2(scene.positions[v.z]);
  const glm::dvec3 n = glm::cross(p1 - p0, p2 - p0);
  const double length = glm::length(n);
  return length > 0.0 ? n / length : glm::dvec3(0.0, 0.0, 1.0);
}

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Both surface.cpp functions against the from-scratch reference, bit for
// bit, for one ray and triangle of `s` (whatever the memo holds).
void expectMatchesReference(const Scene& s, uint32_t tri, const Ray& ray, const std::string& where) {
  double t = 0.0, tr = 0.0;
  glm::dvec2 b(0.0), br(0.0);
  const bool ok = intersectTrianglePlane(s, 0, tri, ray, &t, &b);
  ASSERT_EQ(ok, referencePlanePoint(s, tri, ray, &tr, &br)) << where;
  if (ok) {
    EXPECT_TRUE(sameBits(t, tr) && sameBits(b.x, br.x) && sameBits(b.y, br.y)) << where;
  }
  SampleHit h;
  h.instance = 0;
  h.triangle = tri;
  h.b1 = 0.2f;
  h.b2 = 0.3f;
  const glm::dvec3 n = makeSurfacePoint(s, h).geometricNormal, nr = referenceFaceNormal(s, tri);
  EXPECT_TRUE(sameBits(n.x, nr.x) && sameBits(n.y, nr.y) && sameBits(n.z, nr.z)) << where;
}

// The last triangle's corners, edges and normal are remembered per thread
// (common/surface.cpp): repeated, alternating and edited triangles, and
// another scene with the same (instance, triangle), give exactly what a
// computation from scratch gives. Edits in place (rebasing, a test moving
// a vertex) must never be answered from the memo.
TEST(RefineHit, TheLastTriangleMemoNeverChangesResults) {
  uint32_t state = 99u;
  auto next = [&] {
    state = state * 1664525u + 1013904223u;
    return float(state >> 8) / float(1u << 24) * 4.0f - 2.0f;
  };
  Scene s = triangleScene();
  s.positions.clear();
  s.triangles.clear();
  for (uint32_t i = 0; i < 6; ++i) {
    for (int k = 0; k < 3; ++k) s.positions.push_back({next(), next(), next()});
    s.triangles.push_back({3 * i, 3 * i + 1, 3 * i + 2});
  }
  s.positions[15] = s.positions[16] = s.positions[17];  // triangle 5 is degenerate
  // Every vertex needs its attributes (the base scene has three).
  s.normals.assign(s.positions.size(), glm::vec3(0, 0, 1));
  s.texcoords.assign(s.positions.size(), glm::vec2(0.5f, 0.25f));
  s.instances[0].vertexCount = uint32_t(s.positions.size());
  s.instances[0].triangleCount = uint32_t(s.triangles.size());
  const uint32_t sequence[] = {0, 0, 0, 1, 0, 1, 2, 2, 5, 5, 3, 4, 3, 0};
  for (int r = 0; r < 20; ++r) {
    const Ray ray = rayThrough({next() * 5, next() * 5, 9.0 + next()}, {next(), next(), next()});
    for (const uint32_t tri : sequence)
      expectMatchesReference(s, tri, ray, "sequence, triangle " + std::to_string(tri));
  }
  // The same triangle edited in place, then one of its corners set back.
  const Ray ray = rayThrough({0.5, 0.25, 7.0}, {0.1, 0.2, 0.0});
  expectMatchesReference(s, 1, ray, "before the edit");
  const glm::vec3 saved = s.positions[4];
  s.positions[4] += glm::vec3(0.0f, 0.0f, 0.5f);
  expectMatchesReference(s, 1, ray, "edited");
  s.positions[4].x = -0.0f;
  expectMatchesReference(s, 1, ray, "-0");
  s.positions[4].x = 0.0f;
  expectMatchesReference(s, 1, ray, "+0");
  s.positions[4] = saved;
  expectMatchesReference(s, 1, ray, "restored");
  // Another scene, same (instance, triangle), other corners.
  Scene other = s;
  for (glm::vec3& p : other.positions) p = glm::vec3(p.y, p.z, p.x) * 3.0f;
  expectMatchesReference(s, 2, ray, "first scene");
  expectMatchesReference(other, 2, ray, "second scene");
  expectMatchesReference(s, 2, ray, "first scene again");
}

void expectSameSurfacePoint(const SurfacePoint& a, const SurfacePoint& b, const std::string& where) {
  EXPECT_EQ(a.instance, b.instance) << where;
  EXPECT_EQ(a.triangle, b.triangle) << where;
  EXPECT_EQ(a.material, b.material) << where;
  EXPECT_TRUE(std::memcmp(&a.b1, &b.b1, sizeof a.b1) == 0 && std::memcmp(&a.b2, &b.b2, sizeof a.b2) == 0)
      << where;
  for (int k = 0; k < 3; ++k) {
    EXPECT_TRUE(sameBits(a.position[k], b.position[k])) << where;
    EXPECT_TRUE(sameBits(a.geometricNormal[k], b.geometricNormal[k])) << where;
    EXPECT_TRUE(sameBits(a.shadingNormal[k], b.shadingNormal[k])) << where;
  }
  EXPECT_TRUE(std::memcmp(&a.uv, &b.uv, sizeof a.uv) == 0) << where;
  EXPECT_TRUE(std::memcmp(&a.color, &b.color, sizeof a.color) == 0) << where;
}

// surfacePointOnRay is makeSurfacePoint(refineHit(...)) in one call: the
// same bits inside the triangle, outside it (clamped), with the plane
// behind the ray (the hit kept) and for a ray in the plane (no
// intersection).
TEST(RefineHit, SurfacePointOnRayIsMakeSurfacePointOfTheRefinedHit) {
  Scene s = triangleScene();
  s.instances[0].normals = NormalSource::Authored;
  s.normals = {{0.1f, 0.2f, 1.0f}, {-0.3f, 0.0f, 0.9f}, {0.0f, 0.5f, 0.8f}};
  s.instances[0].hasColors = true;
  s.colors = {{1.0f, 0.5f, 0.25f, 1.0f}, {0.0f, 1.0f, 0.5f, 0.5f}, {0.3f, 0.3f, 1.0f, 1.0f}};
  uint32_t state = 7u;
  auto next = [&] {
    state = state * 1664525u + 1013904223u;
    return double(state >> 8) / double(1u << 24) * 3.0 - 1.5;
  };
  std::vector<Ray> rays;
  for (int i = 0; i < 300; ++i)
    rays.push_back(rayThrough({next(), next(), 3.0 + next()}, {next(), next(), 0.0}));
  rays.push_back(rayThrough({0, 0, -2}, {0, 0, -3}));     // plane behind the ray
  rays.push_back(rayThrough({-5, 0.1, 0}, {5, 0.1, 0}));  // in the plane
  for (size_t i = 0; i < rays.size(); ++i) {
    SampleHit hit = rendererHit(1.5f);
    hit.b1 = float(0.5 + 0.3 * next());
    hit.b2 = float(0.25 + 0.2 * next());
    expectSameSurfacePoint(surfacePointOnRay(s, rays[i], hit),
                           makeSurfacePoint(s, refineHit(s, rays[i], hit)), "ray " + std::to_string(i));
  }
}

}  // namespace
}  // namespace rastray
