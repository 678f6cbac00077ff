// resolveTile (raster/resolve.h): the box filter's colour and the centre
// sample's depth and ids land on exactly the tile's pixels, whatever the
// alignment of the image rows (the resolve streams rows out with
// non-temporal stores on their 16-byte aligned middle and plain stores at
// the ends), and nothing outside the tile is written.
#include "raster/resolve.h"

#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <algorithm>
#include <cstring>
#include <limits>
#include <random>
#include <string>

namespace rastray {
namespace {

TEST(Resolve, WritesExactlyTheTilesPixelsAtAnyRowAlignment) {
  const float sentinel = -7.0f;
  for (int spp : {1, 4}) {
    // Odd image widths and tile corners: rows start at every offset modulo 16 bytes.
    for (int width : {61, 64, 130}) {
      for (int x0 : {0, 1, 3, 5}) {
        const int height = 9;
        const TileRect rect{x0, 2, std::min(width, x0 + 100), 7};  // wider than a tile too
        const TileSampleIndex index{rect, spp};
        TileSamples samples;
        samples.color.resize(index.count());
        samples.front.resize(index.count());
        for (size_t i = 0; i < index.count(); ++i) {
          const float v = float(i);
          samples.color[i] = glm::vec4(v, v + 0.25f, -v, 0.5f + float(i % 3));
          samples.front[i] = SampleHit{uint32_t(i % 5), uint32_t(i), 0.125f * v, 0.0f, 0.0f};
        }
        FlatImage image(width, height);
        for (size_t p = 0; p < image.color.size(); ++p) {
          image.color[p] = glm::vec4(sentinel);
          image.depth[p] = sentinel;
          image.instance[p] = image.triangle[p] = 0xDEADBEEFu;
        }
        const int centre = spp == 1 ? 0 : 2;
        // On every target: the image's rows are streamed out in its widest
        // vectors where aligned (also the ends of unaligned rows).
        for (int64_t simd : hwy::SupportedAndGeneratedTargets()) {
          hwy::SetSupportedTargetsForTest(simd);
          resolveTile(rect, spp, centre, samples, &image);
          hwy::SetSupportedTargetsForTest(0);
          for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x) {
              const size_t p = image.index(x, y);
              const bool inside = x >= rect.x0 && x < rect.x1 && y >= rect.y0 && y < rect.y1;
              SCOPED_TRACE("spp " + std::to_string(spp) + " width " + std::to_string(width) + " x0 " +
                           std::to_string(x0) + " pixel " + std::to_string(x) + "," + std::to_string(y) +
                           " " + hwy::TargetName(simd));
              if (!inside) {
                ASSERT_EQ(image.color[p], glm::vec4(sentinel));
                ASSERT_EQ(image.depth[p], sentinel);
                ASSERT_EQ(image.instance[p], 0xDEADBEEFu);
                ASSERT_EQ(image.triangle[p], 0xDEADBEEFu);
                continue;
              }
              // The box filter: (0 + s0 + … ) / spp, in sample order.
              glm::vec4 sum(0.0f);
              for (int s = 0; s < spp; ++s) sum += samples.color[index(x, y, s)];
              const glm::vec4 expected = sum / float(spp);
              ASSERT_EQ(0, std::memcmp(&image.color[p], &expected, sizeof expected));
              const SampleHit& h = samples.front[index(x, y, centre)];
              ASSERT_EQ(image.depth[p], h.depth);
              ASSERT_EQ(image.instance[p], h.instance);
              ASSERT_EQ(image.triangle[p], h.triangle);
            }
        }
      }
    }
  }
}

// The lean form (no front hits; ids from the winners, depth per sample,
// no background colours) against the full form of the same
// tile: the same bits in every pixel, background pixels and -0 colours
// included, for a tile of the frame's target and a tile-local one.
TEST(Resolve, LeanFormGivesTheFullFormsPixels) {
  std::mt19937 rng(20);
  std::vector<TriangleSetup> setups(5);
  for (size_t k = 0; k < setups.size(); ++k) {
    setups[k].instance = uint32_t(k % 3);
    setups[k].triangle = uint32_t(100 + k);
  }
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int spp : {1, 2, 4}) {
    for (bool frameTarget : {false, true}) {
      const int width = 130, height = 7;
      const TileRect rect{frameTarget ? 64 : 0, 2, frameTarget ? 130 : 64, 7};
      const TileSampleIndex index{rect, spp};
      DepthTarget target = frameTarget ? DepthTarget(width, height, spp)
                                       : DepthTarget(rect.x1 - rect.x0, rect.y1 - rect.y0, spp);
      if (!frameTarget) target.x0 = rect.x0, target.y0 = rect.y0;
      TileSamples full, lean;
      full.color.resize(index.count());
      full.front.resize(index.count());
      lean.lean = true;
      lean.color.resize(index.count());
      lean.depth.resize(index.count());
      for (int y = rect.y0; y < rect.y1; ++y)
        for (int x = rect.x0; x < rect.x1; ++x)
          for (int s = 0; s < spp; ++s) {
            const uint32_t i = index(x, y, s);
            // Short runs of one winner, background among them; in even
            // rows long runs (the 1-spp row writes vectors of pixels won by
            // one setup or by none whole).
            const uint32_t r = uint32_t(rng() % 8);
            const uint32_t w = y % 2 == 0 ? (x / 20 % 3 == 1 ? kNoSetup : uint32_t(x / 20 % 5))
                               : (x / 5 + y) % 4 == 0 || r == 0 ? kNoSetup
                                                                : uint32_t((x / 3 + r / 4) % 5);
            target.winners[target.index(x, y, s)] = w;
            const float v = float(rng() % 1000) * 0.001f;
            const glm::vec4 c = r == 1 ? glm::vec4(-0.0f, 0.0f, v, 1.0f) : glm::vec4(v, 0.5f * v, -v, 1.0f);
            if (w == kNoSetup) {
              full.color[i] = glm::vec4(0.0f);
              full.front[i] = SampleHit{};
              // What the lean form holds there: unset (here stale values).
              lean.color[i] = glm::vec4(nan, 2.0f, -0.0f, 3.0f);
              lean.depth[i] = nan;
            } else {
              const float depth = 0.5f + v;
              full.color[i] = lean.color[i] = c;
              full.front[i] = SampleHit{setups[w].instance, setups[w].triangle, depth, v, 0.25f};
              lean.depth[i] = depth;
            }
          }
      FlatImage a(width, height), b(width, height);
      for (size_t p = 0; p < a.color.size(); ++p) {
        a.color[p] = b.color[p] = glm::vec4(-7.0f);
        a.depth[p] = b.depth[p] = -7.0f;
        a.instance[p] = b.instance[p] = a.triangle[p] = b.triangle[p] = 0xDEADBEEFu;
      }
      // Every sample as the centre (the 4-spp lanes pick it among four).
      for (int centre = 0; centre < spp; ++centre) {
        resolveTile(rect, spp, centre, full, &a);
        const std::string what = "spp " + std::to_string(spp) + " centre " + std::to_string(centre) +
                                 (frameTarget ? " frame target" : " tile target");
        for (int64_t simd : hwy::SupportedAndGeneratedTargets()) {
          hwy::SetSupportedTargetsForTest(simd);
          resolveTileLean(rect, spp, centre, lean, target, setups.data(), &b);
          EXPECT_EQ(0, std::memcmp(a.color.data(), b.color.data(), a.color.size() * sizeof(glm::vec4)))
              << what << " " << hwy::TargetName(simd);
          EXPECT_EQ(0, std::memcmp(a.depth.data(), b.depth.data(), a.depth.size() * sizeof(float)))
              << what << " " << hwy::TargetName(simd);
          EXPECT_EQ(a.instance, b.instance) << what << " " << hwy::TargetName(simd);
          EXPECT_EQ(a.triangle, b.triangle) << what << " " << hwy::TargetName(simd);
        }
        hwy::SetSupportedTargetsForTest(0);
        size_t background = 0;
        for (int x = rect.x0; x < rect.x1; ++x) background += a.instance[a.index(x, 3)] == kNoId;
        EXPECT_GT(background, 0u) << what;
      }
    }
  }
}

}  // namespace
}  // namespace rastray
