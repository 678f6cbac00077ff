// The fast setup path (per-vertex clip codes and snapped positions, integer
// tests before any plane) against the per-triangle reference, and the
// setups dropped because they cover no sample: the same setups for every
// triangle that can cover a sample, the same bins, depth keys, winners and
// hits as when every setup is kept.
#include <gtest/gtest.h>
#include <hwy/targets.h>
#include <tbb/global_control.h>

#include <cstring>
#include <random>

#include "common/surface.h"
#include "common/triangle_plane.h"
#include "raster/bin.h"
#include "raster/clip.h"
#include "raster/coverage.h"
#include "raster/setup.h"
#include "raster_test_util.h"

namespace rastray {
namespace {

// Every stored field of two setups (padding aside).
void expectSameSetup(const TriangleSetup& a, const TriangleSetup& b, size_t i) {
  ASSERT_EQ(a.id(), b.id()) << i;
  for (int k = 0; k < 3; ++k) {
    ASSERT_EQ(a.vertex[k], b.vertex[k]) << i;
    ASSERT_EQ(a.edge[k].a, b.edge[k].a) << i;
    ASSERT_EQ(a.edge[k].b, b.edge[k].b) << i;
    ASSERT_EQ(a.edge[k].c, b.edge[k].c) << i;
    ASSERT_EQ(a.edge[k].bias, b.edge[k].bias) << i;
    ASSERT_EQ(a.edge[k].topLeft, b.edge[k].topLeft) << i;
    ASSERT_EQ(a.edge[k].original, b.edge[k].original) << i;
  }
  ASSERT_EQ(a.pixelMin, b.pixelMin) << i;
  ASSERT_EQ(a.pixelMax, b.pixelMax) << i;
  const auto planeEq = [](const PlaneCoefficients& p, const PlaneCoefficients& q) {
    return p.v0 == q.v0 && p.dx == q.dx && p.dy == q.dy;
  };
  ASSERT_TRUE(a.depth.v0 == b.depth.v0 && a.depth.dx == b.depth.dx && a.depth.dy == b.depth.dy &&
              a.depth.x0 == b.depth.x0 && a.depth.y0 == b.depth.y0)
      << i;
  ASSERT_TRUE(planeEq(a.invW, b.invW) && planeEq(a.dOverW, b.dOverW) && planeEq(a.b1OverW, b.b1OverW) &&
              planeEq(a.b2OverW, b.b2OverW))
      << i;
  ASSERT_EQ(a.centroidDepth, b.centroidDepth) << i;
  ASSERT_EQ(a.frontFacing, b.frontFacing) << i;
  ASSERT_EQ(a.fromClipping, b.fromClipping) << i;
  ASSERT_EQ(a.corners, b.corners) << i;
  ASSERT_EQ(std::memcmp(&a.faceNormal, &b.faceNormal, sizeof(glm::dvec3)), 0) << i;
}

void expectSameCounters(const SetupCounters& a, const SetupCounters& b, const std::string& what) {
  EXPECT_EQ(a.trianglesIn, b.trianglesIn) << what;
  EXPECT_EQ(a.degenerate, b.degenerate) << what;
  EXPECT_EQ(a.culled, b.culled) << what;
  EXPECT_EQ(a.outside, b.outside) << what;
  EXPECT_EQ(a.clipped, b.clipped) << what;
  EXPECT_EQ(a.fromClipping, b.fromClipping) << what;
  EXPECT_EQ(a.guardBandClipped, b.guardBandClipped) << what;
  EXPECT_EQ(a.noSample, b.noSample) << what;
}

// A height field of n × n shared vertices (the bench terrain's kind of
// mesh) in one single-sided instance, seen from a low camera: most of its
// triangles are sub-pixel far away, the near ones cross the near plane and
// the image's sides, and some face away. Then a double-sided BLEND
// instance, and one of world-degenerate (repeated vertex, collinear) and
// snap-degenerate triangles.
Scene terrainScene(int n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> height(-0.15f, 0.15f);
  std::vector<glm::vec3> p;
  std::vector<glm::uvec3> t;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      p.push_back(glm::vec3(-4.0f + 8.0f * float(i) / float(n - 1), height(rng),
                            1.0f - 12.0f * float(j) / float(n - 1)));
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      const uint32_t a = uint32_t(j * n + i), b = a + 1, c = a + uint32_t(n), d = c + 1;
      t.push_back({a, b, d});
      t.push_back({a, d, c});
    }
  Scene scene;
  test::addMesh(scene, p, t, test::colored(glm::vec4(1.0f)));
  // Translucent sheets, some standing up in front of the camera.
  std::vector<glm::vec3> q;
  std::vector<glm::uvec3> u;
  std::uniform_real_distribution<float> x(-3.0f, 3.0f), z(-8.0f, 0.5f), e(-0.3f, 0.3f);
  for (int k = 0; k < 300; ++k) {
    const glm::vec3 c(x(rng), 0.3f + 0.1f * x(rng), z(rng));
    for (int v = 0; v < 3; ++v) q.push_back(c + glm::vec3(e(rng), e(rng), e(rng)));
    u.push_back(glm::uvec3(3 * k, 3 * k + 1, 3 * k + 2));
  }
  test::addMesh(scene, q, u, test::colored(glm::vec4(1.0f, 1.0f, 1.0f, 0.5f), AlphaMode::Blend, true));
  test::addMesh(scene,
                {glm::vec3(0.1f, 0.5f, -2.0f), glm::vec3(0.1f, 0.5f, -2.0f), glm::vec3(0.4f, 0.9f, -2.0f),
                 glm::vec3(0.2f, 0.2f, -3.0f), glm::vec3(0.4f, 0.4f, -3.0f), glm::vec3(0.8f, 0.8f, -3.0f),
                 glm::vec3(0.3f, 0.3f, -9.0f), glm::vec3(0.3f + 1e-6f, 0.3f, -9.0f),
                 glm::vec3(0.3f, 0.3f + 1e-6f, -9.0f)},
                {{0, 1, 2}, {3, 4, 5}, {6, 7, 8}});
  return scene;
}

struct Frame {
  Camera camera;
  SampleGrid grid;
  ClipSpace space;
  DepthSettings depth;
};

Frame frameOf(int w, int h, int spp) {
  Frame f{test::perspectiveCamera(w, h, 1.0, glm::dvec3(0.3, 0.6, 0.4), glm::dvec3(0.0, -0.4, -6.0), 0.05),
          makeSampleGrid(spp, w, h),
          {},
          {}};
  f.space = makeClipSpace(f.camera, f.grid.guardPixels);
  f.depth = {DepthFormat::FloatReversed, f.camera.projection, f.camera.znear, f.camera.zfar, 0.0, 0.0};
  return f;
}

std::vector<TriangleSetup> setUp(const Scene& scene, const Frame& f, CullMode cull,
                                 const TriangleFilter& filter, SetupPath path, SetupCounters* n) {
  return prepareTriangles(scene, f.space, f.grid, f.depth, cull, filter, n, path);
}

TEST(SetupPaths, FastPathGivesTheReferenceSetupsAndCounters) {
  const Scene scene = terrainScene(160, 1);
  std::vector<uint8_t> candidates(scene.triangleCount());
  for (size_t i = 0; i < candidates.size(); ++i) candidates[i] = uint8_t(1u << (i % 3));
  SetupCounters total;
  for (int spp : {1, 4, 25}) {
    const Frame f = frameOf(160, 90, spp);
    for (CullMode cull : {CullMode::None, CullMode::Back})
      for (bool keep : {false, true})
        for (int which = 0; which < 4; ++which) {
          TriangleFilter filter;
          filter.keepSampleless = keep;
          if (which == 1) filter.blend = false;
          if (which == 2) filter.opaque = false;
          if (which == 3) {
            filter.candidates = &candidates;
            filter.candidateBit = 2;
          }
          const std::string what = std::to_string(spp) + " spp, cull " + std::to_string(int(cull)) +
                                   (keep ? ", keeping sampleless" : "") + ", filter " + std::to_string(which);
          SetupCounters nf, nr;
          const auto fast = setUp(scene, f, cull, filter, SetupPath::Fast, &nf);
          const auto reference = setUp(scene, f, cull, filter, SetupPath::Reference, &nr);
          ASSERT_EQ(fast.size(), reference.size()) << what;
          for (size_t i = 0; i < fast.size(); ++i) expectSameSetup(fast[i], reference[i], i);
          expectSameCounters(nf, nr, what);
          total.degenerate += nf.degenerate;
          total.culled += nf.culled;
          total.clipped += nf.clipped;
          total.guardBandClipped += nf.guardBandClipped;
          total.outside += nf.outside;
          total.noSample += nf.noSample;
        }
  }
  // The scene reaches every branch of both paths.
  EXPECT_GT(total.degenerate, 0u);
  EXPECT_GT(total.culled, 0u);
  EXPECT_GT(total.clipped, 0u);
  EXPECT_GT(total.outside, 0u);
  EXPECT_GT(total.noSample, 0u);
}

TEST(SetupPaths, FastPathIsTheSameAtAnyThreadCount) {
  const Scene scene = terrainScene(200, 2);
  const Frame f = frameOf(200, 120, 4);
  SetupCounters n1;
  std::vector<TriangleSetup> one;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = setUp(scene, f, CullMode::Back, {}, SetupPath::Fast, &n1);
  }
  for (size_t threads : {2, 3}) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    SetupCounters n;
    const auto many = setUp(scene, f, CullMode::Back, {}, SetupPath::Fast, &n);
    ASSERT_EQ(many.size(), one.size()) << threads;
    for (size_t i = 0; i < one.size(); ++i) expectSameSetup(many[i], one[i], i);
    expectSameCounters(n, n1, std::to_string(threads) + " threads");
  }
}

