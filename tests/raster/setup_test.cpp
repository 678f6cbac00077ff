#include "raster/setup.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "common/error.h"
#include "raster/bin.h"
#include "raster/clip.h"
#include "raster/coverage.h"
#include "raster_test_util.h"

#include "tests/test_labels.h"

// Tests here render on 2 or more threads (the ThreadSanitizer stage runs them), except those marked quick.
RASTRAY_TEST_LABELS("threads");

namespace rastray {
namespace {

using test::addMesh;
using test::colored;
using test::orthoCamera;

// Coverage count per sample of every set-up triangle, without a depth test.
struct CoverageCount {
  std::vector<int> front, back;
  std::vector<std::vector<uint32_t>> who;  // setup indices covering each sample
};

CoverageCount countCoverage(const Scene& scene, const Camera& camera, int spp) {
  const SampleGrid grid = makeSampleGrid(spp, camera.width, camera.height);
  const ClipSpace space = makeClipSpace(camera, grid.guardPixels);
  const DepthSettings ds{DepthFormat::FloatReversed, camera.projection, camera.znear, camera.zfar, 0, 0};
  SetupCounters counters;
  const auto setups = prepareTriangles(scene, space, grid, ds, CullMode::None, {}, &counters);
  CoverageCount c;
  const size_t n = size_t(camera.width) * size_t(camera.height) * size_t(spp);
  c.front.assign(n, 0);
  c.back.assign(n, 0);
  c.who.resize(n);
  CoverageScratch scratch;
  const TileRect all{0, 0, camera.width, camera.height};
  for (size_t i = 0; i < setups.size(); ++i)
    forEachCoveredSample(setups[i], grid, all, scratch, [&](int x, int y, int s) {
      const size_t k = (size_t(y) * size_t(camera.width) + size_t(x)) * size_t(spp) + size_t(s);
      (setups[i].frontFacing ? c.front : c.back)[k]++;
      c.who[k].push_back(uint32_t(i));
    });
  return c;
}

RASTRAY_TEST_LABELS_OF(SampleGrid, FixedPointRefinementPutsEverySampleOnTheGrid, "quick");
TEST(SampleGrid, FixedPointRefinementPutsEverySampleOnTheGrid) {
  EXPECT_EQ(makeSampleGrid(1, 64, 64).k, 1);
  EXPECT_EQ(makeSampleGrid(16, 64, 64).k, 1);
  EXPECT_EQ(makeSampleGrid(64, 64, 64).k, 1);  // 8x8: 1/16 steps
  EXPECT_EQ(makeSampleGrid(25, 64, 64).k, 5);  // 5x5: tenths
  const SampleGrid g = makeSampleGrid(25, 64, 64);
  for (size_t s = 0; s < g.offsets.size(); ++s)
    EXPECT_EQ(double(g.offsets[s].x) / double(g.unitsPerPixel), g.positions[s].x);
  EXPECT_EQ(makeSampleGrid(1, 64, 64).safePixels, double(1 << 21));
  EXPECT_THROW(makeSampleGrid(3, 64, 64), InputError);
  EXPECT_THROW(makeSampleGrid(1, (1 << 20) + 1, 4), InputError);
}

// An 8×8 ortho view where world (x, y) is image (x + 4, 4 − y): vertices on
// half-integers land exactly on 1-spp sample positions.
Camera pixelCamera() { return orthoCamera(8, 4.0, 0.0, 10.0); }
glm::vec3 at(double ix, double iy) { return glm::vec3(float(ix - 4.0), float(4.0 - iy), -1.0f); }

TEST(FillRule, TopLeftEdgesOwnTheirSamples) {
  // Right triangle with a horizontal top edge, a vertical left edge and a
  // diagonal, all through sample centres.
  Scene scene;
  addMesh(scene, {at(1.5, 1.5), at(1.5, 5.5), at(5.5, 1.5)}, {{0, 1, 2}}, colored(glm::vec4(1)));
  const auto c = countCoverage(scene, pixelCamera(), 1);
  const auto covered = [&](int x, int y) { return c.front[size_t(y * 8 + x)] + c.back[size_t(y * 8 + x)]; };
  EXPECT_EQ(covered(1, 1), 1);  // top-left vertex
  EXPECT_EQ(covered(3, 1), 1);  // on the top edge
  EXPECT_EQ(covered(1, 3), 1);  // on the left edge
  EXPECT_EQ(covered(5, 1), 0);  // top-right vertex: also on the right (diagonal) edge
  EXPECT_EQ(covered(1, 5), 0);  // bottom vertex
  EXPECT_EQ(covered(3, 3), 0);  // on the diagonal (a right edge)
  EXPECT_EQ(covered(2, 2), 1);  // inside
  // The mirrored triangle: a horizontal bottom edge and a vertical right edge are not owned.
  Scene mirrored;
  addMesh(mirrored, {at(5.5, 5.5), at(5.5, 1.5), at(1.5, 5.5)}, {{0, 1, 2}}, colored(glm::vec4(1)));
  const auto m = countCoverage(mirrored, pixelCamera(), 1);
  const auto mcov = [&](int x, int y) { return m.front[size_t(y * 8 + x)] + m.back[size_t(y * 8 + x)]; };
  EXPECT_EQ(mcov(3, 5), 0);  // bottom edge
  EXPECT_EQ(mcov(5, 3), 0);  // right edge
  EXPECT_EQ(mcov(3, 3), 1);  // the diagonal is this triangle's left edge
  EXPECT_EQ(mcov(4, 4), 1);
}

TEST(FillRule, SharedEdgesAndPixelAlignedVerticesCoverOnce) {
  // A fan of 8 triangles around a vertex on a sample, every vertex on a
  // sample: every sample of the square is covered exactly once, except the
  // bottom and right borders, which belong to the neighbours below/right.
  Scene scene;
  std::vector<glm::vec3> p = {at(3.5, 3.5), at(1.5, 1.5), at(3.5, 1.5), at(5.5, 1.5), at(5.5, 3.5),
                              at(5.5, 5.5), at(3.5, 5.5), at(1.5, 5.5), at(1.5, 3.5)};
  std::vector<glm::uvec3> t;
  for (uint32_t i = 0; i < 8; ++i) t.push_back({0u, 1 + (i + 1) % 8, 1 + i});  // CCW with y up
  addMesh(scene, p, t, colored(glm::vec4(1)));
  const auto c = countCoverage(scene, pixelCamera(), 1);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      const bool inside = x >= 1 && x < 5 && y >= 1 && y < 5;
      EXPECT_EQ(c.front[size_t(y * 8 + x)], inside ? 1 : 0) << x << "," << y;
      EXPECT_EQ(c.back[size_t(y * 8 + x)], 0);
    }
}

TEST(Watertight, DenseSphereCoversEverySampleOnceAtManySubpixelOffsets) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.5, 0.5);
  for (int trial = 0; trial < 12; ++trial) {
    Scene scene;
    // Offsets in pixels of a 64-pixel view of a 4-unit window: 1 px = 1/16 unit.
    const glm::dvec3 centre(jitter(rng) / 16.0, jitter(rng) / 16.0, -5.0);
    test::addSphere(scene, centre, 1.5, 48, 24);
    const Camera camera = test::perspectiveCamera(64, 64, 0.8, glm::dvec3(0), glm::dvec3(0, 0, -1), 0.1);
    const auto c = countCoverage(scene, camera, 16);
    size_t inside = 0;
    for (size_t i = 0; i < c.front.size(); ++i) {
      // Closed surface: one front and one back layer inside, nothing outside.
      ASSERT_EQ(c.front[i], c.back[i]) << "trial " << trial << " sample " << i;
      ASSERT_LE(c.front[i], 1) << "trial " << trial << " sample " << i;
      inside += size_t(c.front[i]);
    }
    EXPECT_GT(inside, c.front.size() / 4);
  }
}

