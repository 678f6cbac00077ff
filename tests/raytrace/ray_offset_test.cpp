// Ray origin offsets (raytrace/ray_offset.h): the error-bound origin lies
// strictly on the side the ray leaves, checked apart from the code's own
// bound; its height follows the triangle's vertex magnitudes and size, not
// the hit point's coordinates (where the Ray Tracing Gems offset fails);
// and Embree does not hit the triangle again from it.
#include <gtest/gtest.h>

#include <array>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include <hwy/highway.h>
#include <hwy/targets.h>

#include "common/surface.h"
#include "raytrace/ray_caster.h"
#include "raytrace/ray_offset.h"
#include "raytrace/ray_offset_lanes.h"
#include "test_scenes.h"

#include "tests/test_labels.h"

namespace rastray {
namespace {

// Flush as Embree's traversal reads (DAZ).
long double dazl(float x) { return std::fabs(x) < FLT_MIN ? 0.0L : (long double)x; }

// The side of float origin o relative to the plane of float triangle t
// along `side`: +1 leaving side, -1 the other, 0 undecided. In long double
// (64-bit significand): each w = p − o is exact or off by 2⁻⁶⁴ of itself,
// the determinant's six products and sums add at most 5 more roundings,
// so |computed − exact| ≤ 8·2⁻⁶⁴·per|W|; only a larger |det| decides.
int exactSide(const FloatTriangle& t, const glm::vec3& o, const glm::dvec3& side) {
  long double w[3][3];
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) w[i][k] = dazl(t[size_t(i)][k]) - dazl(o[k]);
  const long double det = w[0][0] * (w[1][1] * w[2][2] - w[1][2] * w[2][1]) -
                          w[0][1] * (w[1][0] * w[2][2] - w[1][2] * w[2][0]) +
                          w[0][2] * (w[1][0] * w[2][1] - w[1][1] * w[2][0]);
  auto a = [&](int i, int k) { return std::fabs(w[i][k]); };
  const long double per = a(0, 0) * (a(1, 1) * a(2, 2) + a(1, 2) * a(2, 1)) +
                          a(0, 1) * (a(1, 0) * a(2, 2) + a(1, 2) * a(2, 0)) +
                          a(0, 2) * (a(1, 0) * a(2, 1) + a(1, 1) * a(2, 0));
  if (!(std::fabs(det) > 8.0L * std::ldexp(1.0L, -64) * per)) return 0;
  // det = dot(p0 − o, N): negative when o lies on N's side.
  const glm::dvec3 n = glm::cross(glm::dvec3(t[1] - t[0]), glm::dvec3(t[2] - t[0]));
  const int nSide = glm::dot(n, side) >= 0.0 ? 1 : -1;
  return det < 0 ? nSide : -nSide;
}

struct Sample {
  FloatTriangle triangle;
  float b1, b2;
  glm::dvec3 position;  // as makeSurfacePoint rebuilds it
  glm::dvec3 side;      // unit, ± the geometric normal
  double size;          // longest edge
  double magnitude;     // largest |vertex coordinate|
};

// A random well-shaped triangle of edge ~size around a centre at distance
// `magnitude` (some centres with a coordinate near zero, as a floor at
// y = 0 far out has), a random point in it and a random side.
Sample randomSample(std::mt19937& rng, double magnitude, double size) {
  std::uniform_real_distribution<double> u(-1.0, 1.0), unit(0.0, 1.0);
  glm::dvec3 c(u(rng), u(rng), u(rng));
  if (unit(rng) < 0.3) c[std::uniform_int_distribution<int>(0, 2)(rng)] = 0.0;
  c = glm::normalize(c) * magnitude;
  Sample s{};
  for (;;) {
    for (glm::vec3& v : s.triangle) v = glm::vec3(c + size * glm::dvec3(u(rng), u(rng), u(rng)));
    const glm::dvec3 e1(s.triangle[1] - s.triangle[0]), e2(s.triangle[2] - s.triangle[0]);
    const double longest = std::max({glm::length(e1), glm::length(e2), glm::length(e2 - e1)});
    // Area against the longest edge squared: no slivers here (they need
    // larger offsets, by their aspect ratio).
    if (glm::length(glm::cross(e1, e2)) > 0.1 * longest * longest) {
      s.size = longest;
      break;
    }
  }
  s.b1 = float(unit(rng));
  s.b2 = float(unit(rng) * (1.0 - s.b1));
  const double b0 = 1.0 - double(s.b1) - double(s.b2);
  s.position = b0 * glm::dvec3(s.triangle[0]) + double(s.b1) * glm::dvec3(s.triangle[1]) +
               double(s.b2) * glm::dvec3(s.triangle[2]);
  const glm::dvec3 n = glm::normalize(
      glm::cross(glm::dvec3(s.triangle[1] - s.triangle[0]), glm::dvec3(s.triangle[2] - s.triangle[0])));
  s.side = unit(rng) < 0.5 ? n : -n;
  s.magnitude = 0.0;
  for (const glm::vec3& v : s.triangle)
    s.magnitude =
        std::max({s.magnitude, double(std::fabs(v.x)), double(std::fabs(v.y)), double(std::fabs(v.z))});
  return s;
}

// Height of o above the triangle's plane along `side`, in double.
double heightOf(const Sample& s, const glm::vec3& o) {
  return glm::dot(glm::dvec3(o) - glm::dvec3(s.triangle[0]), s.side);
}

const double kMagnitudes[] = {1e-3, 1e-2, 1e-1, 1.0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7};

TEST(ErrorBoundOffset, OriginLiesStrictlyOnTheLeavingSide) {
  std::mt19937 rng(9);
  int floatUlpsWrong = 0, total = 0;
  for (double magnitude : kMagnitudes)
    for (double relative : {1.0, 1e-1, 1e-2, 1e-3})
      for (int i = 0; i < 200; ++i) {
        // At least 64 float spacings across, so the float triangle keeps its shape.
        const double size = std::max(relative * magnitude, 64.0 * magnitude * 0x1p-23);
        const Sample s = randomSample(rng, magnitude, size);
        const glm::vec3 o = errorBoundRayOrigin(s.triangle, s.position, s.b1, s.b2, s.side);
        ++total;
        ASSERT_EQ(exactSide(s.triangle, o, s.side), 1)
            << "magnitude " << magnitude << " size " << size << " sample " << i;
        EXPECT_TRUE(leavesWithoutRehit(s.triangle, o, s.side)) << magnitude << " " << i;
        if (exactSide(s.triangle, floatUlpsRayOrigin(glm::vec3(s.position), glm::vec3(s.side)), s.side) != 1)
          ++floatUlpsWrong;
      }
  // For the record (the RTG offset is large enough to land on the right
  // side of these well-shaped triangles nearly always).
  std::printf("float-ulps origins not strictly on the leaving side: %d of %d\n", floatUlpsWrong, total);
}

// errorBoundRayOrigin remembers the last triangle's vertices and normal
// per thread (raytrace/ray_offset.cpp). The origin for a sample must not
// depend on which triangle came before: the same bits after the same
// triangle (memo hit), after another one (miss) and after a triangle that
// differs from it in one vertex bit only, and every origin passes the
// check leavesWithoutRehit makes without the memo.
TEST(ErrorBoundOffset, SameOriginWhicheverTriangleCameBefore) {
  std::mt19937 rng(21);
  std::vector<Sample> samples;
  for (double magnitude : {1e-2, 1.0, 1e3, 1e6})
    for (int i = 0; i < 6; ++i) samples.push_back(randomSample(rng, magnitude, 0.5 * magnitude));
  // Same triangle as sample 0, one vertex one float step away.
  Sample nudged = samples[0];
  nudged.triangle[2].y = std::nextafter(nudged.triangle[2].y, INFINITY);
  samples.push_back(nudged);
  auto origin = [](const Sample& s) {
    return errorBoundRayOrigin(s.triangle, s.position, s.b1, s.b2, s.side);
  };
  auto bits = [](const glm::vec3& o) {
    uint32_t b[3];
    std::memcpy(b, &o, sizeof b);
    return std::array<uint32_t, 3>{b[0], b[1], b[2]};
  };
  std::vector<std::array<uint32_t, 3>> first;
  for (const Sample& s : samples) {
    const glm::vec3 o = origin(s);
    EXPECT_TRUE(leavesWithoutRehit(s.triangle, o, s.side));
    first.push_back(bits(o));
  }
  for (size_t i = 0; i < samples.size(); ++i) {
    EXPECT_EQ(bits(origin(samples[i])), first[i]) << "again, sample " << i;  // after itself
    for (size_t j : {size_t(0), samples.size() - 1, (i + 5) % samples.size()}) {
      origin(samples[j]);
      EXPECT_EQ(bits(origin(samples[i])), first[i]) << "sample " << i << " after " << j;
    }
  }
}

// A nearly level floor far out along x: the RTG offset moves x by
// int(256·n_x) = 0 ULPs and y by 256 ULPs of y, while rounding x to float
// costs up to 0.03·n_x of height: it can land under the floor (acne).
// The error-bound origin stays above.
TEST(ErrorBoundOffset, NearlyLevelFloorFarOutStaysAbove) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int floatUlpsBelow = 0;
  const int n = 2000;
  for (int i = 0; i < n; ++i) {
    // Slope 1/1000 along x around x = 1e6, y ≈ 0.1.
    const double x0 = 1e6 - 10.0, x1 = 1e6 + 10.0;
    const auto height = [](double x) { return 0.1 + 1e-3 * (x - 1e6); };
    Sample s{};
    s.triangle = {glm::vec3(float(x0), float(height(x0)), -10.0f),
                  glm::vec3(float(x1), float(height(x1)), -10.0f),
                  glm::vec3(float(x0), float(height(x0)), 10.0f)};
    std::swap(s.triangle[1], s.triangle[2]);  // counter-clockwise seen from +y
    s.b1 = float(unit(rng));
    s.b2 = float(unit(rng) * (1.0 - s.b1));
    const double b0 = 1.0 - double(s.b1) - double(s.b2);
    s.position = b0 * glm::dvec3(s.triangle[0]) + double(s.b1) * glm::dvec3(s.triangle[1]) +
                 double(s.b2) * glm::dvec3(s.triangle[2]);
    s.side = glm::normalize(
        glm::cross(glm::dvec3(s.triangle[1] - s.triangle[0]), glm::dvec3(s.triangle[2] - s.triangle[0])));
    ASSERT_GT(s.side.y, 0.99);
    const glm::vec3 o = errorBoundRayOrigin(s.triangle, s.position, s.b1, s.b2, s.side);
    ASSERT_EQ(exactSide(s.triangle, o, s.side), 1) << i;
    EXPECT_LT(heightOf(s, o), 1e-4) << i;
    if (exactSide(s.triangle, floatUlpsRayOrigin(glm::vec3(s.position), glm::vec3(s.side)), s.side) != 1)
      ++floatUlpsBelow;
  }
  // The failure this fixes: the RTG origin under the floor for a good share.
  EXPECT_GT(floatUlpsBelow, n / 10) << "float-ulps origins below the floor: " << floatUlpsBelow << " of "
                                    << n;
}