// Whether some sample of the image passes t's three edge tests, by brute
// force over every pixel of the image.
bool coversSomeSample(const TriangleSetup& t, const SampleGrid& grid, int width, int height) {
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (const glm::i64vec2& o : grid.offsets) {
        const int64_t px = int64_t(x) * grid.unitsPerPixel + o.x, py = int64_t(y) * grid.unitsPerPixel + o.y;
        bool inside = true;
        for (const EdgeFunction& e : t.edge) inside = inside && e.at(px, py) + e.bias >= 0;
        if (inside) return true;
      }
  return false;
}

// Bit for bit, signed zeros and NaNs included.
bool samePlane(const RefinePlane& a, const RefinePlane& b) {
  const auto same = [](const glm::dvec3& p, const glm::dvec3& q) {
    return std::memcmp(&p, &q, sizeof p) == 0;
  };
  return same(a.e1, b.e1) && same(a.e2, b.e2) && same(a.s, b.s) && same(a.q, b.q) &&
         std::memcmp(&a.e2DotQ, &b.e2DotQ, sizeof a.e2DotQ) == 0 && a.slot1 == b.slot1 && a.slot2 == b.slot2;
}

// The lanes against the reference on triangles whose corners tie in x, in
// x and y, or entirely (the sorting network's every branch), with signed
// zeros, far from the origin and tiny, in every corner order; blocks of 1
// to 200, on every target.
TEST(SetupPaths, RefinePlanesInLanesGiveTheReferenceBitsOnEveryTarget) {
  std::mt19937 rng(7);
  const float few[] = {-0.0f, 0.0f, 1.0f, -1.0f, 0.5f, 3.0f};
  std::uniform_int_distribution<int> pick(0, 5), kind(0, 3);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  std::vector<glm::vec3> p;
  std::vector<glm::uvec3> t;
  for (int k = 0; k < 600; ++k) {
    const float scale = k % 7 == 0 ? 1e6f : k % 11 == 0 ? 1e-4f : 2.0f;
    for (int v = 0; v < 3; ++v) {
      glm::vec3 c;
      switch (kind(rng)) {
        case 0:  // coordinates from a few values: ties in x, y or all
          c = {few[pick(rng)], few[pick(rng)], few[pick(rng)]};
          break;
        case 1:  // x shared with the previous corner
          c = {v > 0 ? p.back().x : few[pick(rng)], unit(rng) * scale, unit(rng) * scale};
          break;
        default:
          c = {unit(rng) * scale, unit(rng) * scale, unit(rng) * scale};
      }
      p.push_back(c);
    }
    t.push_back(glm::uvec3(3 * k, 3 * k + 1, 3 * k + 2));
  }
  // Every corner order of a few triangles, and a repeated corner.
  for (int k = 0; k < 4; ++k)
    for (const glm::uvec3 o :
         {glm::uvec3(0, 1, 2), glm::uvec3(0, 2, 1), glm::uvec3(1, 0, 2), glm::uvec3(1, 2, 0),
          glm::uvec3(2, 0, 1), glm::uvec3(2, 1, 0), glm::uvec3(0, 0, 1), glm::uvec3(1, 1, 1)})
      t.push_back(glm::uvec3(3 * k) + o);
  Scene scene;
  test::addMesh(scene,
                {glm::vec3(2.0f, -1.0f, 0.5f), glm::vec3(-1.0f, 0.0f, 3.0f), glm::vec3(0.0f, 4.0f, -2.0f)},
                {{0, 1, 2}});
  test::addMesh(scene, p, t);
  const uint32_t instance = 1;
  std::vector<uint32_t> triangles(t.size());
  for (uint32_t i = 0; i < triangles.size(); ++i) triangles[i] = i;
  std::shuffle(triangles.begin(), triangles.end(), rng);
  // Setups of those triangles (only their ids are read), and of instance
  // 0's: blocks that span instances.
  std::vector<TriangleSetup> setups(triangles.size());
  for (size_t i = 0; i < triangles.size(); ++i) {
    setups[i].instance = i % 13 == 0 ? 0 : instance;
    setups[i].triangle = i % 13 == 0 ? 0 : triangles[i];
  }
  for (const glm::dvec3 eye :
       {glm::dvec3(0.3, 0.6, 0.4), glm::dvec3(-0.0, 0.0, -0.0), glm::dvec3(1e7, -3e6, 2.5)}) {
    std::vector<RefinePlane> expected(triangles.size());
    for (size_t i = 0; i < triangles.size(); ++i)
      expected[i] = refinePlaneReference(scene, setups[i].instance, setups[i].triangle, eye);
    for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
      SCOPED_TRACE(hwy::TargetName(target));
      hwy::SetSupportedTargetsForTest(target);
      for (size_t batch : {size_t(1), size_t(5), size_t(64), size_t(200)}) {
        std::vector<RefinePlane> out(triangles.size());
        for (size_t first = 0; first < triangles.size(); first += batch)
          refinePlanes(scene, &setups[first], std::min(batch, setups.size() - first), eye, &out[first]);
        for (size_t i = 0; i < triangles.size(); ++i)
          ASSERT_TRUE(samePlane(out[i], expected[i])) << batch << " " << i << " triangle " << triangles[i];
      }
    }
    hwy::SetSupportedTargetsForTest(0);
  }
}

