// The refinement planes of setup.h (RefinePlane), the face normals and the
// kept unclipped triangles' planes (setup_planes.h) a block of triangles at
// a time in Highway double lanes. Highway compiles the lane function once per
// SIMD target (foreach_target.h re-includes this file); the host code
// gathers the corners, runs the lanes and scatters. Built with
// -ffp-contract=off (the top-level CMakeLists.txt): every operation below
// is the reference's (planeMemoFor's sorting network and subtractions in
// common/surface.cpp, glm's cross and dot; clipOf, imageOf, windowDepth
// and setupPlanes), in its order, so the bits are the same on every target.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "raster/setup_planes.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <cstddef>
#include <cstdint>

#include <hwy/highway.h>

#include "raster/setup.h"
#include "raster/setup_planes.h"

#ifndef RASTRAY_SETUP_PLANES_BLOCK_
#define RASTRAY_SETUP_PLANES_BLOCK_
namespace rastray {
namespace setup_planes_detail {

constexpr size_t kBlock = 64;  // a multiple of every target's double lane count

// A block of triangles' corners (in stored order) and their planes.
struct PlaneBlock {
  size_t lanes = 0;                    // a whole number of vectors
  alignas(64) double c[3][3][kBlock];  // [corner][axis][lane]
  alignas(64) double e1[3][kBlock], e2[3][kBlock], s[3][kBlock], q[3][kBlock];
  alignas(64) double e2DotQ[kBlock], slot1[kBlock], slot2[kBlock];
};

// A block of triangles' corners and their unit face normals.
struct NormalBlock {
  size_t lanes = 0;                    // a whole number of vectors
  alignas(64) double c[3][3][kBlock];  // [corner][axis][lane]
  alignas(64) double n[3][kBlock];     // [axis][lane]
};

// windowDepth's formula (common/depth_formula.cpp) for one frame's depth
// settings.
enum class DepthFormula { Orthographic, PerspectiveInfinite, PerspectiveFinite };

// What a frame's unclipped planes share: the view transform's rows x, y and z
// (glm's columns m[c][r]), clipOf's scale, imageOf's image size and
// windowDepth's formula.
struct UnclippedFrame {
  double m[4][3];
  double scaleX, scaleY, width, height;
  bool perspective;  // clip w = d, else 1
  DepthFormula formula;
  bool reversed;
  double znear, zfar, range;  // range = zfar − znear, as windowDepth forms it
};

// A block of unclipped triangles' world positions (in the setup's vertex
// order) and their planes.
struct UnclippedBlock {
  size_t lanes = 0;                    // a whole number of vectors
  alignas(64) double p[3][3][kBlock];  // [vertex][axis][lane]
  alignas(64) double swapped[kBlock];  // 1: vertex order (0, 2, 1), 0: (0, 1, 2)
  alignas(64) double scalar[kBlock];   // 1: left to the scalar steps
  alignas(64) double x0[kBlock], y0[kBlock], centroid[kBlock], maxZ[kBlock];
  alignas(64) double v0[3][kBlock];                 // z, 1/w, d/w at vertex 0 (b1/w, b2/w are +0 there)
  alignas(64) double dx[5][kBlock], dy[5][kBlock];  // z, 1/w, d/w, b1/w, b2/w
};

}  // namespace setup_planes_detail
}  // namespace rastray
#endif  // RASTRAY_SETUP_PLANES_BLOCK_