// The height follows the triangle: below 2⁻¹²·size (Embree's bound for a
// well-shaped triangle, measured from the origin) plus 2⁻²¹·the vertex
// magnitude (rounding to float there). The RTG offset follows the hit
// point's coordinates instead: 1/65536 near zero whatever the triangle's
// size, 256 ULPs of the coordinate far out; for small triangles both
// break the bound.
TEST(ErrorBoundOffset, HeightProportionalToVertexMagnitudesAndSize) {
  std::mt19937 rng(17);
  for (double magnitude : kMagnitudes) {
    int floatUlpsOver = 0;
    const int n = 200;
    for (int i = 0; i < n; ++i) {
      const double size = std::max(1e-2 * magnitude, 64.0 * magnitude * 0x1p-23);
      const Sample s = randomSample(rng, magnitude, size);
      const double allowed = std::ldexp(s.size, -12) + std::ldexp(s.magnitude, -21);
      const double h = heightOf(s, errorBoundRayOrigin(s.triangle, s.position, s.b1, s.b2, s.side));
      EXPECT_GT(h, 0.0);
      EXPECT_LE(h, allowed) << "magnitude " << magnitude << " size " << s.size << " sample " << i;
      if (heightOf(s, floatUlpsRayOrigin(glm::vec3(s.position), glm::vec3(s.side))) > allowed)
        ++floatUlpsOver;
    }
    // Small triangles near the origin (the fixed 1/65536) and far from it
    // (256 ULPs of 1e4..1e7): the RTG offset is far above the bound.
    if (magnitude <= 1e-2 || magnitude >= 1e4) {
      EXPECT_GT(floatUlpsOver, n / 2) << "magnitude " << magnitude << ": " << floatUlpsOver << " of " << n;
    }
  }
}