// The face normals in lanes against faceNormalOfCorners on random,
// huge, tiny, zero-area (a repeated corner, collinear corners) and
// signed-zero triangles in every corner order; blocks of 1 to 200, on
// every target.
TEST(SetupPaths, FaceNormalsInLanesGiveTheReferenceBitsOnEveryTarget) {
  std::mt19937 rng(11);
  const float few[] = {-0.0f, 0.0f, 1.0f, -1.0f, 0.5f, 3.0f};
  std::uniform_int_distribution<int> pick(0, 5);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  std::vector<glm::vec3> p;
  for (int k = 0; k < 600; ++k) {
    const float scale = k % 7 == 0 ? 1e18f : k % 11 == 0 ? 1e-19f : 2.0f;
    for (int v = 0; v < 3; ++v)
      p.push_back(k % 5 == 0 ? glm::vec3(few[pick(rng)], few[pick(rng)], few[pick(rng)])
                             : glm::vec3(unit(rng), unit(rng), unit(rng)) * scale);
  }
  p.push_back({0.0f, 0.0f, 0.0f}), p.push_back({1.0f, 2.0f, 3.0f}),
      p.push_back({2.0f, 4.0f, 6.0f});  // collinear
  std::vector<glm::uvec3> corners;
  for (uint32_t k = 0; k < 601; ++k)
    for (const glm::uvec3 o :
         {glm::uvec3(0, 1, 2), glm::uvec3(2, 1, 0), glm::uvec3(1, 2, 0), glm::uvec3(0, 0, 1)})
      corners.push_back(glm::uvec3(3 * k) + o);
  Scene scene;
  test::addMesh(scene, p, {{0, 1, 2}});
  std::shuffle(corners.begin(), corners.end(), rng);
  std::vector<glm::dvec3> expected(corners.size());
  for (size_t i = 0; i < corners.size(); ++i)
    expected[i] = faceNormalOfCorners(glm::dvec3(p[corners[i].x]), glm::dvec3(p[corners[i].y]),
                                      glm::dvec3(p[corners[i].z]));
  for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
    SCOPED_TRACE(hwy::TargetName(target));
    hwy::SetSupportedTargetsForTest(target);
    for (size_t batch : {size_t(1), size_t(5), size_t(64), size_t(200)}) {
      std::vector<TriangleSetup> setups(corners.size());
      for (size_t i = 0; i < corners.size(); ++i) setups[i].corners = corners[i];
      for (size_t first = 0; first < setups.size(); first += batch)
        faceNormals(scene, &setups[first], std::min(batch, setups.size() - first));
      for (size_t i = 0; i < setups.size(); ++i)
        ASSERT_EQ(std::memcmp(&setups[i].faceNormal, &expected[i], sizeof expected[i]), 0)
            << batch << " " << i << " z " << setups[i].faceNormal.z << " expected " << expected[i].z;
    }
  }
  hwy::SetSupportedTargetsForTest(0);
}

