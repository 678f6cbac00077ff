// Classifying a visibility mismatch: why two renderers may legitimately
// report different (instance, triangle) at one sample, and when they may not.
//
// Classes, tested in this order (the first that applies wins):
//   1. shared-edge tie: the two hits are different triangles of the same
//      instance that share an edge (two vertices with identical world
//      positions, so indexed and duplicated vertices both count), and the
//      sample lies within `edgeDistance` pixels of that edge in the image.
//      SPEC §3 lets the renderers pick either triangle there.
//   2. depth tie: both hit, and |ΔZ| <= depthTieTolerance (below): the two
//      surfaces are closer than the depth format can tell apart (z-fighting),
//      by the reported depths or, with a scene, by the exact depths of the
//      two triangles' planes along the sample's camera ray.
//   3. near/far plane: a hit lies within planeTolerance of znear or zfar, or
//      beyond either plane (the other renderer clipped it, or should have).
//   4. silhouette edge: the sample lies within `edgeDistance` pixels of an
//      edge of the visible part of either hit triangle (its edges' image-
//      space projections clipped to the near and far planes, and the
//      segments those planes cut out of it), where vertex snapping and
//      float intersection legitimately move coverage.
//   5. genuine: none of the above: a real disagreement.
// Numeric classes (2, 3) come before the edge test because they are exact;
// the shared-edge test comes first because it is the most specific.
//
// Without a scene (image-space classification) the geometric tests use the
// images instead, and the report says so. "The edge is nearby" means: the
// 3×3 pixel neighbourhood (all samples and layers) in A holds B's hit, and
// the one in B holds A's hit (kNoId included), i.e. both images show the
// boundary between the two surfaces within a pixel. A lone speckle in one
// image is not an edge: the other image does not show the speckle's ID.
//   shared-edge tie (image-space): the edge is nearby, and the hits are
//     different triangles of the same instance;
//   silhouette edge (image-space): the edge is nearby otherwise.
// Both are one-pixel guesses, much coarser than the geometric tests.
//
// Edge distance. Default kDefaultEdgeDistance = 1/16 pixel. Why: the
// rasterizer snaps vertices to 1/256 pixel, moving an edge by at most
// √2/512 ≈ 0.003 pixel, and Embree's float ray–triangle test errs by a few
// float ULPs of the coordinates (far below 1/256 pixel for images up to
// 16384 pixels); 1/16 pixel is a 20× margin over the snapping error, yet a
// bug that moves an edge by 1/16 pixel or more (a half-pixel offset, a
// wrong fill rule on a whole edge, a wrong sample position: the Direct3D
// patterns sit on a 1/16 pixel grid) is still reported as genuine.
//
// Depth formats: the window depth z in [0, 1] of view depth d (znear n,
// zfar f, f may be +inf for perspective) is, by the formulas the rasterizer
// stores with (common/depth_formula.h, one definition for both),
//   perspective: z = f(d − n) / (d(f − n))   (1 − n/d when f = inf)
//   orthographic: z = (d − n) / (f − n)
// stored as s = z (float, unorm24, unorm16) or s = 1 − z (float-reversed,
// computed without cancellation: n/d, n(f − d)/(d(f − n)), (f − d)/(f − n)).
// The format's step in s at that depth is
//   unorm24: 2^-24;  unorm16: 2^-16;
//   float, float-reversed: ulp32(s) = 2^(floor(log2 s) − 23) (2^-149 at 0),
// and the resolution in view depth is step / |dz/dd| with
//   |dz/dd| = n f / ((f − n) d²) (n / d² when f = inf); 1 / (f − n) ortho.
// Without known planes only float-reversed has a bound: for s = n/d,
// ulp32(s) <= s · 2^-23, so the resolution is <= d · 2^-23 for every n.
// Tolerances add the rounding of the Z channel itself (float32 view depth):
//   depthTieTolerance(dA, dB) = resolution(D) + ulp32(D), D = max(dA, dB);
//   planeTolerance(p)         = resolution(p) + ulp32(p) for p = n, f.
// The geometric depth tie (with a scene) adds the error bound of a float
// ray–triangle intersection (floatIntersectionError): the ray caster's t
// comes from Embree's single-precision test, whose error grows as the ray
// grazes the plane (1/cos θ) and as the triangle thins (1/sin of its corner
// angle); without it, two nearly coplanar triangles seen at 84° were
// reported genuine although they differ by 1.8e-7 and the bound is 6e-6.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "common/camera.h"
#include "common/depth_formula.h"
#include "common/scene.h"

