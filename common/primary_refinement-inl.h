// The refinement of a primary hit on its stored triangle's plane
// (intersectTrianglePlane, then refinedBarycentrics: common/surface.h) as
// Highway lane code, shared by the batched refinement
// (common/shading_kernel.cpp: refinePrimaryHits) and the rasterizer's fused
// per-block pass (raster/primary_samples.cpp), so both give the same bits.
// Operation for operation as the scalar code: glm's cross
// (x.y·y.z − y.y·x.z, ...) and dot ((x + y) + z), the canonical slots mapped
// back, the plane kept only ahead of the ray, the clamp max(b, 0) as glm's
// (b < 0 ? 0 : b), then the scale onto the edge v1–v2. Include after
// <hwy/highway.h> in a file compiled per target (foreach_target.h) with
// -ffp-contract=off; the guard below re-opens once per target.
#if defined(RASTRAY_PRIMARY_REFINEMENT_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef RASTRAY_PRIMARY_REFINEMENT_INL_H_
#undef RASTRAY_PRIMARY_REFINEMENT_INL_H_
#else
#define RASTRAY_PRIMARY_REFINEMENT_INL_H_
#endif

#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace rastray {
namespace HWY_NAMESPACE {

// A stored triangle's plane as the refinement reads it, with the terms
// that depend only on the ray's origin (the eye) precomputed as
// intersectTrianglePlane's memo computes them: s = origin − a,
// q = s × e1, e2DotQ = e2 · q.
template <class V>
struct RefinePlaneLanes {
  V e1x, e1y, e1z, e2x, e2y, e2z;
  V sx, sy, sz, qx, qy, qz, e2DotQ;
  V slot1, slot2;  // canonical rank of stored corners 1 and 2 (0, 1, 2)
};

// Refined barycentrics of the hit along direction (dx, dy, dz) with
// depthPerT: returns where they replace the interpolated ones (the plane
// met ahead of the ray at a finite depth); *b1, *b2 are set in every lane
// (meaningless where the mask is false).
template <class D, class V = hwy::HWY_NAMESPACE::Vec<D>>
HWY_INLINE hwy::HWY_NAMESPACE::Mask<D> RefineOnPlane(D d, V dx, V dy, V dz, V depthPerT,
                                                     const RefinePlaneLanes<V>& pl, V* b1Out, V* b2Out) {
  namespace hn = hwy::HWY_NAMESPACE;
  const auto zero = hn::Zero(d), one = hn::Set(d, 1.0);
  // p = direction × e2
  const auto px = hn::Sub(hn::Mul(dy, pl.e2z), hn::Mul(pl.e2y, dz));
  const auto py = hn::Sub(hn::Mul(dz, pl.e2x), hn::Mul(pl.e2z, dx));
  const auto pz = hn::Sub(hn::Mul(dx, pl.e2y), hn::Mul(pl.e2x, dy));
  const auto det = hn::Add(hn::Add(hn::Mul(pl.e1x, px), hn::Mul(pl.e1y, py)), hn::Mul(pl.e1z, pz));
  auto ok = hn::Gt(hn::Abs(det), zero);
  const auto inv = hn::Div(one, det);
  const auto u = hn::Mul(hn::Add(hn::Add(hn::Mul(pl.sx, px), hn::Mul(pl.sy, py)), hn::Mul(pl.sz, pz)), inv);
  const auto w = hn::Mul(hn::Add(hn::Add(hn::Mul(dx, pl.qx), hn::Mul(dy, pl.qy)), hn::Mul(dz, pl.qz)), inv);
  const auto t = hn::Mul(pl.e2DotQ, inv);
  ok = hn::And(ok, hn::And(hn::IsFinite(t), hn::And(hn::IsFinite(u), hn::IsFinite(w))));
  const auto w0 = hn::Sub(hn::Sub(one, u), w);
  auto b1 = hn::IfThenElse(hn::Eq(pl.slot1, zero), w0, hn::IfThenElse(hn::Eq(pl.slot1, one), u, w));
  auto b2 = hn::IfThenElse(hn::Eq(pl.slot2, zero), w0, hn::IfThenElse(hn::Eq(pl.slot2, one), u, w));
  ok = hn::And(ok, hn::And(hn::Gt(t, zero), hn::IsFinite(hn::Mul(t, depthPerT))));
  b1 = hn::IfThenElse(hn::Lt(b1, zero), zero, b1);
  b2 = hn::IfThenElse(hn::Lt(b2, zero), zero, b2);
  const auto sum = hn::Add(b1, b2);
  const auto over = hn::Gt(sum, one);
  if (hn::AllFalse(d, over)) {
    // No lane beyond the edge (the usual case): the two divisions would be
    // discarded in every lane.
    *b1Out = b1;
    *b2Out = b2;
  } else {
    *b1Out = hn::IfThenElse(over, hn::Div(b1, sum), b1);
    *b2Out = hn::IfThenElse(over, hn::Div(b2, sum), b2);
  }
  return ok;
}

}  // namespace HWY_NAMESPACE
}  // namespace rastray
HWY_AFTER_NAMESPACE();

#endif  // RASTRAY_PRIMARY_REFINEMENT_INL_H_
