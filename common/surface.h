// From a preliminary hit (common/hit.h) to the full surface description
// shading needs: the one place both renderers turn (instance, triangle,
// b1, b2) into geometry.
#pragma once

#include <cmath>

#include <glm/glm.hpp>

#include "common/camera.h"
#include "common/hit.h"
#include "common/scene.h"

namespace rastray {

struct SurfacePoint {
  uint32_t instance = kNoId;
  uint32_t triangle = kNoId;
  const Material* material = nullptr;
  float b1 = 0.0f, b2 = 0.0f;
  // Rebuilt from the barycentrics over the stored float vertices, in
  // double: the error is that of the barycentrics, not of a ray's t
  // (Ray Tracing Gems ch. 6 rebuilds hit points the same way).
  glm::dvec3 position{0.0};
  glm::dvec3 geometricNormal{0.0, 0.0, 1.0};  // unit; the CCW (front) side
  glm::dvec3 shadingNormal{0.0, 0.0, 1.0};    // unit; authored and interpolated, else geometric
  glm::vec2 uv{0.0f};
  // COLOR_0 interpolated with the barycentrics: linear straight RGBA,
  // white where the instance has none. Shading multiplies it into the
  // base colour (glTF: factor × texture × COLOR_0).
  glm::vec4 color{1.0f};
  // The tangent frame of a normal-mapped instance (Instance::firstTangent):
  // the corners' world tangents interpolated (not normalised; the shader
  // orthogonalises against the shading normal) in xyz, handedness ±1 in w.
  // Zero where the instance has no tangents.
  glm::dvec4 tangent{0.0};
};

SurfacePoint makeSurfacePoint(const Scene& scene, const SampleHit& hit);
// The unit face normal of a stored triangle (CCW front; (0, 0, 1) when
// degenerate), in double: makeSurfacePoint's geometricNormal, bit for bit
// (the same per-thread memo).
glm::dvec3 triangleFaceNormal(const Scene& scene, uint32_t instance, uint32_t triangle);
// makeSurfacePoint(scene, refineHit(scene, ray, hit)), bit-identical, in one
// call: the refined barycentrics go on in registers, not through a
// SampleHit in memory (written in 4- and 8-byte pieces and read back as an
// 8-byte pair: a store-forwarding stall per sample). For shading a hit
// along its primary ray.
SurfacePoint surfacePointOnRay(const Scene& scene, const Ray& ray, const SampleHit& hit);

// Where a ray meets the plane of stored triangle (instance, triangle), in
// double precision: t along the ray and barycentrics (b1, b2), with no
// inside test. Both renderers refine their primary hits with it before
// shading, so a sample that both attribute to the same triangle is shaded
// from bit-identical inputs (hybrid == ray cast where hits agree). False
// when the ray is parallel to the plane or the triangle is degenerate.
bool intersectTrianglePlane(const Scene& scene, uint32_t instance, uint32_t triangle, const Ray& ray,
                            double* t, glm::dvec2* barycentrics);

// A hit refined by intersectTrianglePlane: depth = t · depthPerT, the
// view depth of the plane point along the ray, and barycentrics clamped
// into the triangle: b1, b2 below 0 become 0, then a pair with b1 + b2 > 1
// is scaled by 1 / (b1 + b2) onto the edge v1–v2 (a point of the
// triangle near the plane point, not the nearest one). A sample the renderer
// found inside the triangle whose double-precision plane point lies just
// outside (grazing angles) is thus shaded from the triangle's edge, never
// from attributes extrapolated beyond it. The hit is returned unchanged
// when the plane cannot be intersected or the intersection is not ahead
// of the ray (t <= 0, or a depth that is not finite).
SampleHit refineHit(const Scene& scene, const Ray& ray, const SampleHit& hit);
// refineHit from the plane point (t, barycentrics) intersectTrianglePlane
// already returned true for this hit and ray: the same result, without
// intersecting the plane again. Inline: a 20-byte SampleHit returned
// through memory and copied on was read back in wider pieces than it was
// written (a store-forwarding stall per sample).
//
// refinedBarycentrics is its test and clamp: false when the hit is kept
// (the plane is not ahead of the ray), else the clamped barycentrics.
inline bool refinedBarycentrics(const Ray& ray, double t, glm::dvec2 b, glm::dvec2* clamped) {
  // A plane behind the origin (or at it) is not what the renderer saw:
  // keep its hit.
  if (!(t > 0.0) || !std::isfinite(t * ray.depthPerT)) return false;
  // Into the triangle (above): at grazing angles the plane point may fall
  // just outside, and attributes must not be extrapolated there.
  b = glm::max(b, glm::dvec2(0.0));
  if (b.x + b.y > 1.0) b /= b.x + b.y;
  *clamped = b;
  return true;
}
inline SampleHit refineHitAt(const Ray& ray, const SampleHit& hit, double t, glm::dvec2 b) {
  glm::dvec2 clamped;
  if (!refinedBarycentrics(ray, t, b, &clamped)) return hit;
  SampleHit refined = hit;
  refined.b1 = float(clamped.x);
  refined.b2 = float(clamped.y);
  refined.depth = float(t * ray.depthPerT);
  return refined;
}

// Texture-space footprint of one pixel at a surface point: d(uv)/dx and
// d(uv)/dy per image pixel. Both renderers compute it the same way, from
// the camera rays through the neighbouring pixel positions intersected
// with the triangle's plane, so texture filtering matches exactly; zero
// means "sample the finest level" (used for secondary hits).
struct TextureFootprint {
  glm::vec2 dUVdx{0.0f};
  glm::vec2 dUVdy{0.0f};
};

TextureFootprint pixelFootprint(const Scene& scene, const Camera& camera, const SurfacePoint& point,
                                glm::dvec2 imagePosition);

}  // namespace rastray