// The incremental stepping of forEachCoveredSample against the scalar
// reference: every edge function evaluated from scratch at every sample.
TEST(Coverage, IncrementalSteppingMatchesTheScalarReference) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> coord(-6.0f, 6.0f);
  Scene scene;
  for (int i = 0; i < 200; ++i)
    addMesh(scene,
            {glm::vec3(coord(rng), coord(rng), -1.0f - 0.01f * float(i)),
             glm::vec3(coord(rng), coord(rng), -1.0f), glm::vec3(coord(rng), coord(rng), -2.0f)},
            {{0, 1, 2}});
  const Camera camera = orthoCamera(40, 4.0, 0.0, 10.0);
  for (int spp : {1, 4, 16, 25}) {
    const SampleGrid grid = makeSampleGrid(spp, camera.width, camera.height);
    const ClipSpace space = makeClipSpace(camera, grid.guardPixels);
    const DepthSettings ds{DepthFormat::FloatReversed, camera.projection, camera.znear, camera.zfar, 0, 0};
    SetupCounters n;
    const auto setups = prepareTriangles(scene, space, grid, ds, CullMode::None, {}, &n);
    ASSERT_GT(setups.size(), 100u);
    CoverageScratch scratch;
    for (const TriangleSetup& t : setups) {
      std::vector<int> fast(size_t(40 * 40 * spp), 0), slow(fast.size(), 0);
      // Two tiles' worth of rectangles to exercise the clamping to a rect.
      for (const TileRect& r : {TileRect{0, 0, 17, 40}, TileRect{17, 0, 40, 40}})
        forEachCoveredSample(t, grid, r, scratch,
                             [&](int x, int y, int s) { fast[size_t((y * 40 + x) * spp + s)]++; });
      for (int y = 0; y < 40; ++y)
        for (int x = 0; x < 40; ++x)
          for (int s = 0; s < spp; ++s) {
            const int64_t px = int64_t(x) * grid.unitsPerPixel + grid.offsets[size_t(s)].x;
            const int64_t py = int64_t(y) * grid.unitsPerPixel + grid.offsets[size_t(s)].y;
            bool inside = true;
            for (const EdgeFunction& e : t.edge) inside = inside && e.at(px, py) + e.bias >= 0;
            slow[size_t((y * 40 + x) * spp + s)] = inside;
          }
      ASSERT_EQ(fast, slow) << "spp " << spp;
    }
  }
}

