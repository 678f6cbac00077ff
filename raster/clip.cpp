#include "raster/clip.h"

#include <cmath>

namespace rastray {

ClipSpace makeClipSpace(const Camera& camera, double guardPixels) {
  ClipSpace s;
  s.projection = camera.projection;
  s.viewFromWorld = camera.viewFromWorld;
  s.scale = camera.ndcScale();
  s.znear = camera.znear;
  s.zfar = camera.zfar;
  s.width = camera.width;
  s.height = camera.height;
  // x_image = (x_ndc + 1)·W/2 stays within [−guardPixels, W + guardPixels].
  s.guard = {1.0 + 2.0 * guardPixels / camera.width, 1.0 + 2.0 * guardPixels / camera.height};
  return s;
}

ClipVertex ClipSpace::project(const glm::dvec3& view, const glm::dvec3& bary) const {
  const double d = -view.z;
  const double w = projection == Projection::Perspective ? d : 1.0;
  return {glm::dvec4(view.x / scale.x, view.y / scale.y, d, w), bary};
}

namespace {

constexpr int kPlaneCount = 6;

// Signed distance-like value of a clip position to plane i, >= 0 inside.
double planeValue(const ClipSpace& s, int plane, const glm::dvec4& p) {
  switch (plane) {
    case 0:
      return p.z - s.znear;
    case 1:
      return std::isinf(s.zfar) ? 1.0 : s.zfar - p.z;
    case 2:
      return s.guard.x * p.w - p.x;
    case 3:
      return s.guard.x * p.w + p.x;
    case 4:
      return s.guard.y * p.w - p.y;
    default:
      return s.guard.y * p.w + p.y;
  }
}

// From the inside vertex a towards the outside vertex b (da >= 0 > db).
ClipVertex split(const ClipVertex& a, const ClipVertex& b, double da, double db) {
  const double t = da / (da - db);
  ClipVertex v;
  v.position = a.position + t * (b.position - a.position);
  // Weights that are 0 at both ends stay exactly 0 (wireframe relies on it).
  v.bary = a.bary + t * (b.bary - a.bary);
  return v;
}

}  // namespace

uint8_t outsidePlanes(const ClipSpace& space, const glm::dvec4& v) {
  uint8_t mask = 0;
  for (int p = 0; p < kPlaneCount; ++p)
    if (!(planeValue(space, p, v) >= 0.0)) mask |= uint8_t(1u << p);  // NaN counts as outside
  return mask;
}

ClipResult clipTriangle(const ClipSpace& space, const glm::dvec4 v[3]) {
  ClipResult r;
  const uint8_t mask[3] = {outsidePlanes(space, v[0]), outsidePlanes(space, v[1]),
                           outsidePlanes(space, v[2])};
  if (mask[0] & mask[1] & mask[2]) {  // all three beyond one plane
    r.outcome = ClipOutcome::Outside;
    return r;
  }
  const int outsideMask = mask[0] | mask[1] | mask[2];  // planes with a vertex outside
  r.count = 3;
  for (int i = 0; i < 3; ++i) {
    r.vertices[i].position = v[i];
    r.vertices[i].bary = glm::dvec3(0.0);
    r.vertices[i].bary[i] = 1.0;
  }
  if (outsideMask == 0) return r;

  r.outcome = ClipOutcome::Clipped;
  r.guardClipped = (outsideMask & ~3) != 0;
  ClipVertex buffer[kMaxClipVertices];
  for (int p = 0; p < kPlaneCount; ++p) {
    if (!(outsideMask & (1 << p))) continue;
    int n = 0;
    for (int i = 0; i < r.count; ++i) {
      const ClipVertex& a = r.vertices[i];
      const ClipVertex& b = r.vertices[(i + 1) % r.count];
      const double da = planeValue(space, p, a.position), db = planeValue(space, p, b.position);
      const bool aIn = da >= 0.0, bIn = db >= 0.0;
      if (aIn) buffer[n++] = a;
      if (aIn && !bIn) buffer[n++] = split(a, b, da, db);
      if (!aIn && bIn) buffer[n++] = split(b, a, db, da);
    }
    for (int i = 0; i < n; ++i) r.vertices[i] = buffer[i];
    r.count = n;
    if (n < 3) {
      r.outcome = ClipOutcome::Outside;
      r.count = 0;
      return r;
    }
  }
  return r;
}

}  // namespace rastray