// The same triangle shape near the origin and 1e6 away: the error-bound
// height near the origin is tiny, far away it grows only by float spacing
// there (0.0625), not by 256 of them.
TEST(ErrorBoundOffset, TriangleNearTheOriginIsOffsetTiny) {
  const FloatTriangle nearOrigin = {glm::vec3(-1e-3f, 0.0f, -1e-3f), glm::vec3(0.0f, 2e-4f, 1e-3f),
                                    glm::vec3(1e-3f, 1e-4f, -1e-3f)};
  const glm::dvec3 n = glm::normalize(
      glm::cross(glm::dvec3(nearOrigin[1] - nearOrigin[0]), glm::dvec3(nearOrigin[2] - nearOrigin[0])));
  const float b1 = 0.3f, b2 = 0.3f;
  auto at = [&](const FloatTriangle& t) {
    return 0.4 * glm::dvec3(t[0]) + double(b1) * glm::dvec3(t[1]) + double(b2) * glm::dvec3(t[2]);
  };
  const glm::vec3 o = errorBoundRayOrigin(nearOrigin, at(nearOrigin), b1, b2, n);
  const double h = glm::dot(glm::dvec3(o) - glm::dvec3(nearOrigin[0]), n);
  EXPECT_GT(h, 0.0);
  EXPECT_LT(h, 1e-9);  // triangle 2e-3 across
  const glm::vec3 ulps = floatUlpsRayOrigin(glm::vec3(at(nearOrigin)), glm::vec3(n));
  EXPECT_GT(glm::dot(glm::dvec3(ulps) - glm::dvec3(nearOrigin[0]), n), 1e-5);  // 1/65536
}