HWY_BEFORE_NAMESPACE();
namespace rastray {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// Per lane: planeMemoFor (corners sorted lexicographically by three
// compare-exchanges, a = the first, e1 and e2 the differences to the
// others, the slots of stored corners 1 and 2), then intersectTrianglePlane's
// origin terms for a ray from the eye: s = eye − a, q = glm::cross(s, e1)
// = (s.y·e1.z − e1.y·s.z, s.z·e1.x − e1.z·s.x, s.x·e1.y − e1.x·s.y),
// e2DotQ = glm::dot(e2, q) = (e2.x·q.x + e2.y·q.y) + e2.z·q.z.
void LanesRefinePlanes(setup_planes_detail::PlaneBlock* b, const double* eye) {
  const hn::ScalableTag<double> d;
  using V = hn::Vec<decltype(d)>;
  using M = hn::Mask<decltype(d)>;
  const size_t N = hn::Lanes(d);
  const V ex = hn::Set(d, eye[0]), ey = hn::Set(d, eye[1]), ez = hn::Set(d, eye[2]);
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0), two = hn::Set(d, 2.0);
  struct Corner {
    V x, y, z, index;
  };
  // The reference's `less`: x decides unless equal, then y, then z (a NaN
  // compares unequal and not less, as there).
  const auto less = [&](const Corner& p, const Corner& q) -> M {
    const M ltZ = hn::Lt(p.z, q.z);
    const M ltY = hn::Or(hn::Lt(p.y, q.y), hn::And(hn::Eq(p.y, q.y), ltZ));
    return hn::Or(hn::Lt(p.x, q.x), hn::And(hn::Eq(p.x, q.x), ltY));
  };
  // if (less(second, first)) swap(first, second)
  const auto exchange = [&](Corner* first, Corner* second) {
    const M m = less(*second, *first);
    const Corner f = *first, s = *second;
    first->x = hn::IfThenElse(m, s.x, f.x), second->x = hn::IfThenElse(m, f.x, s.x);
    first->y = hn::IfThenElse(m, s.y, f.y), second->y = hn::IfThenElse(m, f.y, s.y);
    first->z = hn::IfThenElse(m, s.z, f.z), second->z = hn::IfThenElse(m, f.z, s.z);
    first->index = hn::IfThenElse(m, s.index, f.index), second->index = hn::IfThenElse(m, f.index, s.index);
  };
  for (size_t i = 0; i < b->lanes; i += N) {
    Corner k[3];
    for (int c = 0; c < 3; ++c) {
      k[c].x = hn::Load(d, b->c[c][0] + i);
      k[c].y = hn::Load(d, b->c[c][1] + i);
      k[c].z = hn::Load(d, b->c[c][2] + i);
      k[c].index = hn::Set(d, double(c));
    }
    exchange(&k[0], &k[1]);
    exchange(&k[1], &k[2]);
    exchange(&k[0], &k[1]);
    // The slot (rank) holding stored corner 1, and 2.
    const auto slotOf = [&](const V& stored) {
      return hn::IfThenElse(hn::Eq(k[0].index, stored), zero,
                            hn::IfThenElse(hn::Eq(k[1].index, stored), one, two));
    };
    hn::Store(slotOf(one), d, b->slot1 + i);
    hn::Store(slotOf(two), d, b->slot2 + i);
    const V e1x = hn::Sub(k[1].x, k[0].x), e1y = hn::Sub(k[1].y, k[0].y), e1z = hn::Sub(k[1].z, k[0].z);
    const V e2x = hn::Sub(k[2].x, k[0].x), e2y = hn::Sub(k[2].y, k[0].y), e2z = hn::Sub(k[2].z, k[0].z);
    const V sx = hn::Sub(ex, k[0].x), sy = hn::Sub(ey, k[0].y), sz = hn::Sub(ez, k[0].z);
    const V qx = hn::Sub(hn::Mul(sy, e1z), hn::Mul(e1y, sz));
    const V qy = hn::Sub(hn::Mul(sz, e1x), hn::Mul(e1z, sx));
    const V qz = hn::Sub(hn::Mul(sx, e1y), hn::Mul(e1x, sy));
    hn::Store(hn::Add(hn::Add(hn::Mul(e2x, qx), hn::Mul(e2y, qy)), hn::Mul(e2z, qz)), d, b->e2DotQ + i);
    hn::Store(e1x, d, b->e1[0] + i), hn::Store(e1y, d, b->e1[1] + i), hn::Store(e1z, d, b->e1[2] + i);
    hn::Store(e2x, d, b->e2[0] + i), hn::Store(e2y, d, b->e2[1] + i), hn::Store(e2z, d, b->e2[2] + i);
    hn::Store(sx, d, b->s[0] + i), hn::Store(sy, d, b->s[1] + i), hn::Store(sz, d, b->s[2] + i);
    hn::Store(qx, d, b->q[0] + i), hn::Store(qy, d, b->q[1] + i), hn::Store(qz, d, b->q[2] + i);
  }
}

