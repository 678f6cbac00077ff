// Transform and clip: world → view (double) → homogeneous clip space, then
// Sutherland–Hodgman against the near and far planes, and against the x/y
// guard band only when a vertex lies beyond it.
//
// Clip space here is (x, y, d, w): x = x_view / scale.x, y = y_view /
// scale.y (Camera::ndcScale), d = view depth (−z_view), and w = d for
// perspective, 1 for orthographic; NDC = (x/w, y/w). All four are affine
// in view space, so clipping by linear interpolation is exact in both
// projections, and the planes are
//   near  d − znear >= 0            far  zfar − d >= 0 (finite zfar only)
//   guard g·w − x >= 0, g·w + x >= 0, and the same for y,
// with g the guard band's half extent in NDC. After clipping every vertex
// has w >= znear > 0 (perspective), so triangles crossing w = 0 and
// cameras inside geometry project correctly.
//
// Each clip vertex carries its barycentric weights (b0, b1, b2) over the
// ORIGINAL triangle's stored vertices, so pieces keep their parent's IDs
// and interpolate everything from the stored vertices, and SampleHit's
// (b1, b2) refer to the stored order. An edge is always split from its
// inside vertex towards its outside one, so the two triangles sharing an
// edge produce bit-identical new vertices (no cracks after clipping).
#pragma once

#include <cstdint>
#include <glm/glm.hpp>

#include "common/camera.h"

namespace rastray {

// No default values: a ClipResult's nine slots stay unwritten until the
// clipper fills them (only the first `count` are ever read), so clipping a
// triangle does not first zero 500 bytes.
struct ClipVertex {
  glm::dvec4 position;  // (x, y, d, w) as above
  glm::dvec3 bary;      // weights of the original stored vertices
};

// 3 vertices + at most one more per plane (6 planes).
constexpr int kMaxClipVertices = 9;

// Two doubles in one register (GCC/Clang vector extension: SSE2's divpd on
// x86-64): two correctly rounded IEEE divisions for the price of one.
typedef double ClipPair __attribute__((vector_size(16)));

struct ClipSpace {
  Projection projection = Projection::Perspective;
  glm::dmat4 viewFromWorld{1.0};
  glm::dvec2 scale{1.0};
  double znear = 0.0, zfar = 0.0;  // zfar may be +inf (perspective)
  int width = 0, height = 0;
  glm::dvec2 guard{1.0};  // guard band half extents in NDC (>= 1)

  ClipVertex project(const glm::dvec3& view, const glm::dvec3& bary) const;
  // A world point's clip position: view transform in double, then
  // project's divisions by the scale, the two in one register
  // (clipOfReference's bits: IEEE division is correctly rounded per lane).
  // Setup calls it for every vertex and again for every kept triangle's.
  glm::dvec4 clipOf(const glm::dvec3& world) const {
    const glm::dvec4 view = viewFromWorld * glm::dvec4(world, 1.0);
    const double d = -view.z;
    const ClipPair xy = ClipPair{view.x, view.y} / ClipPair{scale.x, scale.y};
    return {xy[0], xy[1], d, projection == Projection::Perspective ? d : 1.0};
  }
  glm::dvec4 clipOfReference(const glm::dvec3& world) const {
    return project(glm::dvec3(viewFromWorld * glm::dvec4(world, 1.0)), glm::dvec3(0.0)).position;
  }
  // Image position (pixels, y down) of a clip vertex with w > 0; the two
  // divisions by w in one register, imageOfReference's bits.
  glm::dvec2 imageOf(const glm::dvec4& clip) const {
    const ClipPair q = ClipPair{clip.x, clip.y} / ClipPair{clip.w, clip.w};
    return {(q[0] + 1.0) * 0.5 * width, (1.0 - q[1]) * 0.5 * height};
  }
  glm::dvec2 imageOfReference(const glm::dvec4& clip) const {
    return {(clip.x / clip.w + 1.0) * 0.5 * width, (1.0 - clip.y / clip.w) * 0.5 * height};
  }
};

// `guardPixels`: how far beyond the image edges (in pixels) a vertex may
// lie before x/y clipping is needed (setup.h derives it from the fixed-point
// range).
ClipSpace makeClipSpace(const Camera& camera, double guardPixels);

enum class ClipOutcome { Inside, Outside, Clipped };

struct ClipResult {
  ClipOutcome outcome = ClipOutcome::Inside;
  int count = 0;  // vertices of the convex polygon in `vertices` (0 when Outside)
  bool guardClipped = false;
  ClipVertex vertices[kMaxClipVertices];
};

// Bit p set when clip position v lies outside plane p (bit 0 near, 1 far,
// 2–5 the guard band's +x, −x, +y, −y sides). A pure function of the
// vertex, so a vertex shared by many triangles is classified once: a
// triangle is trivially outside when its three masks share a bit, and
// needs no clipping when their union is 0 (what clipTriangle decides).
uint8_t outsidePlanes(const ClipSpace& space, const glm::dvec4& v);

// Clips the triangle with clip-space positions v[0..2] (bary = unit
// vectors). Trivially outside (all vertices beyond one plane): Outside.
ClipResult clipTriangle(const ClipSpace& space, const glm::dvec4 v[3]);

}  // namespace rastray
