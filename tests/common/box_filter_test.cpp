// The SIMD box filter (common/box_filter.h) gives the bits of the scalar
// loop it replaced: sum from 0 in sample order, divide by the count.
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "common/box_filter.h"

namespace rastray {
namespace {

uint32_t bitsOf(float f) {
  uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}

TEST(BoxFilter, EverySampleCountGivesTheScalarLoopsBits) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> value(-2.0f, 2.0f);
  const float specials[] = {
      -0.0f, 0.0f, std::numeric_limits<float>::infinity(), std::numeric_limits<float>::denorm_min(),
      1e38f, 3e38f};
  for (int spp : {1, 2, 3, 4, 5, 8, 16, 32})
    for (size_t pixels : {size_t(1), size_t(7), size_t(64), size_t(301)}) {
      std::vector<glm::vec4> samples(pixels * size_t(spp));
      for (size_t i = 0; i < samples.size(); ++i)
        for (int k = 0; k < 4; ++k)
          samples[i][k] = rng() % 5 == 0 ? specials[rng() % std::size(specials)] : value(rng);
      std::vector<glm::vec4> fast(pixels);
      boxFilter(samples.data(), spp, pixels, fast.data());
      for (size_t p = 0; p < pixels; ++p) {
        glm::vec4 sum(0.0f);
        for (int s = 0; s < spp; ++s) sum += samples[p * size_t(spp) + size_t(s)];
        const glm::vec4 expected = sum / float(spp);
        for (int k = 0; k < 4; ++k)
          ASSERT_EQ(bitsOf(fast[p][k]), bitsOf(expected[k]))
              << "spp " << spp << " pixel " << p << " channel " << k;
      }
    }
}

// boxFilterCovered: the bits of boxFilter over a copy with the uncovered
// samples set to 0, whatever those samples hold (NaN, -0, inf here); with
// shareUniform, also with a uniform pixel's samples set to its first one.
TEST(BoxFilter, CoveredSamplesGiveTheBitsOfZeroedEmptySamples) {
  std::mt19937 rng(8);
  std::uniform_real_distribution<float> value(-2.0f, 2.0f);
  // Tiny values too: sums whose quotient is subnormal and rounds (the
  // 4-spp lanes multiply by 0.25 instead of dividing by 4).
  std::uniform_real_distribution<float> tiny(-1e-37f, 1e-37f);
  const float specials[] = {-0.0f, std::numeric_limits<float>::quiet_NaN(),
                            std::numeric_limits<float>::infinity(), 3e38f,
                            3 * std::numeric_limits<float>::denorm_min()};
  const uint32_t none = 0xFFFFFFFFu;
  for (int64_t target : hwy::SupportedAndGeneratedTargets())
    for (int spp : {1, 2, 4, 9, 16})
      for (size_t pixels : {size_t(1), size_t(7), size_t(64)}) {
        std::vector<glm::vec4> samples(pixels * size_t(spp)), zeroed(samples.size());
        std::vector<uint32_t> covered(samples.size());
        for (size_t i = 0; i < samples.size(); ++i) {
          // Runs of covered and empty samples, empty pixels among them.
          covered[i] = (i / 3 + rng() % 2) % 3 == 0 ? none : uint32_t(rng() % 7);
          for (int k = 0; k < 4; ++k) {
            const uint32_t r = rng() % 10;
            samples[i][k] = r < 2 ? specials[rng() % std::size(specials)] : r < 4 ? tiny(rng) : value(rng);
          }
          zeroed[i] = covered[i] == none ? glm::vec4(0.0f) : samples[i];
        }
        std::vector<glm::vec4> got(pixels), expected(pixels);
        hwy::SetSupportedTargetsForTest(target);
        boxFilterCovered(samples.data(), covered.data(), none, spp, pixels, got.data());
        boxFilter(zeroed.data(), spp, pixels, expected.data());
        for (size_t p = 0; p < pixels; ++p)
          for (int k = 0; k < 4; ++k)
            ASSERT_EQ(bitsOf(got[p][k]), bitsOf(expected[p][k]))
                << "spp " << spp << " pixel " << p << " channel " << k;
        // shareUniform: every third pixel's samples all hold one covered
        // value; only its first sample's colour is read (the others hold
        // stale values), as if they held that colour.
        // (Any other pixel whose samples happen to hold one value is
        // uniform too.)
        for (size_t p = 0; p < pixels; p += 3) {
          const size_t first = p * size_t(spp);
          covered[first] = uint32_t(p % 7);
          for (int j = 0; j < spp; ++j) {
            covered[first + size_t(j)] = covered[first];
            if (j > 0) samples[first + size_t(j)] = glm::vec4(std::numeric_limits<float>::quiet_NaN());
          }
        }
        std::vector<glm::vec4> shared = zeroed;
        for (size_t p = 0; p < pixels; ++p) {
          const size_t first = p * size_t(spp);
          bool uniform = covered[first] != none;
          for (int j = 1; j < spp; ++j) uniform = uniform && covered[first + size_t(j)] == covered[first];
          for (int j = 0; j < spp && uniform; ++j) shared[first + size_t(j)] = samples[first];
        }
        boxFilterCovered(samples.data(), covered.data(), none, spp, pixels, got.data(),
                         /*shareUniform=*/true);
        boxFilter(shared.data(), spp, pixels, expected.data());
        for (size_t p = 0; p < pixels; ++p)
          for (int k = 0; k < 4; ++k)
            ASSERT_EQ(bitsOf(got[p][k]), bitsOf(expected[p][k]))
                << "shared, spp " << spp << " pixel " << p << " channel " << k << " "
                << hwy::TargetName(target);
        hwy::SetSupportedTargetsForTest(0);
      }
}

}  // namespace
}  // namespace rastray
