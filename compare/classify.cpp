#include "compare/classify.h"

#include <algorithm>
#include <cmath>

#include "common/depth_formula.h"
#include "common/surface.h"

namespace rastray {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

}  // namespace

const char* toString(MismatchClass c) {
  switch (c) {
    case MismatchClass::SharedEdgeTie:
      return "shared-edge-tie";
    case MismatchClass::DepthTie:
      return "depth-tie";
    case MismatchClass::NearFarPlane:
      return "near-far-plane";
    case MismatchClass::SilhouetteEdge:
      return "silhouette-edge";
    case MismatchClass::Genuine:
      return "genuine";
  }
  return "?";
}

const char* displayName(MismatchClass c) {
  switch (c) {
    case MismatchClass::SharedEdgeTie:
      return "shared-edge tie";
    case MismatchClass::DepthTie:
      return "depth tie";
    case MismatchClass::NearFarPlane:
      return "near/far plane";
    case MismatchClass::SilhouetteEdge:
      return "silhouette edge";
    case MismatchClass::Genuine:
      return "genuine";
  }
  return "?";
}

std::string depthFormatFormula(DepthFormat f) {
  const char* planes =
      "view-depth resolution = step / |dz/dd|, |dz/dd| = n f/((f-n) d^2) (n/d^2 for f = inf), "
      "1/(f-n) ortho";
  switch (f) {
    case DepthFormat::FloatReversed:
      return std::string("float-reversed: stores 1-z; step = ulp32(1-z) = 2^(floor(log2(1-z))-23); ") +
             planes + "; without planes <= d*2^-23; tie when |dZ| <= resolution(D) + ulp32(D), D = max depth";
    case DepthFormat::Float:
      return std::string("float: stores z; step = ulp32(z) = 2^(floor(log2 z)-23); ") + planes +
             "; tie when |dZ| <= resolution(D) + ulp32(D), D = max depth";
    case DepthFormat::Unorm24:
      return std::string("unorm24: stores z; step = 2^-24; ") + planes +
             "; tie when |dZ| <= resolution(D) + ulp32(D), D = max depth";
    case DepthFormat::Unorm16:
      return std::string("unorm16: stores z; step = 2^-16; ") + planes +
             "; tie when |dZ| <= resolution(D) + ulp32(D), D = max depth";
  }
  return "?";
}

double ulp32(double x) { return float32Ulp(x); }

double depthResolution(DepthFormat format, const DepthPlanes& planes, double d) {
  if (!(d > 0.0) || std::isinf(d)) return kInf;
  if (!planes.known) return format == DepthFormat::FloatReversed ? d * std::ldexp(1.0, -23) : kInf;
  // The formulas the rasterizer stores with: step at the stored value / |dz/dd|.
  return viewDepthResolution(format, planes.projection, planes.znear, planes.zfar, d);
}

double depthTieTolerance(DepthFormat format, const DepthPlanes& planes, double dA, double dB) {
  const double d = std::max(dA, dB);
  return depthResolution(format, planes, d) + ulp32(d);
}

double planeTolerance(DepthFormat format, const DepthPlanes& planes, double plane) {
  return depthResolution(format, planes, plane) + ulp32(plane);
}

double floatIntersectionError(const Scene& scene, uint32_t instance, uint32_t triangle, const Ray& ray,
                              double t) {
  const glm::uvec3 idx = scene.triangle(instance, triangle);
  const glm::dvec3 v0(scene.positions[idx.x]), v1(scene.positions[idx.y]), v2(scene.positions[idx.z]);
  const glm::dvec3 e1 = v0 - v1, e2 = v2 - v0, ng = glm::cross(e1, e2);
  const double area2 = glm::length(ng);
  if (!(area2 > 0.0)) return kInf;
  const double cosine = std::fabs(glm::dot(ng, ray.direction)) / area2;
  if (!(cosine > 0.0)) return kInf;
  constexpr double kEps = 0x1p-24;  // float unit roundoff
  // Relative error of the float normal's direction: 2ε|e1||e2| / |e1 × e2|
  // (1/sin of the corner angle, large for slivers), counted in both dots.
  const double normalError = 2.0 * kEps * glm::length(e1) * glm::length(e2) / area2;
  const double reach = std::max(1.0, glm::length(v0 - ray.origin) / std::max(t, 1e-300));
  return t * (7.0 * kEps + 2.0 * normalError) * reach / cosine;
}

MismatchClassifier::MismatchClassifier(const ClassifierSettings& settings) : settings_(settings) {}

