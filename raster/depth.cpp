#include "raster/depth.h"

namespace rastray {

DepthEncoding encodingOf(DepthFormat format) {
  switch (format) {
    case DepthFormat::FloatReversed:
      return DepthEncoding::FloatReversed;
    case DepthFormat::Float:
      return DepthEncoding::Float;
    case DepthFormat::Unorm24:
      return DepthEncoding::Unorm24;
    case DepthFormat::Unorm16:
      return DepthEncoding::Unorm16;
  }
  return DepthEncoding::FloatReversed;
}

double windowDepth(DepthFormat format, Projection projection, double znear, double zfar, double d) {
  return storedWindowDepth(encodingOf(format), projection, znear, zfar, d);
}

double minimumResolvableDifference(DepthFormat format, double maxZ) {
  return depthStep(encodingOf(format), maxZ > 0.0 ? maxZ : 0.0);  // NaN, negative: the smallest step
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