// Per lane: faceNormal's (common/surface.cpp) n = glm::cross(p1 − p0,
// p2 − p0), length = sqrt((n.x·n.x + n.y·n.y) + n.z·n.z) (glm::length),
// n / length when length > 0, else (0, 0, 1). Three divisions and a
// square root per triangle, correctly rounded in every lane.
void LanesFaceNormals(setup_planes_detail::NormalBlock* b) {
  const hn::ScalableTag<double> d;
  using V = hn::Vec<decltype(d)>;
  const size_t N = hn::Lanes(d);
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0);
  for (size_t i = 0; i < b->lanes; i += N) {
    V p[3][3];
    for (int c = 0; c < 3; ++c)
      for (int a = 0; a < 3; ++a) p[c][a] = hn::Load(d, b->c[c][a] + i);
    const V ux = hn::Sub(p[1][0], p[0][0]), uy = hn::Sub(p[1][1], p[0][1]), uz = hn::Sub(p[1][2], p[0][2]);
    const V vx = hn::Sub(p[2][0], p[0][0]), vy = hn::Sub(p[2][1], p[0][1]), vz = hn::Sub(p[2][2], p[0][2]);
    const V nx = hn::Sub(hn::Mul(uy, vz), hn::Mul(vy, uz));
    const V ny = hn::Sub(hn::Mul(uz, vx), hn::Mul(vz, ux));
    const V nz = hn::Sub(hn::Mul(ux, vy), hn::Mul(vx, uy));
    const V length = hn::Sqrt(hn::Add(hn::Add(hn::Mul(nx, nx), hn::Mul(ny, ny)), hn::Mul(nz, nz)));
    const auto positive = hn::Gt(length, zero);  // false for 0 and NaN, as the reference's test
    hn::Store(hn::IfThenElse(positive, hn::Div(nx, length), zero), d, b->n[0] + i);
    hn::Store(hn::IfThenElse(positive, hn::Div(ny, length), zero), d, b->n[1] + i);
    hn::Store(hn::IfThenElse(positive, hn::Div(nz, length), one), d, b->n[2] + i);
  }
}