// prepareTriangles' planes: one per setup (clipped pieces included), each
// the reference's for its triangle and the eye, on both setup paths; the
// setups themselves as without them.
TEST(SetupPaths, StoredRefinePlanesAreEachSetupsReferencePlane) {
  Scene scene = terrainScene(160, 1);
  // Triangles through the near plane, beside the eye: clipped into pieces.
  test::addMesh(scene,
                {glm::vec3(0.3f, 0.5f, 1.0f), glm::vec3(0.0f, 0.3f, -2.0f), glm::vec3(0.6f, 0.3f, -2.0f),
                 glm::vec3(0.1f, 0.7f, 0.5f), glm::vec3(0.5f, 0.7f, 0.3f), glm::vec3(0.3f, 0.2f, -1.0f)},
                {{0, 1, 2}, {3, 4, 5}});
  const Frame f = frameOf(160, 90, 4);
  for (const SetupPath path : {SetupPath::Fast, SetupPath::Reference}) {
    SetupCounters n0, n1;
    const std::vector<TriangleSetup> plain = setUp(scene, f, CullMode::None, {}, path, &n0);
    std::vector<TriangleSetup> setups;
    RefinePlanes planes(3);  // stale contents are replaced
    prepareTriangles(scene, f.space, f.grid, f.depth, CullMode::None, {}, &n1, path, &setups,
                     {f.camera.eye(), &planes});
    expectSameCounters(n0, n1, "with planes");
    ASSERT_EQ(setups.size(), plain.size());
    ASSERT_EQ(planes.size(), setups.size());
    size_t clipped = 0;
    for (size_t i = 0; i < setups.size(); ++i) {
      expectSameSetup(setups[i], plain[i], i);
      clipped += setups[i].fromClipping;
      ASSERT_TRUE(samePlane(
          planes[i], refinePlaneReference(scene, setups[i].instance, setups[i].triangle, f.camera.eye())))
          << i;
    }
    EXPECT_GT(clipped, 0u);
  }
}

