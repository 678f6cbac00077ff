// Depth formats, depth keys and polygon offset.
//
// Every format stores a window depth in [0, 1] computed from the view
// depth d (znear n, zfar f; f may be +inf for perspective) by the shared
// formulas of common/depth_formula.h, which the compare tool uses too:
//   conventional (Float, Unorm24, Unorm16): z = f(d − n) / (d(f − n)),
//     i.e. 1 − n/d for f = inf; orthographic z = (d − n) / (f − n). Near 0, far 1.
//   FloatReversed (the default): s = 1 − z (near 1, far 0), computed
//     directly as n(f − d) / (d(f − n)), n/d for f = inf, (f − d) / (f − n)
//     ortho, so it keeps relative precision where 1 − z would cancel.
// The stored value is affine in screen space, so it is interpolated
// linearly over the screen from the vertices (in double) and only then
// rounded to the format.
//
// Precision (the smallest step the buffer can tell apart, at view depth d):
//   Unorm16: 2^-16 in z, ≈ d²/n · 2^-16 in view depth (perspective, f = inf).
//   Unorm24: 2^-24 in z, ≈ d²/n · 2^-24.
//   Float:   z near 1 has ULP 2^-24, the same as unorm24 far from the camera,
//            and far better only near the near plane, where z is small.
//   FloatReversed: s ≈ n/d is small far away, where float's exponent gives
//            relative precision 2^-24 in s, i.e. ≈ d · 2^-24 in view depth:
//            nearly constant relative precision at every distance (the
//            double-precision s before rounding is good to ≈ 2^-51 relative).
// Orthographic z is linear in d, so the steps are (f − n) times the above.
//
// The raster stages compare *depth keys*: a uint32 per format where a
// smaller key is nearer (float bit patterns of non-negative floats sort as
// integers; reversed keys are mirrored). kClearDepthKey lies beyond every
// format's far plane, so the first fragment at a sample always passes.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "common/depth_formula.h"
#include "raster/options.h"

namespace rastray {

constexpr uint32_t kClearDepthKey = 0xFFFFFFFFu;

// Window depth of view depth d as `format` stores it (z, or s reversed; see
// above), before clamping and rounding.
double windowDepth(DepthFormat format, Projection projection, double znear, double zfar, double d);

// The key stored for window depth z (clamped to [0, 1] first, as GL clamps).
// Inline: the depth pass calls it at every covered sample.
inline uint32_t depthKey(DepthFormat format, double z) {
  constexpr uint32_t kOneBits = 0x3F800000u;  // 1.0f: the largest stored float
  const auto floatBits = [](float f) {
    uint32_t u;
    std::memcpy(&u, &f, sizeof u);
    return u;
  };
  z = std::clamp(z, 0.0, 1.0);
  switch (format) {
    case DepthFormat::Float:
      return floatBits(float(z));
    case DepthFormat::FloatReversed:
      return kOneBits - floatBits(float(z));  // larger z: smaller key
    case DepthFormat::Unorm24:
      return uint32_t(std::lround(z * double((1u << 24) - 1u)));
    case DepthFormat::Unorm16:
      return uint32_t(std::lround(z * double((1u << 16) - 1u)));
  }
  return kClearDepthKey;
}

// glPolygonOffset's r: the smallest difference the format resolves for a
// primitive whose largest window depth is maxZ: 2^-bits for unorm (the
// format's own step), 2^(e − 23) for float with e the exponent of maxZ
// (OpenGL 4.6 §14.6.5; 2^-149 below 2^-126): depthStep of
// common/depth_formula.h.
double minimumResolvableDifference(DepthFormat format, double maxZ);

// The offset to add to window depth *away from the viewer* (positive
// factor/units push back, glPolygonOffset): factor·DZ + units·r, with DZ
// = max(|∂z/∂x|, |∂z/∂y|) in z per pixel. Callers add it for conventional
// formats and subtract it for reversed ones.
double polygonOffset(DepthFormat format, double factor, double units, double maxSlope, double maxZ);

// The depth-test rule for a fragment against the stored (key, id), with
// (instance, triangle) packed into `id` for ties: the result is what
// OpenGL gives when primitives are submitted in (instance, triangle)
// order, so it does not depend on the real submission order:
//   Less:   nearer, or equal and a lower id (the first submitted keeps it);
//   LEqual: nearer, or equal and an id not lower (the last submitted wins).
inline bool passesDepthTest(DepthFunc func, uint32_t key, uint64_t id, uint32_t storedKey,
                            uint64_t storedId) {
  if (key != storedKey) return key < storedKey;
  return func == DepthFunc::Less ? id < storedId : id >= storedId;
}

inline uint64_t packId(uint32_t instance, uint32_t triangle) { return (uint64_t(instance) << 32) | triangle; }

const char* toString(DepthFunc func);

}  // namespace rastray
