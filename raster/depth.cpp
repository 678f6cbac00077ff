#include "raster/depth.h"

namespace rastray {

double windowDepth(DepthFormat format, Projection projection, double znear, double zfar, double d) {
  return storedWindowDepth(format, projection, znear, zfar, d);
}

double minimumResolvableDifference(DepthFormat format, double maxZ) {
  return depthStep(format, maxZ > 0.0 ? maxZ : 0.0);  // NaN, negative: the smallest step
}

double polygonOffset(DepthFormat format, double factor, double units, double maxSlope, double maxZ) {
  if (factor == 0.0 && units == 0.0) return 0.0;
  return factor * maxSlope + units * minimumResolvableDifference(format, maxZ);
}

const char* toString(DepthFunc func) { return func == DepthFunc::Less ? "less" : "lequal"; }

}  // namespace rastray
