// The shared depth formulas (common/depth_formula.h): reversed depth keeps
// relative precision far from the camera, the encodings' steps and the
// resolution in view depth agree with what the stored values resolve.
#include "common/depth_formula.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace rastray {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr DepthFormat kEncodings[] = {DepthFormat::FloatReversed, DepthFormat::Float, DepthFormat::Unorm24,
                                      DepthFormat::Unorm16};

double relativeError(double value, long double exact) {
  return double(std::fabs((long double)value - exact) / std::fabs(exact));
}

TEST(DepthFormula, ReversedDepthKeepsRelativePrecisionFarAway) {
  // d/n = 1e7: 1 − z would lose 2^-53 · 1e7 ≈ 1e-9 relative.
  const double n = 1.0, d = 1e7;
  EXPECT_EQ(reversedWindowDepth(Projection::Perspective, n, kInf, d), n / d);
  const double f = 1e9;
  const long double exactFinite =
      (long double)n * ((long double)f - d) / ((long double)d * ((long double)f - n));
  EXPECT_LE(relativeError(reversedWindowDepth(Projection::Perspective, n, f, d), exactFinite), 4 * 0x1p-53);
  // Orthographic, just before the far plane: s = (f − d)/(f − n) ≈ 1e-7.
  const double fo = 1e7 + 1.0, no = 0.5;
  const long double exactOrtho = ((long double)fo - d) / ((long double)fo - no);
  EXPECT_LE(relativeError(reversedWindowDepth(Projection::Orthographic, no, fo, d), exactOrtho), 4 * 0x1p-53);
  // Even at d/n = 2^60, where 1 − z would be 0 or 2^-53.
  EXPECT_EQ(reversedWindowDepth(Projection::Perspective, 1.0, kInf, 0x1p60), 0x1p-60);
}

TEST(DepthFormula, ReversedDepthOrdersViewDepthsOneUlpApart) {
  // View depths one double ULP apart at d/n = 1e7 stay strictly ordered
  // (1 − z would map a thousand of them to one value).
  const double n = 1.0;
  double d = 1e7;
  double previous = reversedWindowDepth(Projection::Perspective, n, kInf, d);
  for (int i = 0; i < 1000; ++i) {
    d = std::nextafter(d, kInf);
    const double s = reversedWindowDepth(Projection::Perspective, n, kInf, d);
    ASSERT_LT(s, previous) << "step " << i;
    previous = s;
  }
  // Float view depths one float ULP apart: the stored float32 never
  // reorders them.
  float df = 1e7f;
  float previousStored = float(reversedWindowDepth(Projection::Perspective, n, kInf, df));
  for (int i = 0; i < 1000; ++i) {
    df = std::nextafter(df, INFINITY);
    const float stored = float(reversedWindowDepth(Projection::Perspective, n, kInf, df));
    ASSERT_LE(stored, previousStored);
    previousStored = stored;
  }
}

TEST(DepthFormula, ReversedIsOneMinusConventional) {
  for (Projection p : {Projection::Perspective, Projection::Orthographic})
    for (double f : {100.0, kInf}) {
      if (p == Projection::Orthographic && std::isinf(f)) continue;
      for (double d : {0.1, 0.5, 3.0, 50.0, 99.0}) {
        const double z = conventionalWindowDepth(p, 0.1, f, d), s = reversedWindowDepth(p, 0.1, f, d);
        EXPECT_NEAR(z + s, 1.0, 1e-15) << d;
        EXPECT_EQ(storedWindowDepth(DepthFormat::FloatReversed, p, 0.1, f, d), s);
        EXPECT_EQ(storedWindowDepth(DepthFormat::Unorm24, p, 0.1, f, d), z);
      }
    }
  EXPECT_EQ(conventionalWindowDepth(Projection::Perspective, 0.1, kInf, 0.1), 0.0);
  EXPECT_EQ(reversedWindowDepth(Projection::Perspective, 0.1, kInf, 0.1), 1.0);
  EXPECT_EQ(reversedWindowDepth(Projection::Perspective, 0.1, 100.0, 100.0), 0.0);
}

TEST(DepthFormula, SlopeIsTheDerivative) {
  for (Projection p : {Projection::Perspective, Projection::Orthographic})
    for (double f : {100.0, kInf}) {
      if (p == Projection::Orthographic && std::isinf(f)) continue;
      for (double d : {0.5, 3.0, 50.0}) {
        const double h = d * 1e-6;
        const double numeric =
            (conventionalWindowDepth(p, 0.1, f, d + h) - conventionalWindowDepth(p, 0.1, f, d - h)) / (2 * h);
        EXPECT_NEAR(windowDepthSlope(p, 0.1, f, d) / numeric, 1.0, 1e-6) << d;
      }
    }
}

TEST(DepthFormula, Steps) {
  EXPECT_EQ(depthStep(DepthFormat::Unorm24, 0.5), 0x1p-24);
  EXPECT_EQ(depthStep(DepthFormat::Unorm16, 0.5), 0x1p-16);
  EXPECT_EQ(depthStep(DepthFormat::Float, 0.75), 0x1p-24);
  EXPECT_EQ(depthStep(DepthFormat::FloatReversed, 0.001), 0x1p-33);
  EXPECT_EQ(float32Ulp(0.0), 0x1p-149);
  EXPECT_EQ(float32Ulp(1.0), 0x1p-23);
  EXPECT_EQ(float32Ulp(-3.0), 0x1p-22);
  EXPECT_TRUE(std::isinf(float32Ulp(kInf)));
  EXPECT_TRUE(std::isinf(viewDepthResolution(DepthFormat::Float, Projection::Perspective, 0.1, kInf, 0.0)));
  EXPECT_TRUE(std::isinf(viewDepthResolution(DepthFormat::Float, Projection::Perspective, 0.1, kInf, kInf)));
}

// The value a buffer of the encoding holds for stored value s.
double rounded(DepthFormat e, double s) {
  switch (e) {
    case DepthFormat::Unorm24:
      return double(std::lround(s * double((1u << 24) - 1u)));
    case DepthFormat::Unorm16:
      return double(std::lround(s * double((1u << 16) - 1u)));
    default:
      return double(float(s));
  }
}

TEST(DepthFormula, ResolutionIsWhatTheRoundedValuesTellApart) {
  // Moving a view depth by twice the stated resolution changes the value
  // the buffer holds; the resolution is honest for every encoding.
  for (DepthFormat e : kEncodings)
    for (Projection p : {Projection::Perspective, Projection::Orthographic})
      for (double f : {1000.0, kInf}) {
        if (p == Projection::Orthographic && std::isinf(f)) continue;
        for (double d : {0.2, 1.0, 10.0, 300.0}) {
          const double r = viewDepthResolution(e, p, 0.1, f, d);
          ASSERT_TRUE(std::isfinite(r) && r > 0.0);
          const double a = rounded(e, storedWindowDepth(e, p, 0.1, f, d));
          const double b = rounded(e, storedWindowDepth(e, p, 0.1, f, d + 2.0 * r));
          EXPECT_NE(a, b) << int(e) << " " << int(p) << " f " << f << " d " << d << " r " << r;
        }
      }
}

}  // namespace
}  // namespace rastray
