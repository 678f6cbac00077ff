// The vertex codes of setup_vertex_codes.h in Highway double lanes. Highway
// compiles the lane function once per SIMD target (foreach_target.h
// re-includes this file); the host code gathers a block of positions,
// runs the lanes and scatters the codes. Built with -ffp-contract=off (the
// top-level CMakeLists.txt): every operation below is the scalar
// reference's (ClipSpace::clipOf with glm's matrix-vector product,
// outsidePlanes, ClipSpace::imageOf, snapUnits), in its order, and IEEE
// addition, multiplication and division are correctly rounded in every
// lane, so the bits are the same on every target.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "raster/setup_vertex_codes.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <cstddef>
#include <cstdint>

#include <hwy/highway.h>

#include "raster/setup.h"
#include "raster/setup_vertex_codes.h"

#ifndef RASTRAY_SETUP_CLASSIFY_BLOCK_
#define RASTRAY_SETUP_CLASSIFY_BLOCK_
namespace rastray {
namespace setup_vertex_codes_detail {

constexpr size_t kBlock = 64;  // a multiple of every target's double lane count

// The frame's constants of the vertex codes.
struct VertexTransform {
  double view[4][3];  // viewFromWorld's four columns' x, y, z rows
  double scale[2];
  double znear, zfar;
  bool finiteFar, perspective;
  double guard[2];
  double width, height, unitsPerPixel;
};

// A block of vertices' world positions and their codes.
struct VertexBlock {
  size_t lanes = 0;                       // a whole number of vectors
  alignas(64) double p[3][kBlock];        // [axis][lane]
  alignas(64) double outside[kBlock];     // outsidePlanes' bits, as a double
  alignas(64) double snapped[2][kBlock];  // [axis][lane]; 0 where outside
};

}  // namespace setup_vertex_codes_detail
}  // namespace rastray
#endif  // RASTRAY_SETUP_CLASSIFY_BLOCK_

HWY_BEFORE_NAMESPACE();
namespace rastray {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// Per lane: view = (m0·x + m1·y) + (m2·z + m3) (glm's mat4 × vec4 with
// w = 1, whose m3·1 is m3), d = −view.z, clip (x, y) = view (x, y) / scale,
// w = d or 1; outsidePlanes' six tests (NaN outside); the image position
// ((x/w + 1)·0.5·width, (1 − y/w)·0.5·height), times the units per pixel,
// rounded half away from zero (trunc, then ±1 when the exact remainder's
// magnitude is >= 0.5) and clamped to ±kMaxCoordinateUnits.
void LanesVertexCodes(const setup_vertex_codes_detail::VertexTransform* f,
                      setup_vertex_codes_detail::VertexBlock* b) {
  const hn::ScalableTag<double> d;
  using V = hn::Vec<decltype(d)>;
  const size_t N = hn::Lanes(d);
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0), half = hn::Set(d, 0.5);
  const V limit = hn::Set(d, double(kMaxCoordinateUnits));
  const V units = hn::Set(d, f->unitsPerPixel);
  const auto snap = [&](const V& image) {
    const V s = hn::Mul(image, units);
    const V t = hn::Trunc(s);
    const V away = hn::IfThenElseZero(hn::Ge(hn::Abs(hn::Sub(s, t)), half), hn::CopySign(one, s));
    return hn::Min(hn::Max(hn::Add(t, away), hn::Neg(limit)), limit);
  };
  for (size_t i = 0; i < b->lanes; i += N) {
    const V x = hn::Load(d, b->p[0] + i), y = hn::Load(d, b->p[1] + i), z = hn::Load(d, b->p[2] + i);
    V view[3];
    for (int r = 0; r < 3; ++r)
      view[r] = hn::Add(hn::Add(hn::Mul(hn::Set(d, f->view[0][r]), x), hn::Mul(hn::Set(d, f->view[1][r]), y)),
                        hn::Add(hn::Mul(hn::Set(d, f->view[2][r]), z), hn::Set(d, f->view[3][r])));
    const V depth = hn::Neg(view[2]);
    const V cx = hn::Div(view[0], hn::Set(d, f->scale[0])), cy = hn::Div(view[1], hn::Set(d, f->scale[1]));
    const V w = f->perspective ? depth : one;
    V outside = zero;
    double bit = 1.0;
    const auto test = [&](const V& value) {  // the next plane's bit where !(value >= 0)
      outside = hn::Add(outside, hn::IfThenElseZero(hn::Not(hn::Ge(value, zero)), hn::Set(d, bit)));
      bit *= 2.0;
    };
    test(hn::Sub(depth, hn::Set(d, f->znear)));
    test(f->finiteFar ? hn::Sub(hn::Set(d, f->zfar), depth) : one);
    const V gx = hn::Mul(hn::Set(d, f->guard[0]), w), gy = hn::Mul(hn::Set(d, f->guard[1]), w);
    test(hn::Sub(gx, cx));
    test(hn::Add(gx, cx));
    test(hn::Sub(gy, cy));
    test(hn::Add(gy, cy));
    const V imageX = hn::Mul(hn::Mul(hn::Add(hn::Div(cx, w), one), half), hn::Set(d, f->width));
    const V imageY = hn::Mul(hn::Mul(hn::Sub(one, hn::Div(cy, w)), half), hn::Set(d, f->height));
    const auto inside = hn::Eq(outside, zero);
    hn::Store(outside, d, b->outside + i);
    hn::Store(hn::IfThenElseZero(inside, snap(imageX)), d, b->snapped[0] + i);
    hn::Store(hn::IfThenElseZero(inside, snap(imageY)), d, b->snapped[1] + i);
  }
}