TEST(Setup, DegenerateTrianglesCoverNothing) {
  Scene scene;
  addMesh(scene, {at(1.5, 1.5), at(3.5, 3.5), at(5.5, 5.5)}, {{0, 1, 2}});  // collinear
  addMesh(scene, {at(1.5, 1.5), at(1.5, 1.5), at(5.5, 5.5)}, {{0, 1, 2}});  // repeated vertex
  const auto c = countCoverage(scene, pixelCamera(), 4);
  for (size_t i = 0; i < c.front.size(); ++i) EXPECT_EQ(c.front[i] + c.back[i], 0);
}

// setupTriangle's planes (divisions paired, b/w of weights 0 and 1
// without a division) against their scalar reference, bit for bit: random
// triangles in clip space, perspective (w from 1e-3 to 1e3) and
// orthographic (w = 1), unit weights (an unclipped triangle) and clipped
// pieces' fractional ones with exact 0s and 1s among them, every depth
// format, with and without polygon offset, both facings.
RASTRAY_TEST_LABELS_OF(Setup, PairedPlaneDivisionsMatchTheScalarReferenceBitForBit, "quick");
TEST(Setup, PairedPlaneDivisionsMatchTheScalarReferenceBitForBit) {
  const auto bits = [](const auto& a, const auto& b) { return std::memcmp(&a, &b, sizeof a) == 0; };
  std::mt19937 rng(20261202);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const SampleGrid grid = makeSampleGrid(4, 96, 64);
  Camera camera = orthoCamera(96, 1.0);
  camera.height = 64;
  const ClipSpace space = makeClipSpace(camera, grid.guardPixels);
  size_t compared = 0;
  for (int n = 0; n < 4000; ++n) {
    const bool ortho = n % 4 == 3;
    DepthSettings ds{DepthFormat(n % 4),
                     ortho ? Projection::Orthographic : Projection::Perspective,
                     0.1,
                     100.0,
                     n % 3 == 0 ? 1.5 : 0.0,
                     n % 5 == 0 ? 2.0 : 0.0};
    ClipVertex v[3];
    for (int i = 0; i < 3; ++i) {
      const double w = ortho ? 1.0 : std::pow(10.0, 6.0 * unit(rng) - 3.0);
      v[i].position = {(2.0 * unit(rng) - 1.0) * w, (2.0 * unit(rng) - 1.0) * w, unit(rng) * w, w};
      v[i].bary = glm::dvec3(0.0);
      v[i].bary[i] = 1.0;
    }
    if (n % 2 == 1) {  // a clipped piece's weights: fractional, with exact 0s and 1s among them
      for (int i = 0; i < 3; ++i) {
        const int kind = int(unit(rng) * 3.0);
        if (kind == 0) continue;  // keeps its unit weights
        const double a = kind == 1 ? unit(rng) : 0.0;
        v[i].bary = {1.0 - a, a, 0.0};
        if (unit(rng) < 0.5) std::swap(v[i].bary.y, v[i].bary.z);
      }
    }
    TriangleSetup fast, scalar;
    const SetupOutcome a = setupTriangle(space, grid, ds, v, CullMode::None, &fast);
    const SetupOutcome b = setupTriangleScalarPlanes(space, grid, ds, v, CullMode::None, &scalar);
    ASSERT_EQ(a, b) << n;
    if (a != SetupOutcome::Ok) continue;
    ++compared;
    ASSERT_TRUE(bits(fast.depth, scalar.depth)) << n;
    ASSERT_TRUE(bits(fast.invW, scalar.invW)) << n;
    ASSERT_TRUE(bits(fast.dOverW, scalar.dOverW)) << n;
    ASSERT_TRUE(bits(fast.b1OverW, scalar.b1OverW)) << n;
    ASSERT_TRUE(bits(fast.b2OverW, scalar.b2OverW)) << n;
    for (int e = 0; e < 3; ++e) ASSERT_EQ(fast.edge[e].original, scalar.edge[e].original) << n;
  }
  EXPECT_GT(compared, size_t(3000));
}