// Each setup carries its stored triangle's corner indices and face normal
// for the shading kernel (PrimaryHitBlock::runCorners): scene.triangle's
// indices and triangleFaceNormal's bits, clipped pieces included (their
// parent's), on both setup paths (expectSameSetup compares the paths).
TEST(SetupPaths, SetupsCarryTheStoredTrianglesCornersAndFaceNormal) {
  Scene scene = terrainScene(160, 3);
  // Triangles through the near plane, beside the eye: clipped into pieces;
  // a far, tilted one at a large scale.
  test::addMesh(
      scene,
      {glm::vec3(0.3f, 0.5f, 1.0f), glm::vec3(0.0f, 0.3f, -2.0f), glm::vec3(0.6f, 0.3f, -2.0f),
       glm::vec3(0.1f, 0.7f, 0.5f), glm::vec3(0.5f, 0.7f, 0.3f), glm::vec3(0.3f, 0.2f, -1.0f),
       glm::vec3(-3e3f, 1.5e3f, -9e3f), glm::vec3(3e3f, 1.7e3f, -9.5e3f), glm::vec3(1e2f, -2e3f, -8e3f)},
      {{0, 1, 2}, {3, 4, 5}, {6, 7, 8}});
  const Frame f = frameOf(160, 90, 1);
  for (const SetupPath path : {SetupPath::Fast, SetupPath::Reference}) {
    SetupCounters n;
    const std::vector<TriangleSetup> setups = setUp(scene, f, CullMode::None, {}, path, &n);
    ASSERT_GT(setups.size(), 1000u);
    size_t clipped = 0;
    for (size_t i = 0; i < setups.size(); ++i) {
      const TriangleSetup& t = setups[i];
      clipped += t.fromClipping;
      ASSERT_EQ(t.corners, scene.triangle(t.instance, t.triangle)) << i;
      const glm::dvec3 expected = triangleFaceNormal(scene, t.instance, t.triangle);
      ASSERT_EQ(std::memcmp(&t.faceNormal, &expected, sizeof(glm::dvec3)), 0) << i;
    }
    EXPECT_GT(clipped, 0u);
  }
  // setupTriangle alone computes neither: the kernel then takes its own.
  EXPECT_EQ(TriangleSetup{}.corners.x, kNoId);
}