namespace rastray {

enum class MismatchClass : uint8_t { SharedEdgeTie, DepthTie, NearFarPlane, SilhouetteEdge, Genuine };
constexpr int kMismatchClassCount = 5;

// Machine names ("shared-edge-tie", "depth-tie", "near-far-plane",
// "silhouette-edge", "genuine") for JSON; readable names for tables.
const char* toString(MismatchClass c);
const char* displayName(MismatchClass c);

// The depth buffer whose resolution decides a depth tie is a DepthFormat
// (common/depth_formula.h), the rasterizer's own: toString and
// parseDepthFormat spell it as --depth-format does.
// One line: the step formula of the format, for the report.
std::string depthFormatFormula(DepthFormat f);

constexpr double kDefaultEdgeDistance = 1.0 / 16.0;  // pixels, see above

// The clipping planes the depth format maps between. `known` false: no
// scene and no --znear: only float-reversed has a (plane-free) resolution,
// and the near/far class is never assigned.
struct DepthPlanes {
  bool known = false;
  Projection projection = Projection::Perspective;
  double znear = 0.0;
  double zfar = std::numeric_limits<double>::infinity();
};

// ULP of a float32 at |x| (2^-149 at 0, inf for inf/NaN).
double ulp32(double x);
// The format's resolution in view depth at view depth d (formula above);
// +inf when it cannot be stated (planes unknown for a format that needs them,
// d outside (0, inf)).
double depthResolution(DepthFormat format, const DepthPlanes& planes, double d);
double depthTieTolerance(DepthFormat format, const DepthPlanes& planes, double dA, double dB);

// Bound on the error of the t a float ray–triangle test (Embree's: e1 = v0 −
// v1, e2 = v2 − v0, Ng = e1 × e2, t = Ng·(v0 − O) / Ng·D) reports for the
// stored triangle at exact distance t along `ray`, from the rounding of the
// edges, the normal and the two dot products:
//   Δt <= t (7ε + 2·2ε|e1||e2|/|Ng|) · max(1, |v0 − O| / t) / |cos θ|,
// ε = 2^-24, θ the angle between the ray and the normal. +inf for a ray
// parallel to the plane or a degenerate triangle.
double floatIntersectionError(const Scene& scene, uint32_t instance, uint32_t triangle, const Ray& ray,
                              double t);
double planeTolerance(DepthFormat format, const DepthPlanes& planes, double plane);

// What one file says is visible at one sample and layer.
struct HitRecord {
  uint32_t instance = kNoId, triangle = kNoId;
  float depth = std::numeric_limits<float>::infinity();  // view depth
  bool isHit() const { return instance != kNoId || triangle != kNoId; }
  bool sameSurface(const HitRecord& o) const { return instance == o.instance && triangle == o.triangle; }
};

// What the images show around a mismatch, for image-space classification.
struct ImageSpaceEvidence {
  bool edgeNearby = false;  // A's neighbourhood holds B's hit and B's holds A's (see above)
};

struct ClassifierSettings {
  DepthFormat depthFormat = DepthFormat::FloatReversed;
  double edgeDistance = kDefaultEdgeDistance;  // pixels
  DepthPlanes planes;
  // Both or neither: with them, the geometric tests; without, image space.
  const Scene* scene = nullptr;
  const Camera* camera = nullptr;
};

class MismatchClassifier {
 public:
  explicit MismatchClassifier(const ClassifierSettings& settings);

  bool geometric() const { return settings_.scene != nullptr && settings_.camera != nullptr; }
  const ClassifierSettings& settings() const { return settings_; }

  // `sample`: the sample position in pixels from the image's top-left
  // corner (pixel + SPEC §3 offset). Hits must be valid for the scene (the
  // caller checks IDs against it). a and b must differ.
  MismatchClass classify(glm::dvec2 sample, const HitRecord& a, const HitRecord& b,
                         const ImageSpaceEvidence& evidence);

  // Image-space distance (pixels) from `sample` to the nearest edge of the
  // hit's triangle, +inf when no part of it lies between the planes.
  double distanceToTriangleEdges(glm::dvec2 sample, const HitRecord& hit);
  // Distance to the edge a and b share, +inf when they share none.
  double distanceToSharedEdge(glm::dvec2 sample, const HitRecord& a, const HitRecord& b);

  bool isDepthTie(const HitRecord& a, const HitRecord& b) const;
  // The same test on the exact depths of the two triangles' planes along
  // the sample's camera ray (double), when that ray passes inside both
  // triangles: coincident or overlapping coplanar surfaces tie
  // there even when a renderer's own Z rounding (Embree's float t) puts the
  // reported depths a few ULPs further apart than the format resolves.
  bool isGeometricDepthTie(glm::dvec2 sample, const HitRecord& a, const HitRecord& b) const;
  bool touchesNearOrFarPlane(const HitRecord& h) const;

 private:
  double distanceToSegment(glm::dvec2 sample, const glm::dvec3& p, const glm::dvec3& q) const;
  // Image-space distance to a segment given in view space, in front of the eye.
  double distanceToViewSegment(glm::dvec2 sample, const glm::dvec3& a, const glm::dvec3& b) const;

  ClassifierSettings settings_;
};

}  // namespace rastray