// mayCoverSample tests only the samples inside the vertices' box; its
// reference tests every sample of the pixel bounds. Random small
// triangles (up to 3 pixels across, so most are searched) at 1, 4, 16
// and 25 (k = 5: no power-of-two units) samples per pixel, partly off the
// image, both orientations: the same answer every time, and both answers
// occur.
RASTRAY_TEST_LABELS_OF(Setup, BoxedSampleSearchMatchesTheFullSearch, "quick");
TEST(Setup, BoxedSampleSearchMatchesTheFullSearch) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const int spp : {1, 4, 16, 25}) {
    const SampleGrid grid = makeSampleGrid(spp, 40, 30);
    Camera camera = orthoCamera(40, 1.0);
    camera.height = 30;
    const ClipSpace space = makeClipSpace(camera, grid.guardPixels);
    const DepthSettings ds{DepthFormat::FloatReversed, Projection::Orthographic, 0.1, 100.0, 0, 0};
    size_t covers = 0, misses = 0;
    for (int n = 0; n < 6000; ++n) {
      // Image position (pixels) to clip x, y with w = 1.
      const double cx = -2.0 + 44.0 * unit(rng), cy = -2.0 + 34.0 * unit(rng), size = 3.0 * unit(rng);
      ClipVertex v[3];
      for (int i = 0; i < 3; ++i) {
        const double px = cx + size * unit(rng), py = cy + size * unit(rng);
        v[i].position = {2.0 * px / 40.0 - 1.0, 1.0 - 2.0 * py / 30.0, 0.5, 1.0};
        v[i].bary = glm::dvec3(0.0);
        v[i].bary[i] = 1.0;
      }
      TriangleSetup t;
      if (setupTriangle(space, grid, ds, v, CullMode::None, &t) != SetupOutcome::Ok) continue;
      const bool reference = mayCoverSampleReference(t, grid);
      ASSERT_EQ(mayCoverSample(t, grid), reference) << "spp " << spp << " triangle " << n;
      ++(reference ? covers : misses);
    }
    EXPECT_GT(covers, size_t(100)) << spp;
    EXPECT_GT(misses, size_t(100)) << spp;
  }
}

