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

void BoxFilterCoveredLanes(const float* samples, const uint32_t* covered, uint32_t uncovered, int spp,
                           size_t pixels, float* out, bool shareUniform) {
  // One RGBA pixel per 4-lane vector (in pieces where the target has fewer
  // lanes); an uncovered sample adds +0, as its stored 0 would.
  const hn::CappedTag<float, 4> d4;
  const size_t lanes = hn::Lanes(d4);
  const auto count = hn::Set(d4, float(spp)), zero = hn::Zero(d4);
  for (size_t p = 0; p < pixels; ++p) {
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
