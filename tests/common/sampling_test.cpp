#include "common/sampling.h"

#include <limits>
#include <set>
#include <stdexcept>

#include <gtest/gtest.h>

namespace rastray {
namespace {

TEST(Sampling, SupportedCounts) {
  for (int spp : {1, 2, 4, 8, 16, 25, 36, 64, 100}) EXPECT_TRUE(isSupportedSampleCount(spp)) << spp;
  for (int spp : {0, -1, 3, 5, 9, 12, 24, 26}) EXPECT_FALSE(isSupportedSampleCount(spp)) << spp;
  EXPECT_THROW(samplePositions(9), std::invalid_argument);
}

TEST(Sampling, GridsStopAt16By16) {
  EXPECT_TRUE(isSupportedSampleCount(kMaxGridSide * kMaxGridSide));
  EXPECT_EQ(kMaxGridSide, 16);
  EXPECT_EQ(samplePositions(256).size(), 256u);
  for (int spp : {289, 324, 400, 1024, 65536, 46340 * 46340, std::numeric_limits<int>::max()})
    EXPECT_FALSE(isSupportedSampleCount(spp)) << spp;
  EXPECT_THROW(samplePositions(289), std::invalid_argument);
  // The message names the bound, so a user asking for 289 sees why.
  EXPECT_NE(supportedSampleCounts().find("n <= 16"), std::string::npos) << supportedSampleCounts();
  EXPECT_NE(supportedSampleCounts().find("256"), std::string::npos) << supportedSampleCounts();
}

TEST(Sampling, OneSampleIsThePixelCentre) {
  const auto p = samplePositions(1);
  ASSERT_EQ(p.size(), 1u);
  EXPECT_EQ(p[0], glm::dvec2(0.5, 0.5));
}

TEST(Sampling, Direct3DFourSamplePattern) {
  // D3D11 standard 4x pattern in 1/16 pixel from the centre, y down.
  const auto p = samplePositions(4);
  ASSERT_EQ(p.size(), 4u);
  EXPECT_EQ(p[0], glm::dvec2(0.5 - 2.0 / 16, 0.5 - 6.0 / 16));
  EXPECT_EQ(p[1], glm::dvec2(0.5 + 6.0 / 16, 0.5 - 2.0 / 16));
  EXPECT_EQ(p[2], glm::dvec2(0.5 - 6.0 / 16, 0.5 + 2.0 / 16));
  EXPECT_EQ(p[3], glm::dvec2(0.5 + 2.0 / 16, 0.5 + 6.0 / 16));
}

TEST(Sampling, PatternsAreDistinctAndInsideThePixel) {
  for (int spp : {2, 4, 8, 16, 25, 49}) {
    const auto p = samplePositions(spp);
    ASSERT_EQ(int(p.size()), spp);
    std::set<std::pair<double, double>> unique;
    for (const auto& s : p) {
      EXPECT_GE(s.x, 0.0);
      EXPECT_LT(s.x, 1.0);
      EXPECT_GE(s.y, 0.0);
      EXPECT_LT(s.y, 1.0);
      unique.insert({s.x, s.y});
    }
    EXPECT_EQ(int(unique.size()), spp) << spp;
  }
}

TEST(Sampling, GridIsCellCentres) {
  const auto p = samplePositions(25);
  EXPECT_EQ(p[0], glm::dvec2(0.1, 0.1));
  EXPECT_EQ(p[24], glm::dvec2(0.9, 0.9));
  EXPECT_EQ(p[7], glm::dvec2(0.5, 0.3));  // row 1, column 2
}

TEST(Sampling, CentreSampleIndex) {
  EXPECT_EQ(centreSampleIndex(1), 0);
  EXPECT_EQ(centreSampleIndex(25), 12);  // the exact centre of the 5x5 grid
  // 4x: all four samples are equally far (sqrt(40)/16): ties keep index 0.
  EXPECT_EQ(centreSampleIndex(4), 0);
  // 16x: sample 0 at (1, 1)/16 is the nearest.
  EXPECT_EQ(centreSampleIndex(16), 0);
  // 8x: (1,-3) and (-1,3) tie at sqrt(10): the lower index.
  EXPECT_EQ(centreSampleIndex(8), 0);
}

}  // namespace
}  // namespace rastray