TEST(SamplelessSetups, OnlySetupsThatCoverNoSampleAreDropped) {
  const Scene scene = terrainScene(160, 1);
  for (int spp : {1, 4, 16}) {
    const Frame f = frameOf(96, 54, spp);
    TriangleFilter keepAll;
    keepAll.keepSampleless = true;
    SetupCounters na, nk;
    const auto all = setUp(scene, f, CullMode::Back, keepAll, SetupPath::Fast, &na);
    const auto kept = setUp(scene, f, CullMode::Back, {}, SetupPath::Fast, &nk);
    size_t next = 0, dropped = 0, small = 0;
    for (size_t i = 0; i < all.size(); ++i) {
      const bool covers = coversSomeSample(all[i], f.grid, 96, 54);
      const int64_t w = all[i].pixelMax.x - all[i].pixelMin.x + 1,
                    h = all[i].pixelMax.y - all[i].pixelMin.y + 1;
      small += w * h * spp <= kSampleSearchLimit;
      // Exact within the search limit, never dropping one that covers a sample.
      EXPECT_EQ(mayCoverSample(all[i], f.grid), covers || w * h * spp > kSampleSearchLimit) << i;
      if (!mayCoverSample(all[i], f.grid)) {
        ++dropped;
        continue;
      }
      ASSERT_LT(next, kept.size());
      expectSameSetup(kept[next++], all[i], i);
    }
    EXPECT_EQ(next, kept.size());
    // Far triangles fall between samples: many at 1 spp, fewer with more samples.
    EXPECT_GT(dropped, all.size() / (spp == 1 ? 4 : 20)) << spp << " spp";
    EXPECT_GT(small, dropped);
    // Each triangle not clipped is one setup: dropped setups are counted
    // per triangle, and nothing else changes.
    EXPECT_GE(dropped, nk.noSample);
    EXPECT_GT(nk.noSample, 0u);
    EXPECT_EQ(na.noSample, 0u);
    EXPECT_EQ(nk.trianglesIn, na.trianglesIn);
    EXPECT_EQ(nk.outside, na.outside);
    EXPECT_EQ(nk.degenerate, na.degenerate);
    EXPECT_EQ(nk.culled, na.culled);
    EXPECT_EQ(nk.clipped, na.clipped);
  }
}

// Triangle ids of a bin's setups.
std::vector<uint64_t> idsOf(const std::vector<uint32_t>& bin, const std::vector<TriangleSetup>& setups) {
  std::vector<uint64_t> ids;
  for (uint32_t i : bin) ids.push_back(setups[i].id());
  return ids;
}

