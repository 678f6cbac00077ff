// The compare tool's depth resolution comes from the same definition the
// rasterizer stores with (common/depth_formula.h): bit-identical values.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "common/depth_formula.h"
#include "compare/classify.h"

namespace rastray {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

TEST(DepthFormulaAgreement, ResolutionAndTiesUseTheSharedDefinition) {
  const std::pair<DepthFormat, DepthFormat> formats[] = {
      {DepthFormat::FloatReversed, DepthFormat::FloatReversed},
      {DepthFormat::Float, DepthFormat::Float},
      {DepthFormat::Unorm24, DepthFormat::Unorm24},
      {DepthFormat::Unorm16, DepthFormat::Unorm16}};
  for (const auto& [stored, encoding] : formats)
    for (Projection p : {Projection::Perspective, Projection::Orthographic})
      for (double f : {50.0, kInf}) {
        if (p == Projection::Orthographic && std::isinf(f)) continue;
        const DepthPlanes planes{true, p, 0.1, f};
        for (double d : {0.05, 0.1, 0.37, 1.0, 7.5, 49.0, 60.0, 1e6}) {
          const double r = viewDepthResolution(encoding, p, 0.1, f, d);
          EXPECT_EQ(depthResolution(stored, planes, d), r) << toString(stored) << " d " << d;
          EXPECT_EQ(depthTieTolerance(stored, planes, d, d / 2), r + float32Ulp(d)) << toString(stored);
        }
      }
  for (double x : {0.0, 1e-40, 0.3, 1.0, 7e20, kInf}) EXPECT_EQ(ulp32(x), float32Ulp(x));
}

TEST(DepthFormulaAgreement, ReversedResolutionFarAwayIsRelative) {
  // d/n = 1e7, infinite far: s = n/d, resolution ulp32(s) · d²/n <= d · 2^-23.
  const DepthPlanes planes{true, Projection::Perspective, 1.0, kInf};
  const double r = depthResolution(DepthFormat::FloatReversed, planes, 1e7);
  EXPECT_LE(r, 1e7 * 0x1p-23);
  EXPECT_GE(r, 1e7 * 0x1p-24);
}

}  // namespace
}  // namespace rastray