// ClipSpace's clipOf and imageOf (two divisions in one register) against
// their scalar references, bit for bit: perspective and orthographic,
// points near and far, in front and behind.
RASTRAY_TEST_LABELS_OF(Clip, PairedDivisionsMatchTheScalarReferenceBitForBit, "quick");
TEST(Clip, PairedDivisionsMatchTheScalarReferenceBitForBit) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const auto same = [](const auto& a, const auto& b) { return std::memcmp(&a, &b, sizeof a) == 0; };
  for (const bool ortho : {false, true}) {
    Camera camera = ortho ? orthoCamera(97, 1.3)
                          : test::perspectiveCamera(97, 61, 0.7, {0.3, -0.2, 5.0}, {0.0, 0.1, 0.0});
    camera.height = 61;
    const ClipSpace space = makeClipSpace(camera, 100.0);
    for (int n = 0; n < 5000; ++n) {
      const double scale = std::pow(10.0, 4.0 * unit(rng));
      const glm::dvec3 world(unit(rng) * scale, unit(rng) * scale, unit(rng) * scale);
      const glm::dvec4 clip = space.clipOf(world);
      ASSERT_TRUE(same(clip, space.clipOfReference(world))) << n;
      if (!(clip.w > 0.0)) continue;
      ASSERT_TRUE(same(space.imageOf(clip), space.imageOfReference(clip))) << n;
    }
  }
}

RASTRAY_TEST_LABELS_OF(Clip, NearPlaneSplitsKeepParentBarycentricsAndShareVertices, "quick");
TEST(Clip, NearPlaneSplitsKeepParentBarycentricsAndShareVertices) {
  Camera camera = test::perspectiveCamera(32, 32, 1.0, glm::dvec3(0), glm::dvec3(0, 0, -1), 0.5);
  const ClipSpace space = makeClipSpace(camera, 1000.0);
  // Two triangles sharing edge (a, b), which crosses the near plane.
  const glm::dvec3 a(0.2, 0.1, 1.0), b(-0.3, 0.2, -3.0), c(1.0, -0.5, -2.0), d(-1.0, -1.0, -2.0);
  const auto clipOf = [&](glm::dvec3 p0, glm::dvec3 p1, glm::dvec3 p2) {
    const glm::dvec4 v[3] = {space.project(p0, {}).position, space.project(p1, {}).position,
                             space.project(p2, {}).position};
    return clipTriangle(space, v);
  };
  const ClipResult r1 = clipOf(a, b, c), r2 = clipOf(b, a, d);
  ASSERT_EQ(r1.outcome, ClipOutcome::Clipped);
  ASSERT_EQ(r2.outcome, ClipOutcome::Clipped);
  const glm::dvec3 p[3] = {a, b, c};
  for (int i = 0; i < r1.count; ++i) {
    const ClipVertex& v = r1.vertices[i];
    EXPECT_GE(v.position.z, camera.znear - 1e-12);
    EXPECT_NEAR(v.bary.x + v.bary.y + v.bary.z, 1.0, 1e-12);
    // The weights rebuild the clip position from the parent's vertices.
    const glm::dvec3 view = v.bary.x * p[0] + v.bary.y * p[1] + v.bary.z * p[2];
    EXPECT_NEAR(-view.z, v.position.z, 1e-12);
  }
  // The new vertex on the shared edge is bit-identical in both triangles.
  int shared = 0;
  for (int i = 0; i < r1.count; ++i)
    for (int j = 0; j < r2.count; ++j)
      if (r1.vertices[i].position == r2.vertices[j].position && r1.vertices[i].position.z == camera.znear)
        ++shared;
  EXPECT_EQ(shared, 1);
  // Entirely behind the camera: outside.
  EXPECT_EQ(clipOf(glm::dvec3(0, 0, 1), glm::dvec3(1, 0, 1), glm::dvec3(0, 1, 2)).outcome,
            ClipOutcome::Outside);
}

