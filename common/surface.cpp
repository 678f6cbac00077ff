#include "common/surface.h"

#include "common/triangle_plane.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

namespace rastray {

namespace {

// Barycentrics (b1, b2) of point p in the plane of triangle (a, b, c).
glm::dvec2 planeBarycentrics(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b,
                             const glm::dvec3& c) {
  const glm::dvec3 e1 = b - a, e2 = c - a, d = p - a;
  const double d11 = glm::dot(e1, e1), d12 = glm::dot(e1, e2), d22 = glm::dot(e2, e2);
  const double dp1 = glm::dot(d, e1), dp2 = glm::dot(d, e2);
  const double det = d11 * d22 - d12 * d12;
  if (!(std::abs(det) > 0.0)) return glm::dvec2(0.0);
  return {(d22 * dp1 - d12 * dp2) / det, (d11 * dp2 - d12 * dp1) / det};
}

// The bits of the three stored float vertices of a triangle: what every
// per-triangle quantity below is a function of, and so the key of the
// per-thread memos (bits, so that −0 and NaN corners are told apart).
// Compared in registers, straight from the scene's arrays: a key first
// copied into a local struct was stored in 4- and 8-byte pieces and read
// back wider, stalling store-to-load forwarding on every call.
using CornerBits = std::array<uint32_t, 9>;

inline uint32_t bitsOf(const float& f) {
  uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}

inline bool sameCorners(const CornerBits& key, const glm::vec3& p0, const glm::vec3& p1,
                        const glm::vec3& p2) {
  return ((key[0] ^ bitsOf(p0.x)) | (key[1] ^ bitsOf(p0.y)) | (key[2] ^ bitsOf(p0.z)) |
          (key[3] ^ bitsOf(p1.x)) | (key[4] ^ bitsOf(p1.y)) | (key[5] ^ bitsOf(p1.z)) |
          (key[6] ^ bitsOf(p2.x)) | (key[7] ^ bitsOf(p2.y)) | (key[8] ^ bitsOf(p2.z))) == 0;
}

inline CornerBits cornerBits(const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& p2) {
  return {bitsOf(p0.x), bitsOf(p0.y), bitsOf(p0.z), bitsOf(p1.x), bitsOf(p1.y),
          bitsOf(p1.z), bitsOf(p2.x), bitsOf(p2.y), bitsOf(p2.z)};
}

// Consecutive samples (a tile's pixels, a packet's rays) mostly hit the
// triangle the previous one hit, so each thread remembers the last
// triangle's derived data. A memo hit returns exactly the values the
// computation would (they depend on the corners alone, compared bit for
// bit), so results do not depend on the order samples arrive in. Plain
// aggregates without initializers: thread storage starts zero-filled
// (valid false) and needs no per-access initialization check.
struct PlaneMemo {
  bool valid;
  CornerBits key;
  int slot1, slot2;      // canonical (lexicographic) rank of stored corners 1 and 2
  glm::dvec3 a, e1, e2;  // first canonical corner, edges to the other two
  // What depends on the triangle and the ray's origin alone, for the last
  // origin (a perspective camera's primary rays share theirs): s = origin −
  // a, q = s × e1 and e2·q, the same operations as without the memo.
  bool originValid;
  glm::dvec3 origin, s, q;
  double e2DotQ;
};
struct NormalMemo {
  bool valid;
  CornerBits key;
  glm::dvec3 normal;  // unit cross(p1 − p0, p2 − p0), (0, 0, 1) when degenerate
};
thread_local PlaneMemo planeMemo;
thread_local NormalMemo normalMemo;

// The unit face normal of stored corners p0, p1, p2 (CCW front).
glm::dvec3 faceNormal(const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& p2) {
  const glm::dvec3 n = glm::cross(p1 - p0, p2 - p0);
  const double length = glm::length(n);
  return length > 0.0 ? n / length : glm::dvec3(0.0, 0.0, 1.0);
}

// The face normal (a square root and three divisions) from the memo when
// the previous call was on the same triangle.
inline glm::dvec3 memoisedFaceNormal(const glm::vec3& f0, const glm::vec3& f1, const glm::vec3& f2) {
  NormalMemo& memo = normalMemo;
  if (!memo.valid || !sameCorners(memo.key, f0, f1, f2)) {
    memo.key = cornerBits(f0, f1, f2);
    memo.normal = faceNormal(glm::dvec3(f0), glm::dvec3(f1), glm::dvec3(f2));
    memo.valid = true;
  }
  return memo.normal;
}

// makeSurfacePoint from the hit's fields as values: callers pass b1 and b2
// in registers (a SampleHit just returned through memory, read back as
// one 8-byte pair, stalled store-to-load forwarding).
SurfacePoint surfacePointAt(const Scene& scene, uint32_t instance, uint32_t triangle, float b1, float b2) {
  SurfacePoint sp;
  sp.instance = instance;
  sp.triangle = triangle;
  sp.b1 = b1;
  sp.b2 = b2;
  const Instance& inst = scene.instances[instance];
  sp.material = &scene.materials[inst.material];
  const glm::uvec3 t = scene.triangle(instance, triangle);
  const double b0 = 1.0 - double(b1) - double(b2);
  const glm::vec3 &f0 = scene.positions[t.x], &f1 = scene.positions[t.y], &f2 = scene.positions[t.z];
  const glm::dvec3 p0(f0), p1(f1), p2(f2);
  sp.position = b0 * p0 + double(b1) * p1 + double(b2) * p2;

  sp.geometricNormal = memoisedFaceNormal(f0, f1, f2);
  sp.shadingNormal = sp.geometricNormal;
  if (inst.normals == NormalSource::Authored) {
    const glm::dvec3 ns = b0 * glm::dvec3(scene.normals[t.x]) + double(b1) * glm::dvec3(scene.normals[t.y]) +
                          double(b2) * glm::dvec3(scene.normals[t.z]);
    const double nl = glm::length(ns);
    if (nl > 0.0 && std::isfinite(nl)) sp.shadingNormal = ns / nl;  // zero: keep the face normal
  }
  if (inst.hasTexcoords)
    sp.uv = float(b0) * scene.texcoords[t.x] + b1 * scene.texcoords[t.y] + b2 * scene.texcoords[t.z];
  if (inst.hasColors)
    sp.color = float(b0) * scene.colors[t.x] + b1 * scene.colors[t.y] + b2 * scene.colors[t.z];
  if (inst.firstTangent != kNoId) {
    const glm::vec4* c = &scene.tangents[size_t(inst.firstTangent) + 3 * size_t(triangle)];
    const glm::dvec3 xyz =
        b0 * glm::dvec3(c[0]) + double(b1) * glm::dvec3(c[1]) + double(b2) * glm::dvec3(c[2]);
    // Handedness: the corners' (one value per face when generated), by the
    // weighted majority where a file's corners disagree.
    const double w = b0 * c[0].w + double(b1) * c[1].w + double(b2) * c[2].w;
    sp.tangent = glm::dvec4(xyz, w < 0.0 ? -1.0 : 1.0);
  }
  return sp;
}

}  // namespace

SurfacePoint makeSurfacePoint(const Scene& scene, const SampleHit& hit) {
  return surfacePointAt(scene, hit.instance, hit.triangle, hit.b1, hit.b2);
}

glm::dvec3 faceNormalOfCorners(const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& p2) {
  return faceNormal(p0, p1, p2);
}

glm::dvec3 triangleFaceNormal(const Scene& scene, uint32_t instance, uint32_t triangle) {
  const glm::uvec3 t = scene.triangle(instance, triangle);
  return memoisedFaceNormal(scene.positions[t.x], scene.positions[t.y], scene.positions[t.z]);
}

SurfacePoint surfacePointOnRay(const Scene& scene, const Ray& ray, const SampleHit& hit) {
  // refineHit's steps, its result kept in registers.
  if (!hit.valid()) return makeSurfacePoint(scene, hit);
  double t;
  glm::dvec2 b;
  glm::dvec2 clamped;
  if (!intersectTrianglePlane(scene, hit.instance, hit.triangle, ray, &t, &b) ||
      !refinedBarycentrics(ray, t, b, &clamped))
    return makeSurfacePoint(scene, hit);
  return surfacePointAt(scene, hit.instance, hit.triangle, float(clamped.x), float(clamped.y));
}

namespace {

// The plane memo brought up to date for corners f0, f1, f2.
PlaneMemo& planeMemoFor(const glm::vec3& f0, const glm::vec3& f1, const glm::vec3& f2) {
  PlaneMemo& memo = planeMemo;
  if (!memo.valid || !sameCorners(memo.key, f0, f1, f2)) {
    // The corners in a canonical (lexicographic) order, so that coincident
    // triangles listed with their vertices in another order (duplicated or
    // reversed faces) get bit-identical t: their layers then tie exactly
    // and are ordered by (instance, triangle) in both renderers.
    const std::array<glm::dvec3, 3> corner = {glm::dvec3(f0), glm::dvec3(f1), glm::dvec3(f2)};
    // Three compare-exchanges (a sorting network) instead of std::sort: the
    // same order for distinct corners; equal corners make det 0 below, so
    // their order never shows.
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
    memo.key = cornerBits(f0, f1, f2);
    for (int slot = 0; slot < 3; ++slot) {
      if (order[size_t(slot)] == 1) memo.slot1 = slot;
      if (order[size_t(slot)] == 2) memo.slot2 = slot;
    }
    memo.a = corner[size_t(order[0])];
    memo.e1 = corner[size_t(order[1])] - memo.a;
    memo.e2 = corner[size_t(order[2])] - memo.a;
    memo.valid = true;
    memo.originValid = false;
  }
  return memo;
}

}  // namespace

TrianglePlane trianglePlane(const Scene& scene, uint32_t instance, uint32_t triangle) {
  const glm::uvec3 v = scene.triangle(instance, triangle);
  const PlaneMemo& memo = planeMemoFor(scene.positions[v.x], scene.positions[v.y], scene.positions[v.z]);
  return {memo.a, memo.e1, memo.e2, memo.slot1, memo.slot2};
}

bool intersectTrianglePlane(const Scene& scene, uint32_t instance, uint32_t triangle, const Ray& ray,
                            double* t, glm::dvec2* barycentrics) {
  const glm::uvec3 v = scene.triangle(instance, triangle);
  PlaneMemo& memo = planeMemoFor(scene.positions[v.x], scene.positions[v.y], scene.positions[v.z]);
  const glm::dvec3 e1 = memo.e1, e2 = memo.e2;
  // Compared bit for bit: −0 and +0 may give differently signed zeros in s.
  if (!memo.originValid || std::memcmp(&memo.origin, &ray.origin, sizeof memo.origin) != 0) {
    memo.origin = ray.origin;
    memo.s = ray.origin - memo.a;
    memo.q = glm::cross(memo.s, e1);
    memo.e2DotQ = glm::dot(e2, memo.q);
    memo.originValid = true;
  }
  // Möller–Trumbore in double, without the inside test.
  const glm::dvec3 p = glm::cross(ray.direction, e2);
  const double det = glm::dot(e1, p);
  if (!(std::abs(det) > 0.0)) return false;
  const double inv = 1.0 / det;
  const glm::dvec3 s = memo.s, q = memo.q;
  const double u = glm::dot(s, p) * inv;
  const double w = glm::dot(ray.direction, q) * inv;
  *t = memo.e2DotQ * inv;
  // Back to the stored order: canonical corner 0 weighs 1 − u − w, 1 u, 2 w.
  const double w0 = 1.0 - u - w;
  auto weightOf = [&](int slot) { return slot == 0 ? w0 : slot == 1 ? u : w; };
  *barycentrics = glm::dvec2(weightOf(memo.slot1), weightOf(memo.slot2));
  return std::isfinite(*t) && std::isfinite(u) && std::isfinite(w);
}

SampleHit refineHit(const Scene& scene, const Ray& ray, const SampleHit& hit) {
  if (!hit.valid()) return hit;
  double t;
  glm::dvec2 b;
  if (!intersectTrianglePlane(scene, hit.instance, hit.triangle, ray, &t, &b)) return hit;
  return refineHitAt(ray, hit, t, b);
}

TextureFootprint pixelFootprint(const Scene& scene, const Camera& camera, const SurfacePoint& point,
                                glm::dvec2 imagePosition) {
  TextureFootprint fp;
  const Instance& inst = scene.instances[point.instance];
  if (!inst.hasTexcoords) return fp;
  const glm::uvec3 t = scene.triangle(point.instance, point.triangle);
  const glm::dvec3 a(scene.positions[t.x]), b(scene.positions[t.y]), c(scene.positions[t.z]);
  const glm::dvec3 n = point.geometricNormal;
  const glm::vec2 uv0 = scene.texcoords[t.x], uv1 = scene.texcoords[t.y], uv2 = scene.texcoords[t.z];

  // uv where the camera ray through an image position meets the triangle's
  // plane in front of the camera.
  auto uvAt = [&](glm::dvec2 image, glm::vec2* uv) {
    const Ray r = camera.primaryRay(image);
    const double denom = glm::dot(r.direction, n);
    if (!(std::abs(denom) > 0.0)) return false;
    const double tPlane = glm::dot(a - r.origin, n) / denom;
    if (!(tPlane > 0.0) || !std::isfinite(tPlane)) return false;  // beyond the horizon
    const glm::dvec2 bc = planeBarycentrics(r.origin + r.direction * tPlane, a, b, c);
    *uv = float(1.0 - bc.x - bc.y) * uv0 + float(bc.x) * uv1 + float(bc.y) * uv2;
    return std::isfinite(uv->x) && std::isfinite(uv->y);
  };
  // One-sided differences; near the horizon the forward neighbour may
  // miss the plane, then the backward one is used, and failing both the
  // footprint is unbounded (the coarsest mip level).
  constexpr float kUnbounded = 1e6f;
  auto derivative = [&](glm::vec2 centre, glm::dvec2 step) {
    glm::vec2 uv;
    if (uvAt(imagePosition + step, &uv)) return uv - centre;
    if (uvAt(imagePosition - step, &uv)) return centre - uv;
    return glm::vec2(kUnbounded);
  };
  glm::vec2 centre;
  if (!uvAt(imagePosition, &centre)) {
    fp.dUVdx = fp.dUVdy = glm::vec2(kUnbounded);
    return fp;
  }
  fp.dUVdx = derivative(centre, {1.0, 0.0});
  fp.dUVdy = derivative(centre, {0.0, 1.0});
  return fp;
}

}  // namespace rastray
