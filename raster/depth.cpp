#include "raster/depth.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace rastray {

namespace {

uint32_t floatBits(float f) {
  uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}

constexpr uint32_t kOneBits = 0x3F800000u;  // 1.0f: the largest stored float

}  // namespace

double windowDepth(DepthFormat format, Projection projection, double znear, double zfar, double d) {
  double z;
  if (projection == Projection::Orthographic)
    z = (d - znear) / (zfar - znear);
  else if (std::isinf(zfar))
    z = 1.0 - znear / d;
  else
    z = zfar * (d - znear) / (d * (zfar - znear));
  return isReversed(format) ? 1.0 - z : z;
}

uint32_t depthKey(DepthFormat format, double z) {
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

double minimumResolvableDifference(DepthFormat format, double maxZ) {
  switch (format) {
    case DepthFormat::Unorm24:
      return std::ldexp(1.0, -24);
    case DepthFormat::Unorm16:
      return std::ldexp(1.0, -16);
    case DepthFormat::Float:
    case DepthFormat::FloatReversed: {
      if (!(maxZ > 0.0)) return std::ldexp(1.0, -149);  // zero: the smallest denormal step
      int e;
      std::frexp(maxZ, &e);  // maxZ = m·2^e, m in [0.5, 1): IEEE exponent e − 1
      return std::ldexp(1.0, (e - 1) - 23);
    }
  }
  return 0.0;
}

double polygonOffset(DepthFormat format, double factor, double units, double maxSlope, double maxZ) {
  if (factor == 0.0 && units == 0.0) return 0.0;
  return factor * maxSlope + units * minimumResolvableDifference(format, maxZ);
}

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

const char* toString(DepthFunc func) { return func == DepthFunc::Less ? "less" : "lequal"; }

}  // namespace rastray