TEST(Setup, BackFaceCullingOnlyForSingleSidedMaterials) {
  Scene scene;
  // CCW seen from the camera (front) and CW (back).
  addMesh(scene, {at(1, 1), at(1, 7), at(7, 1)}, {{0, 1, 2}}, colored(glm::vec4(1)));
  addMesh(scene, {at(1, 1), at(7, 1), at(1, 7)}, {{0, 1, 2}}, colored(glm::vec4(1)));
  addMesh(scene, {at(1, 1), at(7, 1), at(1, 7)}, {{0, 1, 2}}, colored(glm::vec4(1), AlphaMode::Opaque, true));
  const Camera camera = pixelCamera();
  const SampleGrid grid = makeSampleGrid(1, 8, 8);
  const ClipSpace space = makeClipSpace(camera, grid.guardPixels);
  const DepthSettings ds{DepthFormat::FloatReversed, camera.projection, camera.znear, camera.zfar, 0, 0};
  for (CullMode cull : {CullMode::None, CullMode::Back, CullMode::Front}) {
    SetupCounters n;
    const auto setups = prepareTriangles(scene, space, grid, ds, cull, {}, &n);
    std::vector<uint32_t> instances;
    for (const auto& s : setups) instances.push_back(s.instance);
    const std::vector<uint32_t> expected = cull == CullMode::None   ? std::vector<uint32_t>{0, 1, 2}
                                           : cull == CullMode::Back ? std::vector<uint32_t>{0, 2}
                                                                    : std::vector<uint32_t>{1, 2};
    EXPECT_EQ(instances, expected);
    EXPECT_EQ(n.culled, cull == CullMode::None ? 0u : 1u);
  }
}

TEST(Setup, HugeTrianglesFarOutsideTheScreenAreClippedToTheGuardBandAndExact) {
  Scene scene;
  // A plane at z = −2 made of one triangle with vertices ±1e7 units away.
  addMesh(scene,
          {glm::vec3(-1e7f, -1e7f, -2.0f), glm::vec3(1e7f, -1e7f, -2.0f), glm::vec3(0.0f, 1e7f, -2.0f)},
          {{0, 1, 2}});
  // Another, edge-on through the image, shared edge with a twin: no cracks.
  addMesh(scene,
          {glm::vec3(-3e6f, -3e6f, -3.0f), glm::vec3(3e6f, 3e6f, -3.0f), glm::vec3(-3e6f, 3e6f, -3.0f)},
          {{0, 1, 2}});
  addMesh(scene,
          {glm::vec3(-3e6f, -3e6f, -3.0f), glm::vec3(3e6f, -3e6f, -3.0f), glm::vec3(3e6f, 3e6f, -3.0f)},
          {{0, 1, 2}});
  const Camera camera = test::perspectiveCamera(48, 48, 1.0, glm::dvec3(0), glm::dvec3(0, 0, -1), 0.1);
  const auto c = countCoverage(scene, camera, 4);
  for (size_t i = 0; i < c.front.size(); ++i) {
    ASSERT_EQ(c.front[i], 2) << i;  // the big plane + exactly one of the twins
    ASSERT_EQ(c.back[i], 0) << i;
  }
  RasterOptions o;
  o.spp = 4;
  o.keepSamples = true;
  const RenderOutput out = test::render(scene, camera, o);
  EXPECT_GT(out.counters.get("raster.guard_band_clipped"), 0u);
  for (size_t p = 0; p < out.image.depth.size(); ++p) {
    EXPECT_EQ(out.image.instance[p], 0u);
    EXPECT_NEAR(out.image.depth[p], 2.0f, 2e-6f);
  }
}

}  // namespace
}  // namespace rastray
