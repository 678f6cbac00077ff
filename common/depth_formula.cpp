#include "common/depth_formula.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rastray {

const char* toString(DepthFormat format) {
  switch (format) {
    case DepthFormat::FloatReversed:
      return "float-reversed";
    case DepthFormat::Float:
      return "float";
    case DepthFormat::Unorm24:
      return "unorm24";
    case DepthFormat::Unorm16:
      return "unorm16";
  }
  return "?";
}

std::optional<DepthFormat> parseDepthFormat(const std::string& name) {
  for (DepthFormat f :
       {DepthFormat::FloatReversed, DepthFormat::Float, DepthFormat::Unorm24, DepthFormat::Unorm16})
    if (name == toString(f)) return f;
  return std::nullopt;
}

double conventionalWindowDepth(Projection projection, double znear, double zfar, double d) {
  if (projection == Projection::Orthographic) return (d - znear) / (zfar - znear);
  if (std::isinf(zfar)) return 1.0 - znear / d;
  return zfar * (d - znear) / (d * (zfar - znear));
}

double reversedWindowDepth(Projection projection, double znear, double zfar, double d) {
  // 1 − z rearranged so that nothing near 1 is subtracted (header).
  if (projection == Projection::Orthographic) return (zfar - d) / (zfar - znear);
  if (std::isinf(zfar)) return znear / d;
  return znear * (zfar - d) / (d * (zfar - znear));
}

double storedWindowDepth(DepthFormat encoding, Projection projection, double znear, double zfar, double d) {
  return isReversed(encoding) ? reversedWindowDepth(projection, znear, zfar, d)
                              : conventionalWindowDepth(projection, znear, zfar, d);
}

double windowDepthSlope(Projection projection, double znear, double zfar, double d) {
  if (projection == Projection::Orthographic) return 1.0 / (zfar - znear);
  if (std::isinf(zfar)) return znear / (d * d);
  return znear * zfar / ((zfar - znear) * d * d);
}

double float32Ulp(double x) {
  x = std::fabs(x);
  if (!std::isfinite(x)) return std::numeric_limits<double>::infinity();
  if (x < std::ldexp(1.0, -126)) return std::ldexp(1.0, -149);  // denormal range: fixed step
  int e;
  std::frexp(x, &e);  // x = m·2^e, m in [0.5, 1): IEEE exponent e − 1
  return std::ldexp(1.0, (e - 1) - 23);
}

double depthStep(DepthFormat encoding, double stored) {
  switch (encoding) {
    case DepthFormat::Unorm24:
      return std::ldexp(1.0, -24);
    case DepthFormat::Unorm16:
      return std::ldexp(1.0, -16);
    case DepthFormat::Float:
    case DepthFormat::FloatReversed:
      return float32Ulp(stored);
  }
  return std::numeric_limits<double>::infinity();
}

double viewDepthResolution(DepthFormat encoding, Projection projection, double znear, double zfar, double d) {
  if (!(d > 0.0) || std::isinf(d)) return std::numeric_limits<double>::infinity();
  const double stored = std::clamp(storedWindowDepth(encoding, projection, znear, zfar, d), 0.0, 1.0);
  return depthStep(encoding, stored) / windowDepthSlope(projection, znear, zfar, d);
}

}  // namespace rastray