// Per lane and vertex, setupChunkFast's scalar steps: clipOf (glm's dmat4 ×
// dvec4(p, 1) = (m0·x + m1·y) + (m2·z + m3), where m3·1 is m3 exactly; d =
// −view.z; x and y over the scale; w = d or 1), imageOf ((x/w + 1)·0.5·W,
// (1 − y/w)·0.5·H) and windowDepth (d); the centroid's view depth over the
// stored order; then setupPlanes: planePositions' area, 1/w and d/w per
// vertex, b/w as 1/w for a weight of 1 and +0 for 0 (w > 0), the ten
// coefficients and the largest z, std::max's first largest. Lanes whose
// area is not positive and finite, or with a w not positive, are marked
// for the scalar steps.
void LanesUnclippedPlanes(setup_planes_detail::UnclippedBlock* b,
                          const setup_planes_detail::UnclippedFrame* f) {
  using setup_planes_detail::DepthFormula;
  const hn::ScalableTag<double> d;
  using V = hn::Vec<decltype(d)>;
  const size_t N = hn::Lanes(d);
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0), half = hn::Set(d, 0.5), three = hn::Set(d, 3.0);
  const V scaleX = hn::Set(d, f->scaleX), scaleY = hn::Set(d, f->scaleY);
  const V width = hn::Set(d, f->width), height = hn::Set(d, f->height);
  const V znear = hn::Set(d, f->znear), zfar = hn::Set(d, f->zfar), range = hn::Set(d, f->range);
  V m[4][3];
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 3; ++r) m[c][r] = hn::Set(d, f->m[c][r]);
  // conventionalWindowDepth / reversedWindowDepth at view depth v.
  const auto windowDepth = [&](const V& v) -> V {
    switch (f->formula) {
      case DepthFormula::Orthographic:
        return f->reversed ? hn::Div(hn::Sub(zfar, v), range) : hn::Div(hn::Sub(v, znear), range);
      case DepthFormula::PerspectiveInfinite:
        return f->reversed ? hn::Div(znear, v) : hn::Sub(one, hn::Div(znear, v));
      case DepthFormula::PerspectiveFinite:
        return f->reversed ? hn::Div(hn::Mul(znear, hn::Sub(zfar, v)), hn::Mul(v, range))
                           : hn::Div(hn::Mul(zfar, hn::Sub(v, znear)), hn::Mul(v, range));
    }
    return v;
  };
  for (size_t i = 0; i < b->lanes; i += N) {
    V x[3], y[3], view[3], w[3], attr[5][3];  // attr: z, 1/w, d/w, b1/w, b2/w
    for (int s = 0; s < 3; ++s) {
      const V px = hn::Load(d, b->p[s][0] + i), py = hn::Load(d, b->p[s][1] + i),
              pz = hn::Load(d, b->p[s][2] + i);
      const auto row = [&](int r) {
        return hn::Add(hn::Add(hn::Mul(m[0][r], px), hn::Mul(m[1][r], py)),
                       hn::Add(hn::Mul(m[2][r], pz), m[3][r]));
      };
      view[s] = hn::Neg(row(2));
      w[s] = f->perspective ? view[s] : one;
      const V cx = hn::Div(row(0), scaleX), cy = hn::Div(row(1), scaleY);
      x[s] = hn::Mul(hn::Mul(hn::Add(hn::Div(cx, w[s]), one), half), width);
      y[s] = hn::Mul(hn::Mul(hn::Sub(one, hn::Div(cy, w[s])), half), height);
      attr[0][s] = windowDepth(view[s]);
      attr[1][s] = hn::Div(one, w[s]);
      attr[2][s] = hn::Div(view[s], w[s]);
    }
    const auto positiveW = hn::And(hn::And(hn::Gt(w[0], zero), hn::Gt(w[1], zero)), hn::Gt(w[2], zero));
    const auto swapped = hn::Ne(hn::Load(d, b->swapped + i), zero);
    // Stored corner 1 is vertex 2 when swapped, else vertex 1; corner 2 the other.
    attr[3][0] = attr[4][0] = zero;
    attr[3][1] = hn::IfThenZeroElse(swapped, attr[1][1]);
    attr[3][2] = hn::IfThenElseZero(swapped, attr[1][2]);
    attr[4][1] = hn::IfThenElseZero(swapped, attr[1][1]);
    attr[4][2] = hn::IfThenZeroElse(swapped, attr[1][2]);
    const V corner1 = hn::IfThenElse(swapped, view[2], view[1]);
    const V corner2 = hn::IfThenElse(swapped, view[1], view[2]);
    hn::Store(hn::Div(hn::Add(hn::Add(view[0], corner1), corner2), three), d, b->centroid + i);
    const V x10 = hn::Sub(x[1], x[0]), x20 = hn::Sub(x[2], x[0]);
    const V y10 = hn::Sub(y[1], y[0]), y20 = hn::Sub(y[2], y[0]);
    const V area = hn::Sub(hn::Mul(x10, y20), hn::Mul(y10, x20));
    const auto scalar = hn::Not(hn::And(positiveW, hn::And(hn::Gt(area, zero), hn::IsFinite(area))));
    hn::Store(hn::IfThenElseZero(scalar, one), d, b->scalar + i);
    for (int k = 0; k < 5; ++k) {
      const V a10 = hn::Sub(attr[k][1], attr[k][0]), a20 = hn::Sub(attr[k][2], attr[k][0]);
      hn::Store(hn::Div(hn::Sub(hn::Mul(a10, y20), hn::Mul(a20, y10)), area), d, b->dx[k] + i);
      hn::Store(hn::Div(hn::Sub(hn::Mul(a20, x10), hn::Mul(a10, x20)), area), d, b->dy[k] + i);
    }
    for (int k = 0; k < 3; ++k) hn::Store(attr[k][0], d, b->v0[k] + i);
    hn::Store(x[0], d, b->x0 + i), hn::Store(y[0], d, b->y0 + i);
    V maxZ = attr[0][0];
    maxZ = hn::IfThenElse(hn::Lt(maxZ, attr[0][1]), attr[0][1], maxZ);
    maxZ = hn::IfThenElse(hn::Lt(maxZ, attr[0][2]), attr[0][2], maxZ);
    hn::Store(maxZ, d, b->maxZ + i);
  }
}

size_t PlaneLanes() { return hn::Lanes(hn::ScalableTag<double>()); }

}  // namespace HWY_NAMESPACE
}  // namespace rastray
HWY_AFTER_NAMESPACE();

#if HWY_ONCE

#include <algorithm>
#include <cmath>

#include "common/triangle_plane.h"
#include "raster/depth.h"

