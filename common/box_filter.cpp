#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "common/box_filter.cpp"
#include <hwy/foreach_target.h>  // before highway.h
#include <hwy/highway.h>

#include "common/box_filter.h"

HWY_BEFORE_NAMESPACE();
namespace rastray {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

void BoxFilterLanes(const float* samples, int spp, size_t pixels, float* out) {
  if (spp == 1) {
    // One sample: every float is its own lane, (0 + c) / 1 as the loop.
    const hn::ScalableTag<float> d;
    const size_t n = 4 * pixels, lanes = hn::Lanes(d);
    const auto zero = hn::Zero(d), one = hn::Set(d, 1.0f);
    size_t i = 0;
    for (; i + lanes <= n; i += lanes)
      hn::StoreU(hn::Div(hn::Add(zero, hn::LoadU(d, samples + i)), one), d, out + i);
    for (; i < n; ++i) out[i] = (0.0f + samples[i]) / 1.0f;
    return;
  }
  // Several: one RGBA pixel per 4-lane vector (in pieces where the target
  // has fewer lanes), its samples added in order.
  const hn::CappedTag<float, 4> d4;
  const size_t lanes = hn::Lanes(d4);
  const auto count = hn::Set(d4, float(spp));
  for (size_t p = 0; p < pixels; ++p) {
    const float* s = samples + 4 * size_t(spp) * p;
    for (size_t c = 0; c < 4; c += lanes) {
      auto sum = hn::Zero(d4);
      for (int k = 0; k < spp; ++k) sum = hn::Add(sum, hn::LoadU(d4, s + 4 * size_t(k) + c));
      hn::StoreU(hn::Div(sum, count), d4, out + 4 * p + c);
    }
  }
}

#if HWY_MAX_BYTES == 64 && !HWY_HAVE_SCALABLE
// BoxFilterCoveredLanes at 4 spp on 16 lanes: four pixels a vector, no
// branches; returns the pixels done (a multiple of 4). v_p holds pixel
// p's four samples, one per 128-bit block; the blocks are transposed so
// that w_k holds sample k of the four pixels (lane 4p + channel), each
// term is selected by its pixel's winners as the loop below selects it,
// and the terms are summed from 0 in sample order. The division by 4 is a
// product by 0.25: the same real number rounded once, so the same bits
// (subnormal results and NaN included).
size_t BoxFilterCovered4Lanes16(const float* samples, const uint32_t* covered, uint32_t uncovered,
                                size_t pixels, float* out, bool shareUniform) {
  const hn::Full512<float> df;
  const hn::Full512<uint32_t> du;
  const auto zero = hn::Zero(df), quarter = hn::Set(df, 0.25f);
  const auto none = hn::Set(du, uncovered);
  // Blocks 0, 2, 1, 3.
  alignas(64) static constexpr uint32_t kSwapMiddleBlocks[16] = {0, 1, 2, 3, 8,  9,  10, 11,
                                                                 4, 5, 6, 7, 12, 13, 14, 15};
  const auto swap = hn::IndicesFromVec(df, hn::Load(du, kSwapMiddleBlocks));
  // Lane 4p + c reads the winner of sample k of pixel p: lane 4p + k.
  const auto pixelBase = hn::And(hn::Iota(du, 0), hn::Set(du, ~3u));
  const auto sample0 = hn::IndicesFromVec(du, pixelBase);
  const auto sample1 = hn::IndicesFromVec(du, hn::Add(pixelBase, hn::Set(du, 1u)));
  const auto sample2 = hn::IndicesFromVec(du, hn::Add(pixelBase, hn::Set(du, 2u)));
  const auto sample3 = hn::IndicesFromVec(du, hn::Add(pixelBase, hn::Set(du, 3u)));
  size_t p = 0;
  for (; p + 4 <= pixels; p += 4) {
    const float* s = samples + 16 * p;
    const auto v0 = hn::LoadU(df, s), v1 = hn::LoadU(df, s + 16), v2 = hn::LoadU(df, s + 32),
               v3 = hn::LoadU(df, s + 48);
    // a0 = p0s0 p0s1 p1s0 p1s1, a1 = p0s2 p0s3 p1s2 p1s3, a2/a3 the same of p2, p3.
    const auto a0 = hn::ConcatLowerLower(df, v1, v0), a1 = hn::ConcatUpperUpper(df, v1, v0);
    const auto a2 = hn::ConcatLowerLower(df, v3, v2), a3 = hn::ConcatUpperUpper(df, v3, v2);
    // b0 = p0s0 p1s0 p0s1 p1s1, b1 = p0s2 p1s2 p0s3 p1s3, b2/b3 the same of p2, p3.
    const auto b0 = hn::TableLookupLanes(a0, swap), b1 = hn::TableLookupLanes(a1, swap);
    const auto b2 = hn::TableLookupLanes(a2, swap), b3 = hn::TableLookupLanes(a3, swap);
    const auto w0 = hn::ConcatLowerLower(df, b2, b0), w1 = hn::ConcatUpperUpper(df, b2, b0);
    const auto w2 = hn::ConcatLowerLower(df, b3, b1), w3 = hn::ConcatUpperUpper(df, b3, b1);
    const auto winners = hn::LoadU(du, covered + 4 * p);
    const auto c0 = hn::TableLookupLanes(winners, sample0), c1 = hn::TableLookupLanes(winners, sample1);
    const auto c2 = hn::TableLookupLanes(winners, sample2), c3 = hn::TableLookupLanes(winners, sample3);
    auto t0 = hn::IfThenElseZero(hn::RebindMask(df, hn::Ne(c0, none)), w0);
    auto t1 = hn::IfThenElseZero(hn::RebindMask(df, hn::Ne(c1, none)), w1);
    auto t2 = hn::IfThenElseZero(hn::RebindMask(df, hn::Ne(c2, none)), w2);
    auto t3 = hn::IfThenElseZero(hn::RebindMask(df, hn::Ne(c3, none)), w3);
    if (shareUniform) {
      // A pixel whose samples share one covered winner: its first
      // sample's colour for every sample.
      const auto uniform = hn::RebindMask(
          df, hn::And(hn::And(hn::Ne(c0, none), hn::Eq(c1, c0)), hn::And(hn::Eq(c2, c0), hn::Eq(c3, c0))));
      t1 = hn::IfThenElse(uniform, w0, t1);
      t2 = hn::IfThenElse(uniform, w0, t2);
      t3 = hn::IfThenElse(uniform, w0, t3);
    }
    const auto sum = hn::Add(hn::Add(hn::Add(hn::Add(zero, t0), t1), t2), t3);
    hn::StoreU(hn::Mul(sum, quarter), df, out + 4 * p);
  }
  return p;
}
#endif

void BoxFilterCoveredLanes(const float* samples, const uint32_t* covered, uint32_t uncovered, int spp,
                           size_t pixels, float* out, bool shareUniform) {
  size_t first = 0;
#if HWY_MAX_BYTES == 64 && !HWY_HAVE_SCALABLE
  if (spp == 4) first = BoxFilterCovered4Lanes16(samples, covered, uncovered, pixels, out, shareUniform);
#endif
  // One RGBA pixel per 4-lane vector (in pieces where the target has fewer
  // lanes); an uncovered sample adds +0, as its stored 0 would.
  const hn::CappedTag<float, 4> d4;
  const size_t lanes = hn::Lanes(d4);
  const auto count = hn::Set(d4, float(spp)), zero = hn::Zero(d4);
  for (size_t p = first; p < pixels; ++p) {
    const float* s = samples + 4 * size_t(spp) * p;
    const uint32_t* c = covered + size_t(spp) * p;
    if (shareUniform && c[0] != uncovered) {
      int same = 1;
      while (same < spp && c[same] == c[0]) ++same;
      if (same == spp) {
        for (size_t k = 0; k < 4; k += lanes) {
          const auto v = hn::LoadU(d4, s + k);
          auto sum = zero;
          for (int j = 0; j < spp; ++j) sum = hn::Add(sum, v);
          hn::StoreU(hn::Div(sum, count), d4, out + 4 * p + k);
        }
        continue;
      }
    }
    for (size_t k = 0; k < 4; k += lanes) {
      auto sum = zero;
      for (int j = 0; j < spp; ++j)
        sum = hn::Add(sum, c[j] == uncovered ? zero : hn::LoadU(d4, s + 4 * size_t(j) + k));
      hn::StoreU(hn::Div(sum, count), d4, out + 4 * p + k);
    }
  }
}

// NOLINTNEXTLINE(google-readability-namespace-comments)
}  // namespace HWY_NAMESPACE
}  // namespace rastray
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace rastray {

static_assert(sizeof(glm::vec4) == 4 * sizeof(float), "glm::vec4 is four packed floats");

HWY_EXPORT(BoxFilterLanes);
HWY_EXPORT(BoxFilterCoveredLanes);

void boxFilter(const glm::vec4* samples, int spp, size_t pixels, glm::vec4* out) {
  if (pixels == 0) return;
  HWY_DYNAMIC_DISPATCH(BoxFilterLanes)(&samples[0].x, spp, pixels, &out[0].x);
}

void boxFilterCovered(const glm::vec4* samples, const uint32_t* covered, uint32_t uncovered, int spp,
                      size_t pixels, glm::vec4* out, bool shareUniform) {
  if (pixels == 0) return;
  HWY_DYNAMIC_DISPATCH(BoxFilterCoveredLanes)
  (&samples[0].x, covered, uncovered, spp, pixels, &out[0].x, shareUniform);
}

}  // namespace rastray
#endif  // HWY_ONCE
