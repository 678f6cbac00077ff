// The depth-buffer formats and formulas: the one definition the rasterizer
// stores and the compare tool reasons with (raster/depth.h and
// compare/classify.h call these with the same DepthFormat).
//
// Window depth. For view depth d (znear n, zfar f; f may be +inf for
// perspective) the conventional window depth z in [0, 1] (near 0, far 1) is
//   perspective:  z = f(d − n) / (d(f − n)),   1 − n/d when f = inf;
//   orthographic: z = (d − n) / (f − n).
// The reversed window depth s = 1 − z (near 1, far 0) is computed directly,
// never as 1 − z:
//   perspective:  s = n(f − d) / (d(f − n)),   n/d when f = inf;
//   orthographic: s = (f − d) / (f − n).
// Far from the camera s is small, and 1 − z would cancel: z = 1 − n/d
// carries an absolute error of 2^-53 in double, i.e. a relative error of
// 2^-53 · d/n in s (1e-9 at d/n = 1e7, all of it at d/n = 2^53). The
// direct forms keep a relative error of a few double ULPs (≈ 2^-51) at
// every depth, far below float32's 2^-24, so the stored float is the
// correctly ordered rounding of s. Each form is affine in 1/d (perspective)
// or d (orthographic), so it interpolates linearly over the screen.
//
// Resolution. A format stores s_f = z (conventional) or s (reversed), with
// a step at that value of
//   Unorm24: 2^-24;  Unorm16: 2^-16;
//   Float, FloatReversed: float32's ULP of s_f, 2^(floor(log2 s_f) − 23)
//     (2^-149, the denormal step, below 2^-126).
// The resolution in view depth at d is step / |dz/dd| with
//   |dz/dd| = n f / ((f − n) d²)   (n / d² when f = inf);  1/(f − n) ortho,
// the same for z and s. Unorm16/24 and Float, with z → 1 far away, resolve
// ≈ d²/n · 2^-bits; FloatReversed, with s ≈ n/d, resolves ≤ d · 2^-23 for
// every n (relative precision at every distance).
#pragma once

#include <optional>
#include <string>

#include "common/scene.h"

namespace rastray {

// What a depth buffer stores and at which step (see above).
enum class DepthFormat { FloatReversed, Float, Unorm24, Unorm16 };
// "float-reversed", "float", "unorm24", "unorm16": the --depth-format spellings.
const char* toString(DepthFormat format);
std::optional<DepthFormat> parseDepthFormat(const std::string& name);

// True when the format stores larger values for nearer surfaces (s = 1 − z).
inline bool isReversed(DepthFormat format) { return format == DepthFormat::FloatReversed; }

// Conventional window depth z (near 0, far 1) of view depth d.
double conventionalWindowDepth(Projection projection, double znear, double zfar, double d);
// Reversed window depth s = 1 − z (near 1, far 0), without cancellation.
double reversedWindowDepth(Projection projection, double znear, double zfar, double d);
// The value the encoding stores at view depth d, before clamping to [0, 1]
// and rounding: z, or s for FloatReversed.
double storedWindowDepth(DepthFormat encoding, Projection projection, double znear, double zfar, double d);
// |dz/dd| = |ds/dd| at view depth d.
double windowDepthSlope(Projection projection, double znear, double zfar, double d);

// float32's ULP at |x|: 2^(floor(log2 |x|) − 23), 2^-149 below 2^-126,
// +inf for inf and NaN.
double float32Ulp(double x);
// The encoding's step at stored value s_f (not clamped: callers clamp as
// the buffer does): 2^-24 / 2^-16 for unorm, float32Ulp(s_f) for float.
double depthStep(DepthFormat encoding, double stored);
// The encoding's resolution in view depth at view depth d: the step at the
// stored value (clamped to [0, 1], where the buffer saturates) divided by
// |dz/dd|. +inf for d outside (0, inf).
double viewDepthResolution(DepthFormat encoding, Projection projection, double znear, double zfar, double d);

}  // namespace rastray
