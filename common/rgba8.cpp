// Highway's dynamic dispatch compiles the kernel below once per SIMD target
// (foreach_target.h re-includes this file) and picks one at run time.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "common/rgba8.cpp"
#include <hwy/foreach_target.h>  // before highway.h
#include <hwy/highway.h>

#include "common/rgba8.h"

#include <array>
#include <cstring>

#include "common/image.h"

#ifndef RASTRAY_RGBA8_TABLE
#define RASTRAY_RGBA8_TABLE
namespace rastray {
namespace rgba8_detail {

inline uint32_t bitsOf(float f) {
  uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}
inline float floatOf(uint32_t u) {
  float f;
  std::memcpy(&f, &u, sizeof f);
  return f;
}

// A clamped straight value in [0, 1] has bits in [0, 0x3F800000]; its top
// 16 bits (exponent and 7 mantissa bits) pick a bucket. Within a bucket
// the byte is base, or base + 1 from bit pattern `step` on.
constexpr uint32_t kBucketShift = 16;
constexpr size_t kBuckets = (0x3F800000u >> kBucketShift) + 1;
constexpr int32_t kNoStep = 0x7FFFFFFF;  // above every value's bits

struct Table {
  alignas(64) std::array<int32_t, kBuckets> base;
  alignas(64) std::array<int32_t, kBuckets> step;
};

// The 255 step positions of srgbByte over [0, 1] by bisection on the bit
// patterns (ordered like the values for non-negative floats), then the
// buckets. Throws nothing: a bucket with two steps is a logic error.
inline const Table& table() {
  static const Table t = [] {
    std::array<uint32_t, 256> first{};  // first[k]: smallest bits with byte >= k (k >= 1)
    for (int k = 1; k < 256; ++k) {
      uint32_t lo = 0, hi = 0x3F800000u;  // byte(lo) < k <= byte(hi)
      while (hi - lo > 1) {
        const uint32_t mid = lo + (hi - lo) / 2;
        if (srgbByte(floatOf(mid)) >= k)
          hi = mid;
        else
          lo = mid;
      }
      first[size_t(k)] = hi;
    }
    Table tb;
    int k = 1;  // the next step not yet below the bucket
    for (size_t b = 0; b < kBuckets; ++b) {
      const uint32_t start = uint32_t(b) << kBucketShift, end = start + (1u << kBucketShift);
      while (k < 256 && first[size_t(k)] <= start) ++k;
      tb.base[b] = k - 1;
      tb.step[b] = kNoStep;
      if (k < 256 && first[size_t(k)] < end) {
        tb.step[b] = int32_t(first[size_t(k)]);
        // At most one step per bucket: the next one lies beyond it.
        if (k + 1 < 256 && first[size_t(k) + 1] < end) std::abort();
      }
    }
    return tb;
  }();
  return t;
}

}  // namespace rgba8_detail
}  // namespace rastray
#endif  // RASTRAY_RGBA8_TABLE

HWY_BEFORE_NAMESPACE();
namespace rastray {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// Pixels as lanes: the four channels deinterleaved, encoded, and packed
// back as one little-endian 32-bit word per pixel (R in the lowest byte).
void EncodeRgba8Lanes(const float* premultiplied, size_t n, uint8_t* out, size_t* done) {
  const hn::ScalableTag<float> df;
  const hn::RebindToSigned<decltype(df)> di;
  const size_t lanes = hn::Lanes(df);
  const rgba8_detail::Table& t = rgba8_detail::table();
  const auto zero = hn::Zero(df), one = hn::Set(df, 1.0f);
  // unitClamp: v > 0 ? min(v, 1) : 0, so NaN becomes 0.
  const auto clamp = [&](auto v) { return hn::IfThenElseZero(hn::Gt(v, zero), hn::Min(v, one)); };
  const auto channelByte = [&](auto straight) {
    const auto bits = hn::BitCast(di, clamp(straight));
    const auto bucket = hn::ShiftRight<rgba8_detail::kBucketShift>(bits);
    const auto base = hn::GatherIndex(di, t.base.data(), bucket);
    const auto step = hn::GatherIndex(di, t.step.data(), bucket);
    // base + 1, less one below the step (a mask is −1 in its true lanes).
    return hn::Add(hn::Add(base, hn::Set(di, 1)), hn::VecFromMask(di, hn::Lt(bits, step)));
  };
  size_t i = 0;
  for (; i + lanes <= n; i += lanes) {
    hn::Vec<decltype(df)> r, g, b, a;
    hn::LoadInterleaved4(df, premultiplied + 4 * i, r, g, b, a);
    const auto visible = hn::Gt(a, zero);
    const auto straight = [&](auto c) { return hn::IfThenElseZero(visible, hn::Div(c, a)); };
    // Alpha is linear: × 255 + 0.5 in two roundings, as the scalar
    // definition (no fused multiply-add), then truncated.
    const auto alpha = hn::ConvertTo(di, hn::Add(hn::Mul(clamp(a), hn::Set(df, 255.0f)), hn::Set(df, 0.5f)));
    const auto word = hn::Or(hn::Or(channelByte(straight(r)), hn::ShiftLeft<8>(channelByte(straight(g)))),
                             hn::Or(hn::ShiftLeft<16>(channelByte(straight(b))), hn::ShiftLeft<24>(alpha)));
    hn::StoreU(word, di, reinterpret_cast<int32_t*>(out + 4 * i));
  }
  *done = i;
}

// NOLINTNEXTLINE(google-readability-namespace-comments)
}  // namespace HWY_NAMESPACE
}  // namespace rastray
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace rastray {

static_assert(sizeof(glm::vec4) == 4 * sizeof(float), "glm::vec4 is four packed floats");
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "encodeRgba8 packs bytes into little-endian words"
#endif

uint8_t srgbByte(float straight) {
  const float unit = straight > 0.0f ? (straight < 1.0f ? straight : 1.0f) : 0.0f;
  return uint8_t(linearToSrgb(unit) * 255.0f + 0.5f);
}

void encodeRgba8Reference(const glm::vec4* premultiplied, size_t n, uint8_t* out) {
  for (size_t i = 0; i < n; ++i) {
    const glm::vec4 c = premultiplied[i];
    for (int k = 0; k < 3; ++k) out[4 * i + size_t(k)] = srgbByte(c.a > 0.0f ? c[k] / c.a : 0.0f);
    const float alpha = c.a > 0.0f ? (c.a < 1.0f ? c.a : 1.0f) : 0.0f;
    out[4 * i + 3] = uint8_t(alpha * 255.0f + 0.5f);
  }
}

HWY_EXPORT(EncodeRgba8Lanes);

void encodeRgba8(const glm::vec4* premultiplied, size_t n, uint8_t* out) {
  if (n == 0) return;
  size_t done = 0;
  HWY_DYNAMIC_DISPATCH(EncodeRgba8Lanes)(&premultiplied[0].x, n, out, &done);
  encodeRgba8Reference(premultiplied + done, n - done, out + 4 * done);  // the last partial vector
}

}  // namespace rastray
#endif  // HWY_ONCE
