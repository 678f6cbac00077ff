// primarySamples (raster/primary_samples.h): the interpolated hits and
// primary rays computed in double SIMD lanes have the scalar reference's
// bits (interpolatedHit, PrimaryRays) for every sample, on every compiled
// target, whatever the batch size: cameras near and far from the origin,
// narrow and wide fields of view, odd image sizes, an orthographic camera,
// and planes from steep to nearly degenerate.
#include "raster/primary_samples.h"

#include <gtest/gtest.h>

#include <hwy/targets.h>

#include <algorithm>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "raster_test_util.h"

namespace rastray {
namespace {

bool sameBits(const SampleHit& a, const SampleHit& b) {
  return a.instance == b.instance && a.triangle == b.triangle &&
         std::memcmp(&a.depth, &b.depth, sizeof(float)) == 0 &&
         std::memcmp(&a.b1, &b.b1, sizeof(float)) == 0 && std::memcmp(&a.b2, &b.b2, sizeof(float)) == 0;
}

bool sameBits(const Ray& a, const Ray& b) {
  const auto eq = [](double x, double y) { return std::memcmp(&x, &y, sizeof(double)) == 0; };
  for (int k = 0; k < 3; ++k)
    if (!eq(a.origin[k], b.origin[k]) || !eq(a.direction[k], b.direction[k])) return false;
  return eq(a.tNear, b.tNear) && eq(a.tFar, b.tFar) && eq(a.depthPerT, b.depthPerT);
}

// Setups with random planes through random origins: the lanes' arithmetic
// on values of every magnitude the renderer produces.
std::vector<TriangleSetup> randomSetups(std::mt19937& rng, int width, int height) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<TriangleSetup> setups(97);
  for (size_t i = 0; i < setups.size(); ++i) {
    TriangleSetup& t = setups[i];
    t.instance = uint32_t(i % 5);
    t.triangle = uint32_t(i);
    t.depth.x0 = (unit(rng) + 1.0) * 0.5 * width;
    t.depth.y0 = (unit(rng) + 1.0) * 0.5 * height;
    const double scale = i % 4 == 0 ? 1e-7 : i % 4 == 1 ? 1e3 : 1.0;
    t.invW = {0.5 + 0.4 * unit(rng), 1e-4 * unit(rng) * scale, 1e-4 * unit(rng) * scale};
    t.dOverW = {unit(rng), 1e-3 * unit(rng), 1e-3 * unit(rng)};
    t.b1OverW = {0.3 * (unit(rng) + 1.0), 1e-3 * unit(rng) * scale, 1e-3 * unit(rng)};
    t.b2OverW = {0.3 * (unit(rng) + 1.0), 1e-3 * unit(rng), 1e-3 * unit(rng) * scale};
  }
  return setups;
}

TEST(PrimarySamples, LanesGiveTheReferenceBitsOnEveryTarget) {
  std::mt19937 rng(20);
  struct Case {
    std::string name;
    Camera camera;
  };
  std::vector<Case> cases;
  cases.push_back(
      {"1920x1080 60deg", test::perspectiveCamera(1920, 1080, 1.047, {0.3, 0.2, 4.0}, {0, 0, 0})});
  cases.push_back(
      {"97x61 far eye", test::perspectiveCamera(97, 61, 0.7, {1e6, -3e5, 2e6}, {1e6 + 1, -3e5, 0})});
  cases.push_back({"640x480 narrow, finite zfar",
                   test::perspectiveCamera(640, 480, 0.01, {0, 5, 0}, {0.2, 0, -1}, 0.5, 1e4)});
  cases.push_back({"333x777 wide", test::perspectiveCamera(333, 777, 2.9, {-2, 1, 1}, {3, 2, -7})});
  cases.push_back({"orthographic", test::orthoCamera(128, 3.0)});
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const int w = c.camera.width, h = c.camera.height;
    const std::vector<TriangleSetup> setups = randomSetups(rng, w, h);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<uint32_t> winners;
    std::vector<glm::dvec2> positions;
    for (int k = 0; k < 3001; ++k) {
      // Runs of samples on one setup, as tiles give them, and single ones.
      winners.push_back(uint32_t((k / (k % 2 ? 1 : 7)) % setups.size()));
      positions.push_back(k % 11 == 0 ? glm::dvec2(k % w, (k / w) % h) + 0.5
                                      : glm::dvec2(u(rng) * w, u(rng) * h));
    }
    const size_t n = winners.size();
    const PrimaryRayConstants constants(c.camera);
    std::vector<SampleHit> expectedHits(n);
    std::vector<Ray> expectedRays(n);
    primarySamplesReference(constants, setups.data(), winners.data(), positions.data(), n,
                            expectedHits.data(), expectedRays.data());
    // The reference is PrimaryRays and interpolatedHit themselves.
    const PrimaryRays rays(c.camera);
    for (size_t i = 0; i < n; i += 97) {
      ASSERT_TRUE(sameBits(expectedRays[i], rays(positions[i])));
      ASSERT_TRUE(sameBits(expectedHits[i], interpolatedSampleHit(setups[winners[i]], positions[i])));
    }
    for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
      SCOPED_TRACE(hwy::TargetName(target));
      hwy::SetSupportedTargetsForTest(target);
      for (size_t batch : {size_t(1), size_t(5), size_t(64), size_t(100), n}) {
        std::vector<SampleHit> hits(n);
        std::vector<Ray> out(n);
        for (size_t first = 0; first < n; first += batch)
          primarySamples(constants, setups.data(), &winners[first], &positions[first],
                         std::min(batch, n - first), &hits[first], &out[first]);
        for (size_t i = 0; i < n; ++i) {
          ASSERT_TRUE(sameBits(hits[i], expectedHits[i])) << "batch " << batch << " sample " << i;
          ASSERT_TRUE(sameBits(out[i], expectedRays[i])) << "batch " << batch << " sample " << i;
        }
      }
    }
    hwy::SetSupportedTargetsForTest(0);
  }
}

}  // namespace
}  // namespace rastray
