// The vertex codes in lanes (raster/setup_vertex_codes.h) against the scalar
// reference, on every Highway target.
#include "raster/setup_vertex_codes.h"

#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "raster/setup.h"
#include "raster_test_util.h"

namespace rastray {
namespace {

// The lanes' codes against the reference's for `positions`, in blocks of 1
// to 200 vertices (partial vectors, several blocks per call), on every
// target: the same outside bits, and where they are 0 the same snapped
// position.
void expectReferenceCodes(const ClipSpace& space, double unitsPerPixel,
                          const std::vector<glm::vec3>& positions) {
  const size_t n = positions.size();
  std::vector<uint8_t> outside(n);
  std::vector<SnappedVertex> snapped(n);
  vertexCodesReference(space, unitsPerPixel, positions.data(), n, outside.data(), snapped.data());
  for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
    SCOPED_TRACE(hwy::TargetName(target));
    hwy::SetSupportedTargetsForTest(target);
    for (size_t batch : {size_t(1), size_t(5), size_t(64), size_t(200)}) {
      std::vector<uint8_t> laneOutside(n, 0xff);
      std::vector<SnappedVertex> laneSnapped(n);
      for (size_t first = 0; first < n; first += batch)
        vertexCodes(space, unitsPerPixel, &positions[first], std::min(batch, n - first), &laneOutside[first],
                    &laneSnapped[first]);
      for (size_t i = 0; i < n; ++i) {
        const glm::vec3& p = positions[i];
        ASSERT_EQ(laneOutside[i], outside[i])
            << batch << " vertex " << i << " (" << p.x << ", " << p.y << ", " << p.z << ")";
        if (outside[i] != 0) continue;
        ASSERT_EQ(laneSnapped[i].x, snapped[i].x) << batch << " vertex " << i << " x " << p.x;
        ASSERT_EQ(laneSnapped[i].y, snapped[i].y) << batch << " vertex " << i << " y " << p.y;
      }
    }
  }
  hwy::SetSupportedTargetsForTest(0);
}

// Random vertices in front of, beside, behind and beyond a perspective
// camera (finite and infinite far plane), on its near and far planes,
// and non-finite ones.
TEST(SetupVertexCodes, VertexCodesInLanesGiveTheReferenceBitsForAPerspectiveCameraOnEveryTarget) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  for (const double zfar : {50.0, std::numeric_limits<double>::infinity()}) {
    const Camera camera = test::perspectiveCamera(1920, 1080, 1.0, glm::dvec3(0.3, 0.6, 0.4),
                                                  glm::dvec3(0.0, -0.4, -6.0), 0.05, zfar);
    for (const int spp : {1, 4, 25}) {  // 25: 1,280 units per pixel, not a power of two
      const SampleGrid grid = makeSampleGrid(spp, camera.width, camera.height);
      const ClipSpace space = makeClipSpace(camera, grid.guardPixels);
      std::vector<glm::vec3> p;
      for (int k = 0; k < 3000; ++k) {
        const float scale = k % 5 == 0 ? 1e5f : k % 7 == 0 ? 0.01f : 10.0f;
        p.push_back(glm::vec3(unit(rng), unit(rng), unit(rng)) * scale);
      }
      // On the near and far planes, and at the eye.
      const glm::dvec3 eye(0.3, 0.6, 0.4), forward = glm::normalize(glm::dvec3(0.0, -0.4, -6.0) - eye);
      p.push_back(glm::vec3(eye + forward * 0.05)), p.push_back(glm::vec3(eye + forward * 50.0));
      p.push_back(glm::vec3(eye));
      p.push_back({inf, 0.0f, -3.0f}), p.push_back({0.0f, -inf, -3.0f}), p.push_back({nan, 0.0f, -3.0f});
      expectReferenceCodes(space, double(grid.unitsPerPixel), p);
    }
  }
}

// An orthographic camera whose image position is (x + 1)·512 (x from
// world x, y alike, exact in float): vertices exactly on pixel and unit
// boundaries, half a unit off them both ways (round half away from zero
// at every tie, either sign), on the guard band's edges and just beyond,
// and with a guard band so wide that the clamp to ±2^29 units decides.
TEST(SetupVertexCodes, VertexCodesInLanesGiveTheReferenceBitsOnTiesEdgesAndTheClampOnEveryTarget) {
  const int size = 1024;
  const SampleGrid grid = makeSampleGrid(1, size, size);
  const double U = double(grid.unitsPerPixel);
  const ClipSpace space = makeClipSpace(test::orthoCamera(size, 1.0, 0.0, 100.0), grid.guardPixels);
  const double unitInWorld = 2.0 / (size * U);  // one unit of image position in world x
  std::vector<glm::vec3> p;
  for (int j = -600; j <= 600; ++j)
    for (const double offset : {0.0, 0.5, -0.5, 0.25, U / 2, U}) {
      const float c = float(j * 37 * unitInWorld + offset * unitInWorld);
      p.push_back({c, -c, -1.0f});
      p.push_back({c, 0.5f * c, -1.0f});
    }
  for (const double g : {space.guard.x, -space.guard.x}) {
    const float edge = float(g);
    p.push_back({edge, 0.0f, -1.0f}), p.push_back({0.0f, edge, -1.0f});
    p.push_back({std::nextafter(edge, 2.0f * edge), 0.0f, -1.0f});
    p.push_back({std::nextafter(edge, 0.0f), std::nextafter(edge, 0.0f), -1.0f});
  }
  p.push_back({0.0f, 0.0f, 0.0f}), p.push_back({0.0f, 0.0f, -100.0f}), p.push_back({0.0f, 0.0f, -100.01f});
  expectReferenceCodes(space, U, p);

  ClipSpace wide = space;
  wide.guard = {1e6, 1e6};  // 2^29 units is 2^21 pixels: x = 4095 and −4097 reach it
  std::vector<glm::vec3> far;
  for (const float c : {4096.0f, 4095.0f, 4097.0f, 1e5f, -4096.0f, -4095.0f, -4097.0f, -1e5f})
    far.push_back({c, -c, -1.0f}), far.push_back({c, 0.25f, -1.0f});
  expectReferenceCodes(wide, U, far);
}

}  // namespace
}  // namespace rastray
