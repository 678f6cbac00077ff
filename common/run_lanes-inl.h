// Per-run tables read by a vector of lanes, shared by the SIMD passes that
// store what is constant along a run of lanes on one triangle once per run
// (common/shading_kernel.cpp, raster/primary_samples.cpp): lane i holds
// only the index of its run, runs are non-decreasing within a block, and a
// vector of lanes reads a table entry by a broadcast when all its lanes lie
// on one run (first == last says so), else by a gather. The same value
// either way, so a lane's result does not depend on its neighbours. Include
// after <hwy/highway.h> in a file compiled per target (foreach_target.h);
// the guard below re-opens once per target. `run` is read with an aligned
// load: alignas(64) storage, i a multiple of the lane count.
#if defined(RASTRAY_RUN_LANES_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef RASTRAY_RUN_LANES_INL_H_
#undef RASTRAY_RUN_LANES_INL_H_
#else
#define RASTRAY_RUN_LANES_INL_H_
#endif

#include <cstddef>

#include <hwy/highway.h>

// A lambda in a lane function that must be inlined (GCC may leave one
// out of line once it reads tables through RunLanes, costing a call and
// its vectors' spills per use): `[&](...) RASTRAY_LAMBDA_INLINE { ... }`.
#ifndef RASTRAY_LAMBDA_INLINE
#define RASTRAY_LAMBDA_INLINE __attribute__((always_inline))
#endif

HWY_BEFORE_NAMESPACE();
namespace rastray {
namespace HWY_NAMESPACE {

// The runs of the vector of lanes starting at lane i of `run` (a signed
// integer per lane, as wide as D's lanes: int32_t for float, int64_t for
// double), and table reads for them.
template <class D>
class RunLanes {
 public:
  using DI = hwy::HWY_NAMESPACE::RebindToSigned<D>;
  using Index = hwy::HWY_NAMESPACE::TFromD<DI>;
  using T = hwy::HWY_NAMESPACE::TFromD<D>;

  RunLanes(D d, const Index* run, size_t i)
      : d_(d),
        run_(run + i),
        first_(run[i]),
        last_(run[i + hwy::HWY_NAMESPACE::Lanes(d) - 1]),
        oneRun_(first_ == last_),
        twoRuns_(last_ == first_ + 1) {
    namespace hn = hwy::HWY_NAMESPACE;
    if (twoRuns_) onFirst_ = hn::RebindMask(d_, hn::Eq(hn::Load(DI(), run_), hn::Set(DI(), first_)));
  }

  // Whether every lane lies on one run (table reads are broadcasts).
  bool oneRun() const { return oneRun_; }

  // table[run of each lane]: a broadcast on one run, two blended on two
  // (a vector across one run's end: runs are non-decreasing, so its lanes
  // lie on run first or first + 1), else a gather.
  HWY_INLINE hwy::HWY_NAMESPACE::Vec<D> operator()(const T* table) const {
    namespace hn = hwy::HWY_NAMESPACE;
    if (oneRun_) return hn::Set(d_, table[first_]);
    if (twoRuns_) return hn::IfThenElse(onFirst_, hn::Set(d_, table[first_]), hn::Set(d_, table[last_]));
    return hn::GatherIndex(d_, table, hn::Load(DI(), run_));
  }

 private:
  D d_;
  const Index* run_;
  Index first_, last_;
  bool oneRun_, twoRuns_;
  hwy::HWY_NAMESPACE::Mask<D> onFirst_{};
};

}  // namespace HWY_NAMESPACE
}  // namespace rastray
HWY_AFTER_NAMESPACE();

#endif  // RASTRAY_RUN_LANES_INL_H_
