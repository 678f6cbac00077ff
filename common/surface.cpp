#include "common/surface.h"

#include <algorithm>
#include <array>
#include <cmath>

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

}  // namespace

SurfacePoint makeSurfacePoint(const Scene& scene, const SampleHit& hit) {
  SurfacePoint sp;
  sp.instance = hit.instance;
  sp.triangle = hit.triangle;
  sp.b1 = hit.b1;
  sp.b2 = hit.b2;
  const Instance& inst = scene.instances[hit.instance];
  sp.material = &scene.materials[inst.material];
  const glm::uvec3 t = scene.triangle(hit.instance, hit.triangle);
  const double b0 = 1.0 - double(hit.b1) - double(hit.b2);
  const glm::dvec3 p0(scene.positions[t.x]), p1(scene.positions[t.y]), p2(scene.positions[t.z]);
  sp.position = b0 * p0 + double(hit.b1) * p1 + double(hit.b2) * p2;

  const glm::dvec3 n = glm::cross(p1 - p0, p2 - p0);
  const double length = glm::length(n);
  sp.geometricNormal = length > 0.0 ? n / length : glm::dvec3(0.0, 0.0, 1.0);
  sp.shadingNormal = sp.geometricNormal;
  if (inst.normals == NormalSource::Authored) {
    const glm::dvec3 ns = b0 * glm::dvec3(scene.normals[t.x]) +
                          double(hit.b1) * glm::dvec3(scene.normals[t.y]) +
                          double(hit.b2) * glm::dvec3(scene.normals[t.z]);
    const double nl = glm::length(ns);
    if (nl > 0.0 && std::isfinite(nl)) sp.shadingNormal = ns / nl;  // zero: keep the face normal
  }
  if (inst.hasTexcoords)
    sp.uv = float(b0) * scene.texcoords[t.x] + hit.b1 * scene.texcoords[t.y] + hit.b2 * scene.texcoords[t.z];
  if (inst.hasColors)
    sp.color = float(b0) * scene.colors[t.x] + hit.b1 * scene.colors[t.y] + hit.b2 * scene.colors[t.z];
  return sp;
}

bool intersectTrianglePlane(const Scene& scene, uint32_t instance, uint32_t triangle, const Ray& ray,
                            double* t, glm::dvec2* barycentrics) {
  const glm::uvec3 v = scene.triangle(instance, triangle);
  // The corners in a canonical (lexicographic) order, so that coincident
  // triangles listed with their vertices in another order (duplicated or
  // reversed faces) get bit-identical t: their layers then tie exactly and
  // are ordered by (instance, triangle) in both renderers.
  std::array<glm::dvec3, 3> corner = {glm::dvec3(scene.positions[v.x]), glm::dvec3(scene.positions[v.y]),
                                      glm::dvec3(scene.positions[v.z])};
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
  const glm::dvec3 &a = corner[size_t(order[0])], &b = corner[size_t(order[1])],
                   &c = corner[size_t(order[2])];
  // Möller–Trumbore in double, without the inside test.
  const glm::dvec3 e1 = b - a, e2 = c - a;
  const glm::dvec3 p = glm::cross(ray.direction, e2);
  const double det = glm::dot(e1, p);
  if (!(std::abs(det) > 0.0)) return false;
  const double inv = 1.0 / det;
  const glm::dvec3 s = ray.origin - a;
  const double u = glm::dot(s, p) * inv;
  const glm::dvec3 q = glm::cross(s, e1);
  const double w = glm::dot(ray.direction, q) * inv;
  *t = glm::dot(e2, q) * inv;
  // Back to the stored order: weight[k] belongs to stored corner k.
  std::array<double, 3> weight{};
  weight[size_t(order[0])] = 1.0 - u - w;
  weight[size_t(order[1])] = u;
  weight[size_t(order[2])] = w;
  *barycentrics = glm::dvec2(weight[1], weight[2]);
  return std::isfinite(*t) && std::isfinite(u) && std::isfinite(w);
}

SampleHit refineHit(const Scene& scene, const Ray& ray, const SampleHit& hit) {
  if (!hit.valid()) return hit;
  double t;
  glm::dvec2 b;
  if (!intersectTrianglePlane(scene, hit.instance, hit.triangle, ray, &t, &b)) return hit;
  return refineHitAt(ray, hit, t, b);
}

SampleHit refineHitAt(const Ray& ray, const SampleHit& hit, double t, glm::dvec2 b) {
  // A plane behind the origin (or at it) is not what the renderer saw:
  // keep its hit.
  if (!(t > 0.0) || !std::isfinite(t * ray.depthPerT)) return hit;
  // Into the triangle (header): at grazing angles the plane point may fall
  // just outside, and attributes must not be extrapolated there.
  b = glm::max(b, glm::dvec2(0.0));
  if (b.x + b.y > 1.0) b /= b.x + b.y;
  SampleHit refined = hit;
  refined.b1 = float(b.x);
  refined.b2 = float(b.y);
  refined.depth = float(t * ray.depthPerT);
  return refined;
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