// Embree itself: a one-triangle scene, shadow rays from the offset origin
// in random directions leaving the surface. A ray that hits the triangle
// again returns transmittance 0. Every direction Embree's denominator is
// certified for must come back 1.
RASTRAY_TEST_LABELS_OF(ErrorBoundOffset, EmbreeDoesNotHitTheTriangleAgain, "threads");
TEST(ErrorBoundOffset, EmbreeDoesNotHitTheTriangleAgain) {
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int floatUlpsHits = 0, rays = 0;
  for (double magnitude : kMagnitudes)
    for (int i = 0; i < 12; ++i) {
      const double size = std::max(1e-2 * magnitude, 64.0 * magnitude * 0x1p-23);
      const Sample s = randomSample(rng, magnitude, size);
      test::SceneBuilder b;
      const uint32_t grey = b.addMaterial(test::SceneBuilder::lambert(glm::vec4(0.5f, 0.5f, 0.5f, 1.0f)));
      b.addMesh({s.triangle[0], s.triangle[1], s.triangle[2]}, {{0, 1, 2}}, grey);
      b.addDirectionalLight(glm::dvec3(0.0, -1.0, 0.0), 1.0f);
      const glm::dvec3 c(s.triangle[0]);
      b.setCamera(Projection::Perspective, c + glm::dvec3(0.0, 0.0, 10.0 * size), c,
                  glm::dvec3(0.0, 1.0, 0.0), 0.8, 0.1 * size, 100.0 * size);
      const Scene& scene = b.scene();
      RayCaster caster(scene, analyzeScene(scene));
      SampleHit hit;
      hit.instance = 0;
      hit.triangle = 0;
      hit.b1 = s.b1;
      hit.b2 = s.b2;
      const SurfacePoint p = makeSurfacePoint(scene, hit);
      for (RayOffsetMethod method : {RayOffsetMethod::ErrorBound, RayOffsetMethod::FloatUlps}) {
        RayOptions options;
        options.offset = method;
        caster.bind(makeCamera(scene, {}, 8, 8), options);
        for (int r = 0; r < 200; ++r) {
          glm::dvec3 d = glm::normalize(glm::dvec3(u(rng), u(rng), u(rng)));
          const glm::dvec3 side = offsetSideNormal(p.geometricNormal, d);
          const glm::vec3 o = errorBoundRayOrigin(s.triangle, p.position, p.b1, p.b2, side);
          const glm::vec3 t = caster.transmittance(p, 0, d, std::numeric_limits<double>::infinity());
          if (method == RayOffsetMethod::FloatUlps) {
            floatUlpsHits += t.x == 0.0f;
            continue;
          }
          if (!denominatorCertified(s.triangle, o, side, glm::vec3(d))) continue;
          ++rays;
          EXPECT_EQ(t.x, 1.0f) << "magnitude " << magnitude << " triangle " << i << " ray " << r;
        }
      }
    }
  EXPECT_GT(rays, 20000);
  std::printf("certified rays: %d; float-ulps rays that hit their triangle again: %d\n", rays, floatUlpsHits);
}

