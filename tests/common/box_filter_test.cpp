// The SIMD box filter (common/box_filter.h) gives the bits of the scalar
// loop it replaced: sum from 0 in sample order, divide by the count.
#include <gtest/gtest.h>

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

}  // namespace
}  // namespace rastray