namespace rastray {

HWY_EXPORT(LanesRefinePlanes);
HWY_EXPORT(LanesFaceNormals);
HWY_EXPORT(LanesUnclippedPlanes);
HWY_EXPORT(PlaneLanes);

RefinePlane refinePlaneReference(const Scene& scene, uint32_t instance, uint32_t triangle,
                                 const glm::dvec3& eye) {
  // glm: the same bits as intersectTrianglePlane's memo for a ray from eye.
  const TrianglePlane plane = trianglePlane(scene, instance, triangle);
  RefinePlane p;
  p.e1 = plane.e1;
  p.e2 = plane.e2;
  p.s = eye - plane.a;
  p.q = glm::cross(p.s, plane.e1);
  p.e2DotQ = glm::dot(plane.e2, p.q);
  p.slot1 = plane.slot1;
  p.slot2 = plane.slot2;
  return p;
}

namespace {

using CornerLanes = double[3][3][setup_planes_detail::kBlock];  // [corner][axis][lane]

// Lane k of a block's corners: the stored corners' positions, widened to double.
void gatherCorners(const Scene& scene, const glm::uvec3& corners, size_t k, CornerLanes& c) {
  for (int i = 0; i < 3; ++i) {
    const glm::vec3& p = scene.positions[corners[i]];
    c[i][0][k] = double(p.x), c[i][1][k] = double(p.y), c[i][2][k] = double(p.z);
  }
}

// Pads the n gathered lanes to whole vectors with the last triangle again
// (never read back); returns the lanes the kernel runs.
size_t padCorners(size_t n, size_t vectorLanes, CornerLanes& c) {
  const size_t lanes = (n + vectorLanes - 1) / vectorLanes * vectorLanes;
  for (size_t k = n; k < lanes; ++k)
    for (int i = 0; i < 3; ++i)
      for (int a = 0; a < 3; ++a) c[i][a][k] = c[i][a][n - 1];
  return lanes;
}

}  // namespace

namespace {

// The frame's constants of LanesUnclippedPlanes.
setup_planes_detail::UnclippedFrame unclippedFrame(const ClipSpace& space, const DepthSettings& depth) {
  using setup_planes_detail::DepthFormula;
  setup_planes_detail::UnclippedFrame f;
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 3; ++r) f.m[c][r] = space.viewFromWorld[c][r];
  f.scaleX = space.scale.x, f.scaleY = space.scale.y;
  f.width = double(space.width), f.height = double(space.height);
  f.perspective = space.projection == Projection::Perspective;
  f.formula = depth.projection == Projection::Orthographic ? DepthFormula::Orthographic
              : std::isinf(depth.zfar)                     ? DepthFormula::PerspectiveInfinite
                                                           : DepthFormula::PerspectiveFinite;
  f.reversed = isReversed(depth.format);
  f.znear = depth.znear, f.zfar = depth.zfar, f.range = depth.zfar - depth.znear;
  return f;
}

// Lane k of a block: the triangle's world positions in its setup's vertex order.
void gatherUnclipped(const Scene& scene, const UnclippedTriangle& u, size_t k,
                     setup_planes_detail::UnclippedBlock& b) {
  const uint32_t corner[3] = {u.corners.x, u.swapped ? u.corners.z : u.corners.y,
                              u.swapped ? u.corners.y : u.corners.z};
  for (int i = 0; i < 3; ++i) {
    const glm::vec3& p = scene.positions[corner[i]];
    b.p[i][0][k] = double(p.x), b.p[i][1][k] = double(p.y), b.p[i][2][k] = double(p.z);
  }
  b.swapped[k] = u.swapped ? 1.0 : 0.0;
}

// Pads the n gathered lanes to whole vectors with the last triangle again
// (never read back); returns the lanes the kernel runs.
size_t padUnclipped(size_t n, size_t vectorLanes, setup_planes_detail::UnclippedBlock& b) {
  const size_t lanes = (n + vectorLanes - 1) / vectorLanes * vectorLanes;
  for (size_t k = n; k < lanes; ++k) {
    for (int i = 0; i < 3; ++i)
      for (int a = 0; a < 3; ++a) b.p[i][a][k] = b.p[i][a][n - 1];
    b.swapped[k] = b.swapped[n - 1];
  }
  return lanes;
}

// Lane k's planes into t, and setupPlanes' polygon offset.
void scatterUnclipped(const setup_planes_detail::UnclippedBlock& b, size_t k, const DepthSettings& ds,
                      TriangleSetup* t) {
  t->centroidDepth = b.centroid[k];
  t->depth = {b.v0[0][k], b.dx[0][k], b.dy[0][k], b.x0[k], b.y0[k]};
  t->invW = {b.v0[1][k], b.dx[1][k], b.dy[1][k]};
  t->dOverW = {b.v0[2][k], b.dx[2][k], b.dy[2][k]};
  t->b1OverW = {0.0, b.dx[3][k], b.dy[3][k]};
  t->b2OverW = {0.0, b.dx[4][k], b.dy[4][k]};
  const double offset =
      polygonOffset(ds.format, ds.offsetFactor, ds.offsetUnits, t->maxDepthSlope(), b.maxZ[k]);
  t->depth.v0 += isReversed(ds.format) ? -offset : offset;
}

}  // namespace