TEST(SamplelessSetups, DroppingThemChangesNoBinKeyOrWinner) {
  const Scene scene = terrainScene(140, 4);
  for (int spp : {1, 4}) {
    const int W = 150, H = 100;
    const Frame f = frameOf(W, H, spp);
    TriangleFilter keepAll;
    keepAll.keepSampleless = true;
    keepAll.blend = false;
    TriangleFilter dropping = keepAll;
    dropping.keepSampleless = false;
    SetupCounters na, nk;
    const auto all = setUp(scene, f, CullMode::Back, keepAll, SetupPath::Fast, &na);
    const auto kept = setUp(scene, f, CullMode::Back, dropping, SetupPath::Fast, &nk);
    ASSERT_LT(kept.size(), all.size());
    const TileGrid tiles(W, H);
    const auto every = [](const TriangleSetup&) { return true; };
    const auto binsAll = binTriangles(tiles, f.grid, all, every);
    const auto binsKept = binTriangles(tiles, f.grid, kept, every);
    for (int tile = 0; tile < tiles.count(); ++tile) {
      std::vector<uint32_t> covering;
      for (uint32_t i : binsAll[size_t(tile)])
        if (mayCoverSample(all[i], f.grid)) covering.push_back(i);
      EXPECT_EQ(idsOf(binsKept[size_t(tile)], kept), idsOf(covering, all)) << "tile " << tile;
    }
    for (DepthFunc func : {DepthFunc::Less, DepthFunc::LEqual}) {
      DepthTarget ta(W, H, spp), tk(W, H, spp);
      DepthPassCounters ca, ck;
      for (int tile = 0; tile < tiles.count(); ++tile) {
        rasterDepthPass(all, binsAll[size_t(tile)], f.grid, tiles.rect(tile), f.depth.format, func, {},
                        TraceRequest{}, &ta, &ca, CoveragePath::Fast);
        rasterDepthPass(kept, binsKept[size_t(tile)], f.grid, tiles.rect(tile), f.depth.format, func, {},
                        TraceRequest{}, &tk, &ck, CoveragePath::Fast);
      }
      ASSERT_EQ(tk.keys, ta.keys) << spp << " spp";
      size_t covered = 0;
      for (size_t i = 0; i < ta.winners.size(); ++i) {
        ASSERT_EQ(ta.winners[i] == kNoSetup, tk.winners[i] == kNoSetup) << i;
        if (ta.winners[i] == kNoSetup) continue;
        ++covered;
        ASSERT_EQ(all[ta.winners[i]].id(), kept[tk.winners[i]].id()) << i;
      }
      EXPECT_GT(covered, ta.winners.size() / 2);
      EXPECT_EQ(ck.samplesPassed, ca.samplesPassed);
      EXPECT_LT(ck.coverageTests, ca.coverageTests);
    }
  }
}

// End to end: the wireframe keeps every setup (it draws their edges), so a
// render with it and one without see the same hits and depths.
TEST(SamplelessSetups, TheRenderSeesTheSameHitsAsWithEverySetupKept) {
  const Scene scene = terrainScene(140, 5);
  for (int spp : {1, 4}) {
    const Frame f = frameOf(120, 80, spp);
    RasterOptions o;
    o.spp = spp;
    const SceneAnalysis analysis = analyzeScene(scene);
    std::vector<SampleHit> dropped, keptAll;
    const RenderOutput a = renderRasterWithHits(scene, analysis, f.camera, o, &dropped);
    o.wireframe = true;
    const RenderOutput b = renderRasterWithHits(scene, analysis, f.camera, o, &keptAll);
    EXPECT_GT(a.counters.get("raster.no_sample"), 0u);
    EXPECT_EQ(b.counters.get("raster.no_sample"), 0u);
    EXPECT_LT(a.counters.get("raster.triangles_setup"), b.counters.get("raster.triangles_setup"));
    ASSERT_EQ(dropped.size(), keptAll.size());
    for (size_t i = 0; i < dropped.size(); ++i) {
      ASSERT_EQ(dropped[i].instance, keptAll[i].instance) << i;
      ASSERT_EQ(dropped[i].triangle, keptAll[i].triangle) << i;
      ASSERT_EQ(dropped[i].depth, keptAll[i].depth) << i;
      ASSERT_EQ(dropped[i].b1, keptAll[i].b1) << i;
      ASSERT_EQ(dropped[i].b2, keptAll[i].b2) << i;
    }
    EXPECT_EQ(a.image.depth, b.image.depth);
  }
}

}  // namespace
}  // namespace rastray
