// ray_offset.h's Embree margin (step 2) for a batch of ray origins in
// double SIMD lanes. Highway's dynamic dispatch compiles the kernel once
// per target (foreach_target.h re-includes this file) and picks one at run
// time. Each lane does what the scalar margin() in ray_offset.cpp does, in
// its order of operations (no fused multiply-adds: -ffp-contract=off, and
// no MulAdd here), so the bits are the same on every target.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "raytrace/ray_offset_lanes.cpp"
#include <hwy/foreach_target.h>  // before highway.h
#include <hwy/highway.h>

#include "raytrace/ray_offset_lanes.h"

HWY_BEFORE_NAMESPACE();
namespace rastray {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using D = hn::ScalableTag<double>;
using V = hn::Vec<D>;

struct V3 {
  V x, y, z;
};

HWY_INLINE V3 sub(const V3& a, const V3& b) {
  return {hn::Sub(a.x, b.x), hn::Sub(a.y, b.y), hn::Sub(a.z, b.z)};
}
HWY_INLINE V3 add(const V3& a, const V3& b) {
  return {hn::Add(a.x, b.x), hn::Add(a.y, b.y), hn::Add(a.z, b.z)};
}
HWY_INLINE V3 mul(V s, const V3& a) { return {hn::Mul(s, a.x), hn::Mul(s, a.y), hn::Mul(s, a.z)}; }
HWY_INLINE V3 abs(const V3& a) { return {hn::Abs(a.x), hn::Abs(a.y), hn::Abs(a.z)}; }
// glm::cross(a, b): (a.y·b.z − b.y·a.z, a.z·b.x − b.z·a.x, a.x·b.y − b.x·a.y).
HWY_INLINE V3 cross(const V3& a, const V3& b) {
  return {hn::Sub(hn::Mul(a.y, b.z), hn::Mul(b.y, a.z)), hn::Sub(hn::Mul(a.z, b.x), hn::Mul(b.z, a.x)),
          hn::Sub(hn::Mul(a.x, b.y), hn::Mul(b.x, a.y))};
}
// glm::dot: (a.x·b.x + a.y·b.y) + a.z·b.z.
HWY_INLINE V dot(const V3& a, const V3& b) {
  return hn::Add(hn::Add(hn::Mul(a.x, b.x), hn::Mul(a.y, b.y)), hn::Mul(a.z, b.z));
}
// glm::max: a < b ? b : a.
HWY_INLINE V max(V a, V b) { return hn::IfThenElse(hn::Lt(a, b), b, a); }
HWY_INLINE V3 max(const V3& a, const V3& b) { return {max(a.x, b.x), max(a.y, b.y), max(a.z, b.z)}; }

void EmbreeMarginLanes(const double (*soa)[detail::kOriginLanes], double* det, double* bound) {
  const D d;
  const V u = hn::Set(d, detail::kU);
  for (size_t k = 0; k < detail::kOriginLanes; k += hn::Lanes(d)) {
    auto load = [&](int row) { return hn::Load(d, soa[row] + k); };
    const V3 o = {load(9), load(10), load(11)};
    const V3 w0 = sub({load(0), load(1), load(2)}, o);
    const V3 w1 = sub({load(3), load(4), load(5)}, o);
    const V3 w2 = sub({load(6), load(7), load(8)}, o);
    const V3 cof0 = cross(w1, w2), cof1 = cross(w2, w0), cof2 = cross(w0, w1);
    const V3 a0 = abs(w0), a1 = abs(w1), a2 = abs(w2);
    const V first = hn::Add(hn::Add(dot(a0, abs(cof0)), dot(a1, abs(cof1))), dot(a2, abs(cof2)));
    const V permanent = hn::Add(hn::Add(hn::Mul(a0.x, hn::Add(hn::Mul(a1.y, a2.z), hn::Mul(a1.z, a2.y))),
                                        hn::Mul(a0.y, hn::Add(hn::Mul(a1.x, a2.z), hn::Mul(a1.z, a2.x)))),
                                hn::Mul(a0.z, hn::Add(hn::Mul(a1.x, a2.y), hn::Mul(a1.y, a2.x))));
    // edgeBounds(w).
    const V3 e0 = add(abs(sub(w2, w0)), mul(u, add(a2, a0)));
    const V3 e1 = add(abs(sub(w0, w1)), mul(u, add(a0, a1)));
    const V3 e2 = add(abs(sub(w1, w2)), mul(u, add(a1, a2)));
    const V3 c01 = {hn::Add(hn::Mul(e0.y, e1.z), hn::Mul(e0.z, e1.y)),
                    hn::Add(hn::Mul(e0.z, e1.x), hn::Mul(e0.x, e1.z)),
                    hn::Add(hn::Mul(e0.x, e1.y), hn::Mul(e0.y, e1.x))};
    const V3 c12 = {hn::Add(hn::Mul(e1.y, e2.z), hn::Mul(e1.z, e2.y)),
                    hn::Add(hn::Mul(e1.z, e2.x), hn::Mul(e1.x, e2.z)),
                    hn::Add(hn::Mul(e1.x, e2.y), hn::Mul(e1.y, e2.x))};
    const V3 crossBound = max(c01, c12);
    const V3 reach = max(max(a0, a1), a2);
    const V normalTerm = dot(a0, crossBound);
    // kU·first + 4kU²·permanent + 8kU·normalTerm + slack·(first + permanent +
    // normalTerm) + underflow·(1 + ΣR + ΣC), summed left to right.
    V b = hn::Add(hn::Mul(u, first), hn::Mul(hn::Set(d, 4.0 * detail::kU * detail::kU), permanent));
    b = hn::Add(b, hn::Mul(hn::Set(d, 8.0 * detail::kU), normalTerm));
    b = hn::Add(b, hn::Mul(hn::Set(d, detail::kEvalSlack), hn::Add(hn::Add(first, permanent), normalTerm)));
    V r = hn::Add(hn::Set(d, 1.0), reach.x);
    r = hn::Add(hn::Add(r, reach.y), reach.z);
    r = hn::Add(hn::Add(hn::Add(r, crossBound.x), crossBound.y), crossBound.z);
    b = hn::Add(b, hn::Mul(hn::Set(d, detail::kUnderflow), r));
    hn::Store(dot(w0, cof0), d, det + k);
    hn::Store(b, d, bound + k);
  }
}

}  // namespace HWY_NAMESPACE
}  // namespace rastray
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace rastray::detail {

HWY_EXPORT(EmbreeMarginLanes);

void embreeMarginLanes(const double (*soa)[kOriginLanes], double* det, double* bound) {
  HWY_DYNAMIC_DISPATCH(EmbreeMarginLanes)(soa, det, bound);
}

}  // namespace rastray::detail
#endif  // HWY_ONCE
