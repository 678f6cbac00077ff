// The rasterizer stores depth by the shared formulas of
// common/depth_formula.h (the compare tool reasons with the same ones),
// and its reversed depth keeps relative precision far from the camera.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "raster/depth.h"

namespace rastray {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr DepthFormat kFormats[] = {DepthFormat::FloatReversed, DepthFormat::Float, DepthFormat::Unorm24,
                                    DepthFormat::Unorm16};

TEST(ReversedDepth, KeepsRelativePrecisionAtLargeDistanceOverNear) {
  // d/n = 1e7 with an infinite far plane: the stored value is n/d itself,
  // not 1 − (1 − n/d), which is off by ≈ 1e-9 relative.
  EXPECT_EQ(windowDepth(DepthFormat::FloatReversed, Projection::Perspective, 1.0, kInf, 1e7), 1e-7);
  EXPECT_EQ(windowDepth(DepthFormat::FloatReversed, Projection::Perspective, 0.01, kInf, 1e5), 0.01 / 1e5);
  // Finite far plane: within a few double ULPs of n(f − d)/(d(f − n)).
  const long double n = 1.0L, f = 1e9L, d = 1e7L;
  const long double exact = n * (f - d) / (d * (f - n));
  const double s = windowDepth(DepthFormat::FloatReversed, Projection::Perspective, 1.0, 1e9, 1e7);
  EXPECT_LE(double(std::fabs((long double)s - exact) / exact), 4 * 0x1p-53);
}

TEST(ReversedDepth, ViewDepthsOneUlpApartStayOrdered) {
  double d = 1e7, previous = windowDepth(DepthFormat::FloatReversed, Projection::Perspective, 1.0, kInf, d);
  for (int i = 0; i < 1000; ++i) {
    d = std::nextafter(d, kInf);
    const double s = windowDepth(DepthFormat::FloatReversed, Projection::Perspective, 1.0, kInf, d);
    ASSERT_LT(s, previous) << "step " << i;
    previous = s;
  }
}

TEST(ReversedDepth, RasterStoresTheSharedDefinition) {
  for (DepthFormat format : kFormats)
    for (Projection p : {Projection::Perspective, Projection::Orthographic})
      for (double f : {50.0, kInf}) {
        if (p == Projection::Orthographic && std::isinf(f)) continue;
        for (double d : {0.1, 0.37, 1.0, 7.5, 49.0, 1e6}) {
          EXPECT_EQ(windowDepth(format, p, 0.1, f, d), storedWindowDepth(format, p, 0.1, f, d))
              << toString(format) << " d " << d;
        }
        for (double z : {0.0, 1e-30, 0.001, 0.5, 0.75, 1.0})
          EXPECT_EQ(minimumResolvableDifference(format, z), depthStep(format, z))
              << toString(format) << " z " << z;
      }
  EXPECT_EQ(parseDepthFormat(toString(DepthFormat::Unorm24)), DepthFormat::Unorm24);
}

}  // namespace
}  // namespace rastray