size_t VertexLanes() { return hn::Lanes(hn::ScalableTag<double>()); }

}  // namespace HWY_NAMESPACE
}  // namespace rastray
HWY_AFTER_NAMESPACE();

#if HWY_ONCE

#include <algorithm>
#include <cmath>

namespace rastray {

HWY_EXPORT(LanesVertexCodes);
HWY_EXPORT(VertexLanes);

namespace {

setup_vertex_codes_detail::VertexTransform transformOf(const ClipSpace& space, double unitsPerPixel) {
  setup_vertex_codes_detail::VertexTransform f;
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 3; ++r) f.view[c][r] = space.viewFromWorld[c][r];
  f.scale[0] = space.scale.x, f.scale[1] = space.scale.y;
  f.znear = space.znear, f.zfar = space.zfar;
  f.finiteFar = !std::isinf(space.zfar);
  f.perspective = space.projection == Projection::Perspective;
  f.guard[0] = space.guard.x, f.guard[1] = space.guard.y;
  f.width = double(space.width), f.height = double(space.height);
  f.unitsPerPixel = unitsPerPixel;
  return f;
}

}  // namespace

void vertexCodes(const ClipSpace& space, double unitsPerPixel, const glm::vec3* positions, size_t count,
                 uint8_t* outside, SnappedVertex* snapped) {
  using setup_vertex_codes_detail::kBlock;
  if (count == 0) return;
  // Per thread: 3 KB, reused by every block the thread classifies.
  thread_local setup_vertex_codes_detail::VertexBlock block;
  setup_vertex_codes_detail::VertexBlock& b = block;
  const setup_vertex_codes_detail::VertexTransform f = transformOf(space, unitsPerPixel);
  const size_t vectorLanes = HWY_DYNAMIC_DISPATCH(VertexLanes)();
  for (size_t first = 0; first < count; first += kBlock) {
    const size_t n = std::min(kBlock, count - first);
    for (size_t k = 0; k < n; ++k)
      for (int a = 0; a < 3; ++a) b.p[a][k] = double(positions[first + k][a]);
    // Padded to whole vectors with the last vertex again (never read back).
    b.lanes = (n + vectorLanes - 1) / vectorLanes * vectorLanes;
    for (size_t k = n; k < b.lanes; ++k)
      for (int a = 0; a < 3; ++a) b.p[a][k] = b.p[a][n - 1];
    HWY_DYNAMIC_DISPATCH(LanesVertexCodes)(&f, &b);
    for (size_t k = 0; k < n; ++k) {
      outside[first + k] = uint8_t(b.outside[k]);
      snapped[first + k] = {int32_t(b.snapped[0][k]), int32_t(b.snapped[1][k])};
    }
  }
}

}  // namespace rastray

#endif  // HWY_ONCE