// Large, gently sloped floors (slopes up to 0.3 each way, 2 to 200 units
// across) near and far from the origin, with origins 0.1 above y = 0: the
// case where Embree's own error exceeds one float step of the origin's
// near-zero coordinate. An origin merely on the right side of the exact
// plane (no Embree term) is hit again by about 8 % of these rays; the
// error-bound origin by none, and nor is the RTG one (its 256 ULPs are
// plenty here).
RASTRAY_TEST_LABELS_OF(ErrorBoundOffset, EmbreeDoesNotHitASlopedFloorAgain, "threads");
TEST(ErrorBoundOffset, EmbreeDoesNotHitASlopedFloorAgain) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0), unit(0.0, 1.0);
  int rays = 0, certifiedRays = 0, floatUlpsHits = 0;
  for (double centre : {0.0, 1e2, 1e4, 1e6})
    for (int i = 0; i < 20; ++i) {
      const double sx = 0.3 * u(rng), sz = 0.3 * u(rng), size = 20.0 * std::pow(10.0, u(rng));
      const auto height = [&](double x, double z) { return 0.1 + sx * (x - centre) + sz * (z - centre); };
      const double xs[3] = {centre - size, centre - size, centre + size};
      const double zs[3] = {centre - size, centre + size, centre - size};
      FloatTriangle t;  // counter-clockwise seen from +y
      for (size_t k = 0; k < 3; ++k)
        t[k] = glm::vec3(float(xs[k]), float(height(xs[k], zs[k])), float(zs[k]));
      test::SceneBuilder b;
      const uint32_t grey = b.addMaterial(test::SceneBuilder::lambert(glm::vec4(0.5f)));
      b.addMesh({t[0], t[1], t[2]}, {{0, 1, 2}}, grey);
      b.setCamera(Projection::Perspective, glm::dvec3(t[0]) + glm::dvec3(0.0, 10.0, 0.0), glm::dvec3(t[0]),
                  glm::dvec3(0.0, 0.0, 1.0), 0.8, 0.1, 100.0);
      const Scene& scene = b.scene();
      RayCaster caster(scene, analyzeScene(scene));
      for (RayOffsetMethod method : {RayOffsetMethod::ErrorBound, RayOffsetMethod::FloatUlps}) {
        RayOptions options;
        options.offset = method;
        caster.bind(makeCamera(scene, {}, 8, 8), options);
        std::mt19937 local{uint32_t(i)};
        for (int j = 0; j < 50; ++j) {
          SampleHit hit;
          hit.instance = 0;
          hit.triangle = 0;
          hit.b1 = float(unit(local));
          hit.b2 = float(unit(local) * (1.0 - hit.b1));
          const SurfacePoint p = makeSurfacePoint(scene, hit);
          for (int r = 0; r < 20; ++r) {
            const glm::dvec3 d = glm::normalize(glm::dvec3(u(local), u(local), u(local)));
            const float seen = caster.transmittance(p, 0, d, std::numeric_limits<double>::infinity()).x;
            if (method == RayOffsetMethod::FloatUlps) {
              floatUlpsHits += seen == 0.0f;
              continue;
            }
            ++rays;
            const glm::dvec3 side = offsetSideNormal(p.geometricNormal, d);
            const glm::vec3 o = errorBoundRayOrigin(t, p.position, p.b1, p.b2, side);
            if (!denominatorCertified(t, o, side, glm::vec3(d))) continue;
            ++certifiedRays;
            EXPECT_EQ(seen, 1.0f) << "centre " << centre << " floor " << i << " point " << j << " ray " << r;
          }
        }
      }
    }
  EXPECT_GT(certifiedRays, rays * 99 / 100);
  std::printf("sloped floors: %d rays, %d certified; float-ulps rays that hit their floor again: %d\n", rays,
              certifiedRays, floatUlpsHits);
}

}  // namespace
}  // namespace rastray