bool MismatchClassifier::isDepthTie(const HitRecord& a, const HitRecord& b) const {
  if (!a.isHit() || !b.isHit()) return false;
  const double dA = a.depth, dB = b.depth;
  if (!std::isfinite(dA) || !std::isfinite(dB)) return false;
  const double tol = depthTieTolerance(settings_.depthFormat, settings_.planes, dA, dB);
  return std::fabs(dA - dB) <= tol;  // tol = inf only when d <= 0, a hit behind the eye: no tie then
}

bool MismatchClassifier::isGeometricDepthTie(glm::dvec2 sample, const HitRecord& a,
                                             const HitRecord& b) const {
  if (!geometric() || !a.isHit() || !b.isHit()) return false;
  const Ray ray = settings_.camera->primaryRay(sample);
  double tA, tB;
  glm::dvec2 baryA, baryB;
  if (!intersectTrianglePlane(*settings_.scene, a.instance, a.triangle, ray, &tA, &baryA) ||
      !intersectTrianglePlane(*settings_.scene, b.instance, b.triangle, ray, &tB, &baryB))
    return false;
  // Both surfaces must be there: the ray passes inside both triangles (up
  // to rounding; samples at their edges are the edge classes' business).
  const auto inside = [](const glm::dvec2& w) { return std::min({w.x, w.y, 1.0 - w.x - w.y}) >= -1e-9; };
  if (!inside(baryA) || !inside(baryB)) return false;
  const double dA = tA * ray.depthPerT, dB = tB * ray.depthPerT;
  if (!(dA > 0.0) || !(dB > 0.0) || !std::isfinite(dA) || !std::isfinite(dB)) return false;
  const double rayError = std::max(floatIntersectionError(*settings_.scene, a.instance, a.triangle, ray, tA),
                                   floatIntersectionError(*settings_.scene, b.instance, b.triangle, ray, tB));
  return std::fabs(dA - dB) <=
         depthTieTolerance(settings_.depthFormat, settings_.planes, dA, dB) + rayError * ray.depthPerT;
}

bool MismatchClassifier::touchesNearOrFarPlane(const HitRecord& h) const {
  const DepthPlanes& p = settings_.planes;
  if (!p.known || !h.isHit() || std::isnan(h.depth)) return false;
  const double d = h.depth;
  const double nearTol = planeTolerance(settings_.depthFormat, p, p.znear);
  if (d <= p.znear + nearTol) return true;  // at or in front of the near plane
  if (std::isinf(p.zfar)) return false;
  const double farTol = planeTolerance(settings_.depthFormat, p, p.zfar);
  return d >= p.zfar - farTol;  // at or beyond the far plane
}

double MismatchClassifier::distanceToSegment(glm::dvec2 sample, const glm::dvec3& worldP,
                                             const glm::dvec3& worldQ) const {
  const Camera& cam = *settings_.camera;
  glm::dvec3 p = glm::dvec3(cam.viewFromWorld * glm::dvec4(worldP, 1.0));
  glm::dvec3 q = glm::dvec3(cam.viewFromWorld * glm::dvec4(worldQ, 1.0));
  // Clip the edge to znear <= depth <= zfar in view space (depth = −z):
  // the part outside was never rendered, and perspective projection of a
  // point behind the eye would flip through infinity.
  double t0 = 0.0, t1 = 1.0;
  const double dp = -p.z, dq = -q.z;
  auto clipAgainst = [&](double fp, double fq) {  // keep f >= 0 along p + t(q − p)
    if (fp < 0.0 && fq < 0.0) return false;
    if (fp < 0.0) t0 = std::max(t0, fp / (fp - fq));
    if (fq < 0.0) t1 = std::min(t1, fp / (fp - fq));
    return t0 <= t1;
  };
  if (!clipAgainst(dp - cam.znear, dq - cam.znear)) return kInf;
  if (std::isfinite(cam.zfar) && !clipAgainst(cam.zfar - dp, cam.zfar - dq)) return kInf;
  return distanceToViewSegment(sample, p + t0 * (q - p), p + t1 * (q - p));
}