size_t unclippedPlanes(const Scene& scene, const ClipSpace& space, const DepthSettings& depth,
                       const UnclippedTriangle* triangles, size_t n, TriangleSetup* setups,
                       uint32_t* scalar) {
  using setup_planes_detail::kBlock;
  if (n == 0) return 0;
  // Per thread: 14 KB, reused by every chunk the thread sets up.
  thread_local setup_planes_detail::UnclippedBlock block;
  setup_planes_detail::UnclippedBlock& b = block;
  const setup_planes_detail::UnclippedFrame frame = unclippedFrame(space, depth);
  const size_t vectorLanes = HWY_DYNAMIC_DISPATCH(PlaneLanes)();
  size_t scalarCount = 0;
  for (size_t first = 0; first < n; first += kBlock) {
    const size_t count = std::min(kBlock, n - first);
    for (size_t k = 0; k < count; ++k) gatherUnclipped(scene, triangles[first + k], k, b);
    b.lanes = padUnclipped(count, vectorLanes, b);
    HWY_DYNAMIC_DISPATCH(LanesUnclippedPlanes)(&b, &frame);
    for (size_t k = 0; k < count; ++k) {
      if (b.scalar[k] != 0.0)
        scalar[scalarCount++] = uint32_t(first + k);
      else
        scatterUnclipped(b, k, depth, &setups[triangles[first + k].setup]);
    }
  }
  return scalarCount;
}

void refinePlanes(const Scene& scene, const TriangleSetup* setups, size_t count, const glm::dvec3& eye,
                  RefinePlane* out) {
  using setup_planes_detail::kBlock;
  if (count == 0) return;
  // Per thread: 12 KB, reused by every chunk the thread sets up.
  thread_local setup_planes_detail::PlaneBlock block;
  setup_planes_detail::PlaneBlock& b = block;
  const double eyeLanes[3] = {eye.x, eye.y, eye.z};
  const size_t vectorLanes = HWY_DYNAMIC_DISPATCH(PlaneLanes)();
  for (size_t first = 0; first < count; first += kBlock) {
    const size_t n = std::min(kBlock, count - first);
    for (size_t k = 0; k < n; ++k) {
      const TriangleSetup& t = setups[first + k];
      gatherCorners(scene, scene.triangle(t.instance, t.triangle), k, b.c);
    }
    b.lanes = padCorners(n, vectorLanes, b.c);
    HWY_DYNAMIC_DISPATCH(LanesRefinePlanes)(&b, eyeLanes);
    for (size_t k = 0; k < n; ++k) {
      RefinePlane& p = out[first + k];
      p.e1 = {b.e1[0][k], b.e1[1][k], b.e1[2][k]};
      p.e2 = {b.e2[0][k], b.e2[1][k], b.e2[2][k]};
      p.s = {b.s[0][k], b.s[1][k], b.s[2][k]};
      p.q = {b.q[0][k], b.q[1][k], b.q[2][k]};
      p.e2DotQ = b.e2DotQ[k];
      p.slot1 = int32_t(b.slot1[k]);
      p.slot2 = int32_t(b.slot2[k]);
    }
  }
}

void faceNormals(const Scene& scene, TriangleSetup* setups, size_t count) {
  using setup_planes_detail::kBlock;
  if (count == 0) return;
  // Per thread: 6 KB, reused by every chunk the thread sets up.
  thread_local setup_planes_detail::NormalBlock block;
  setup_planes_detail::NormalBlock& b = block;
  const size_t vectorLanes = HWY_DYNAMIC_DISPATCH(PlaneLanes)();
  for (size_t first = 0; first < count; first += kBlock) {
    const size_t n = std::min(kBlock, count - first);
    for (size_t k = 0; k < n; ++k) gatherCorners(scene, setups[first + k].corners, k, b.c);
    b.lanes = padCorners(n, vectorLanes, b.c);
    HWY_DYNAMIC_DISPATCH(LanesFaceNormals)(&b);
    for (size_t k = 0; k < n; ++k) setups[first + k].faceNormal = {b.n[0][k], b.n[1][k], b.n[2][k]};
  }
}

}  // namespace rastray

#endif  // HWY_ONCE