namespace rastray {
namespace {

// errorBoundRayOrigins (the Embree margins in double SIMD lanes) gives
// errorBoundRayOrigin's bits for every ray, on every Highway target
// compiled and supported: triangles of every size and shape, at the
// origin and 1e6 from it, slivers and degenerate ones, points inside and
// on their edges, both sides, with and without a lift, in batches of 1 to
// 40 that mix triangles.
TEST(ErrorBoundOffset, OriginsInLanesAreTheScalarOrigins) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  struct Ray {
    FloatTriangle triangle;
    glm::dvec3 position, side, lift;
    float b1, b2;
  };
  std::vector<Ray> rays;
  const double offsets[] = {0.0, 1e3, 1e6};
  const double sizes[] = {1e-3, 1.0, 20.0, 1e4};
  for (int i = 0; i < 4000; ++i) {
    const double size = sizes[i % 4], offset = offsets[(i / 4) % 3];
    const glm::dvec3 base = offset * glm::dvec3(1.0, (i / 12) % 2 ? 1.0 : 0.0, 1.0);
    FloatTriangle t;
    for (int v = 0; v < 3; ++v)
      t[size_t(v)] = glm::vec3(base + size * glm::dvec3(uniform(rng), 0.2 * uniform(rng), uniform(rng)));
    if (i % 50 == 0) t[2] = t[1] + (t[1] - t[0]) * 1e-6f;  // a sliver
    if (i % 97 == 0) t[2] = t[1];                          // degenerate
    const float b1 = i % 7 == 0 ? 0.0f : float(0.5 * (uniform(rng) + 1.0));
    const float b2 = i % 11 == 0 ? 1.0f - b1 : float(0.5 * (1.0 - b1) * (uniform(rng) + 1.0));
    const glm::dvec3 p0(t[0]), p1(t[1]), p2(t[2]);
    const glm::dvec3 position = (1.0 - double(b1) - double(b2)) * p0 + double(b1) * p1 + double(b2) * p2;
    glm::dvec3 n = glm::cross(p1 - p0, p2 - p0);
    n = glm::length(n) > 0.0 ? glm::normalize(n) : glm::dvec3(0.0, 1.0, 0.0);
    const glm::dvec3 side = i % 2 ? n : -n;
    const glm::dvec3 lift = i % 5 == 0 ? 1e-3 * size * side : glm::dvec3(0.0);
    rays.push_back({t, position, side, lift, b1, b2});
  }
  const std::vector<int64_t> targets = hwy::SupportedAndGeneratedTargets();
  ASSERT_GE(targets.size(), 1u);
  for (int64_t target : targets) {
    SCOPED_TRACE(hwy::TargetName(target));
    hwy::SetSupportedTargetsForTest(target);
    for (size_t first = 0; first < rays.size();) {
      const size_t n = std::min<size_t>(rays.size() - first, 1 + rng() % 40);
      std::vector<FloatTriangle> triangles;
      std::vector<glm::dvec3> positions, sides, lifts;
      std::vector<float> b1, b2;
      for (size_t k = first; k < first + n; ++k) {
        triangles.push_back(rays[k].triangle);
        positions.push_back(rays[k].position);
        sides.push_back(rays[k].side);
        lifts.push_back(rays[k].lift);
        b1.push_back(rays[k].b1);
        b2.push_back(rays[k].b2);
      }
      std::vector<glm::vec3> lanes(n);
      errorBoundRayOrigins(n, triangles.data(), positions.data(), b1.data(), b2.data(), sides.data(),
                           lifts.data(), lanes.data());
      for (size_t k = 0; k < n; ++k) {
        const Ray& r = rays[first + k];
        const glm::vec3 scalar = errorBoundRayOrigin(r.triangle, r.position, r.b1, r.b2, r.side, r.lift);
        ASSERT_EQ(std::memcmp(&scalar, &lanes[k], sizeof scalar), 0)
            << "ray " << first + k << ": lanes (" << lanes[k].x << ", " << lanes[k].y << ", " << lanes[k].z
            << ") scalar (" << scalar.x << ", " << scalar.y << ", " << scalar.z << ")";
      }
      first += n;
    }
  }
  hwy::SetSupportedTargetsForTest(0);
}

// The lanes' margins themselves (origins rarely show a last-bit change of
// a bound): embreeMarginLanes against embreeSideMargin, bit for bit, on
// every target, for float origins around triangles of every size, near
// and 1e6 from the world origin.
TEST(ErrorBoundOffset, MarginsInLanesAreTheScalarMargins) {
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  constexpr size_t kLanes = detail::kOriginLanes;
  for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
    SCOPED_TRACE(hwy::TargetName(target));
    hwy::SetSupportedTargetsForTest(target);
    for (int batch = 0; batch < 200; ++batch) {
      alignas(64) double soa[12][kLanes], det[kLanes], bound[kLanes];
      FloatTriangle t[kLanes];
      glm::vec3 o[kLanes];
      for (size_t k = 0; k < kLanes; ++k) {
        const double size = std::pow(10.0, -3 + (batch + int(k)) % 8), offset = batch % 3 == 0 ? 1e6 : 0.0;
        for (int v = 0; v < 3; ++v)
          t[k][size_t(v)] =
              glm::vec3(glm::dvec3(offset) + size * glm::dvec3(uniform(rng), uniform(rng), uniform(rng)));
        o[k] = glm::vec3(glm::dvec3(offset) + size * glm::dvec3(uniform(rng), uniform(rng), uniform(rng)));
        for (int v = 0; v < 3; ++v)
          for (int c = 0; c < 3; ++c) soa[3 * v + c][k] = double(t[k][size_t(v)][c]);
        for (int c = 0; c < 3; ++c) soa[9 + c][k] = double(o[k][c]);
      }
      detail::embreeMarginLanes(soa, det, bound);
      for (size_t k = 0; k < kLanes; ++k) {
        const glm::dvec3 p0(t[k][0]);
        const glm::dvec3 n = glm::cross(glm::dvec3(t[k][1]) - p0, glm::dvec3(t[k][2]) - p0);
        const EmbreeSideMargin m = embreeSideMargin(t[k], o[k], n);  // side +1: volume = −det
        const double volume = -det[k];
        ASSERT_EQ(std::memcmp(&m.bound, &bound[k], sizeof(double)), 0) << batch << " " << k;
        ASSERT_EQ(std::memcmp(&m.volume, &volume, sizeof(double)), 0) << batch << " " << k;
      }
    }
  }
  hwy::SetSupportedTargetsForTest(0);
}

}  // namespace
}  // namespace rastray