double MismatchClassifier::distanceToViewSegment(glm::dvec2 sample, const glm::dvec3& a,
                                                 const glm::dvec3& b) const {
  const Camera& cam = *settings_.camera;
  const glm::dvec2 scale = cam.ndcScale();
  auto project = [&](const glm::dvec3& v) {
    const double w = cam.projection == Projection::Orthographic ? 1.0 : -v.z;
    return cam.imageFromNdc({v.x / (scale.x * w), v.y / (scale.y * w)});
  };
  const glm::dvec2 ia = project(a), ib = project(b);
  // Point-to-segment distance in pixels.
  const glm::dvec2 ab = ib - ia, as = sample - ia;
  const double len2 = glm::dot(ab, ab);
  const double t = len2 > 0.0 ? std::clamp(glm::dot(as, ab) / len2, 0.0, 1.0) : 0.0;
  return glm::length(sample - (ia + t * ab));
}

double MismatchClassifier::distanceToTriangleEdges(glm::dvec2 sample, const HitRecord& hit) {
  if (!geometric() || !hit.isHit()) return kInf;
  const Scene& scene = *settings_.scene;
  const glm::uvec3& tri = scene.triangle(hit.instance, hit.triangle);
  double best = kInf;
  for (int e = 0; e < 3; ++e) {
    const glm::dvec3 p(scene.positions[tri[e]]), q(scene.positions[tri[(e + 1) % 3]]);
    best = std::min(best, distanceToSegment(sample, p, q));
  }
  // Where the triangle crosses the near or the far plane its visible part
  // has an edge too: the segment the plane cuts out of it.
  const Camera& cam = *settings_.camera;
  glm::dvec3 v[3];
  for (int k = 0; k < 3; ++k)
    v[k] = glm::dvec3(cam.viewFromWorld * glm::dvec4(glm::dvec3(scene.positions[tri[k]]), 1.0));
  for (const double plane : {cam.znear, cam.zfar}) {
    if (!std::isfinite(plane)) continue;
    std::vector<glm::dvec3> cut;
    for (int e = 0; e < 3; ++e) {
      const glm::dvec3 &p = v[e], &q = v[(e + 1) % 3];
      const double fp = -p.z - plane, fq = -q.z - plane;
      if ((fp < 0.0) != (fq < 0.0)) cut.push_back(p + (fp / (fp - fq)) * (q - p));
    }
    if (cut.size() == 2) best = std::min(best, distanceToViewSegment(sample, cut[0], cut[1]));
  }
  return best;
}

double MismatchClassifier::distanceToSharedEdge(glm::dvec2 sample, const HitRecord& a, const HitRecord& b) {
  if (!geometric() || !a.isHit() || !b.isHit() || a.instance != b.instance || a.triangle == b.triangle)
    return kInf;
  const Scene& scene = *settings_.scene;
  const glm::uvec3& ta = scene.triangle(a.instance, a.triangle);
  const glm::uvec3& tb = scene.triangle(b.instance, b.triangle);
  // Common vertices by world position (bitwise equal floats), so meshes
  // without an index buffer (every vertex duplicated) share edges too.
  std::vector<glm::vec3> common;
  for (int i = 0; i < 3; ++i) {
    const glm::vec3& pa = scene.positions[ta[i]];
    bool shared = false;
    for (int j = 0; j < 3; ++j) shared = shared || pa == scene.positions[tb[j]];
    if (shared && std::find(common.begin(), common.end(), pa) == common.end()) common.push_back(pa);
  }
  if (common.size() != 2) return kInf;  // 3: the same triangle twice; <2: no edge
  return distanceToSegment(sample, glm::dvec3(common[0]), glm::dvec3(common[1]));
}

MismatchClass MismatchClassifier::classify(glm::dvec2 sample, const HitRecord& a, const HitRecord& b,
                                           const ImageSpaceEvidence& evidence) {
  const double limit = settings_.edgeDistance;
  if (geometric()) {
    if (distanceToSharedEdge(sample, a, b) <= limit) return MismatchClass::SharedEdgeTie;
  } else if (a.isHit() && b.isHit() && a.instance == b.instance && a.triangle != b.triangle &&
             evidence.edgeNearby) {
    return MismatchClass::SharedEdgeTie;
  }
  if (isDepthTie(a, b) || isGeometricDepthTie(sample, a, b)) return MismatchClass::DepthTie;
  if (touchesNearOrFarPlane(a) || touchesNearOrFarPlane(b)) return MismatchClass::NearFarPlane;
  if (geometric()) {
    if (distanceToTriangleEdges(sample, a) <= limit || distanceToTriangleEdges(sample, b) <= limit)
      return MismatchClass::SilhouetteEdge;
  } else if (evidence.edgeNearby) {
    return MismatchClass::SilhouetteEdge;
  }
  return MismatchClass::Genuine;
}

}  // namespace rastray
