// The kept unclipped triangles' planes in Highway double lanes
// (unclippedPlanes, raster/setup_planes.h) against the scalar steps: the
// fast setup path's setups equal the reference path's and, for every
// unclipped triangle, setupTriangleScalarPlanes' planes, on every target,
// for every depth format, both projections, a finite and an infinite far
// plane, with and without polygon offset; view depths from near the near
// plane to 10^4 times farther, clipped pieces in the same chunks, and
// edge-on triangles whose unsnapped area is not positive (the scalar
// sliver fallback).
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <cstring>
#include <random>

#include "raster/clip.h"
#include "raster/setup.h"
#include "raster_test_util.h"

namespace rastray {
namespace {

// Random triangles in front of a camera at the origin looking down −Z
// (both projections see x, y within ±0.7·depth up to depth 1): view depths
// from 10^-2.9 to 10^1.9, sizes from sub-pixel to several times their
// depth (those near the camera cross the near plane), both windings; and
// edge-on triangles, in a plane through the eye (perspective) or along −Z
// (orthographic). One single-sided instance, one double-sided.
Scene lanesScene(uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f), exponent(-2.9f, 1.9f), size(-3.0f, 0.5f);
  const auto randomTriangles = [&](bool edgeOn, std::vector<glm::vec3>* p, std::vector<glm::uvec3>* t) {
    for (uint32_t k = 0; k < 1500; ++k) {
      const float depth = std::pow(10.0f, exponent(rng));
      const glm::vec3 c(0.7f * depth * unit(rng), 0.7f * depth * unit(rng), -depth);
      const float r = depth * std::pow(10.0f, size(rng));
      const glm::vec3 u = glm::normalize(glm::vec3(unit(rng), unit(rng), unit(rng)));
      // Edge-on: the second direction is towards the eye (perspective)
      // or along Z (orthographic), alternately.
      const glm::vec3 v = edgeOn ? (k % 2 == 0 ? glm::normalize(c) : glm::vec3(0.0f, 0.0f, 1.0f))
                                 : glm::normalize(glm::vec3(unit(rng), unit(rng), unit(rng)));
      for (int i = 0; i < 3; ++i) p->push_back(c + r * (unit(rng) * u + unit(rng) * v));
      t->push_back(glm::uvec3(3 * k, 3 * k + 1, 3 * k + 2));
    }
  };
  Scene scene;
  for (bool doubleSided : {false, true}) {
    std::vector<glm::vec3> p;
    std::vector<glm::uvec3> t;
    randomTriangles(false, &p, &t);
    test::addMesh(scene, p, t, test::colored(glm::vec4(1.0f), AlphaMode::Opaque, doubleSided));
  }
  std::vector<glm::vec3> p;
  std::vector<glm::uvec3> t;
  randomTriangles(true, &p, &t);
  test::addMesh(scene, p, t, test::colored(glm::vec4(1.0f), AlphaMode::Opaque, true));
  return scene;
}

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Every double the planes hold, bit for bit (+0 and −0 apart).
bool samePlanes(const TriangleSetup& a, const TriangleSetup& b) {
  const auto same = [](const PlaneCoefficients& p, const PlaneCoefficients& q) {
    return sameBits(p.v0, q.v0) && sameBits(p.dx, q.dx) && sameBits(p.dy, q.dy);
  };
  return sameBits(a.depth.v0, b.depth.v0) && sameBits(a.depth.dx, b.depth.dx) &&
         sameBits(a.depth.dy, b.depth.dy) && sameBits(a.depth.x0, b.depth.x0) &&
         sameBits(a.depth.y0, b.depth.y0) && same(a.invW, b.invW) && same(a.dOverW, b.dOverW) &&
         same(a.b1OverW, b.b1OverW) && same(a.b2OverW, b.b2OverW);
}

// Whether t's unsnapped image area, in its setup's vertex order, is not
// positive: planePositions' snapped fallback.
bool takesTheSliverFallback(const Scene& scene, const ClipSpace& space, const TriangleSetup& t) {
  glm::dvec2 q[3];
  for (int i = 0; i < 3; ++i) q[i] = space.imageOf(space.clipOf(glm::dvec3(scene.positions[t.corners[i]])));
  const double stored = (q[1].x - q[0].x) * (q[2].y - q[0].y) - (q[1].y - q[0].y) * (q[2].x - q[0].x);
  const double ordered = t.frontFacing ? -stored : stored;  // front faces swap vertices 1 and 2
  return !(ordered > 0.0 && std::isfinite(ordered));
}

TEST(SetupLanes, UnclippedPlanesGiveTheScalarBitsOnEveryTarget) {
  const Scene scene = lanesScene(20261202);
  const int width = 160, height = 120;
  const SampleGrid grid = makeSampleGrid(1, width, height);
  size_t compared = 0, unclipped = 0, clipped = 0, slivers = 0;
  for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
    SCOPED_TRACE(hwy::TargetName(target));
    hwy::SetSupportedTargetsForTest(target);
    for (int camera = 0; camera < 3; ++camera) {
      Camera cam = camera == 2 ? test::orthoCamera(width, 1.0, 0.0, 100.0)
                               : test::perspectiveCamera(
                                     width, height, 1.0, glm::dvec3(0.0), glm::dvec3(0.0, 0.0, -1.0), 1e-3,
                                     camera == 0 ? 1e3 : std::numeric_limits<double>::infinity());
      cam.height = height;
      const ClipSpace space = makeClipSpace(cam, grid.guardPixels);
      for (DepthFormat format :
           {DepthFormat::FloatReversed, DepthFormat::Float, DepthFormat::Unorm24, DepthFormat::Unorm16})
        for (bool withOffset : {false, true}) {
          SCOPED_TRACE(std::to_string(camera) + " " + std::to_string(int(format)) + " " +
                       std::to_string(withOffset));
          const DepthSettings ds{format,   cam.projection,         cam.znear,
                                 cam.zfar, withOffset ? 1.5 : 0.0, withOffset ? 2.0 : 0.0};
          SetupCounters nf, nr;
          const auto fast =
              prepareTriangles(scene, space, grid, ds, CullMode::Back, {}, &nf, SetupPath::Fast);
          const auto reference =
              prepareTriangles(scene, space, grid, ds, CullMode::Back, {}, &nr, SetupPath::Reference);
          ASSERT_EQ(fast.size(), reference.size());
          for (size_t i = 0; i < fast.size(); ++i) {
            const TriangleSetup& f = fast[i];
            ASSERT_TRUE(samePlanes(f, reference[i])) << i;
            ASSERT_TRUE(sameBits(f.centroidDepth, reference[i].centroidDepth)) << i;
            for (int k = 0; k < 3; ++k) ASSERT_EQ(f.edge[k].original, reference[i].edge[k].original) << i;
            ++compared;
            if (f.fromClipping) {
              ++clipped;
              continue;
            }
            // The scalar reference itself, from the triangle's clip vertices.
            ClipVertex v[3];
            for (int k = 0; k < 3; ++k)
              v[k] = {space.clipOf(glm::dvec3(scene.positions[f.corners[k]])),
                      glm::dvec3(k == 0, k == 1, k == 2)};
            TriangleSetup s;
            ASSERT_EQ(setupTriangleScalarPlanes(space, grid, ds, v, CullMode::None, &s), SetupOutcome::Ok)
                << i;
            ASSERT_TRUE(samePlanes(f, s)) << i;
            ++unclipped;
            if (takesTheSliverFallback(scene, space, f)) ++slivers;
          }
        }
    }
  }
  hwy::SetSupportedTargetsForTest(0);
  // Every case the lanes and their scalar fallback take was compared.
  EXPECT_GT(unclipped, 1000u);
  EXPECT_GT(clipped, 0u);
  EXPECT_GT(slivers, 0u);
  EXPECT_GT(compared, unclipped);
}

}  // namespace
}  // namespace rastray
