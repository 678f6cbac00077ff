// Setup and binning run in parallel (a pipeline of chunks, per-chunk bin
// counts): their results must be the serial ones, in scene order, at any
// thread count. And the cube-map faces set up only the triangles that can
// reach them.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <random>

#include "raster/bin.h"
#include "raster/clip.h"
#include "raster/coverage.h"
#include "raster/setup.h"
#include "raster/shadow_map.h"
#include "raster_test_util.h"

#include "tests/test_labels.h"

// Every test here renders on 2 or more threads (the ThreadSanitizer stage runs them).
RASTRAY_TEST_LABELS("threads");

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
}

// A few thousand random triangles in several instances (some of them
// crossing the near plane, some off screen, some single-sided), so that the
// setup runs many chunks and clipping adds pieces.
Scene randomScene(uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> xy(-4.0f, 4.0f), z(-6.0f, 0.5f), size(-0.6f, 0.6f);
  Scene scene;
  for (int inst = 0; inst < 5; ++inst) {
    std::vector<glm::vec3> p;
    std::vector<glm::uvec3> t;
    const int n = inst == 2 ? 5000 : 900;  // instance 2 spans three chunks
    for (int i = 0; i < n; ++i) {
      const glm::vec3 c(xy(rng), xy(rng), z(rng));
      for (int k = 0; k < 3; ++k) p.push_back(c + glm::vec3(size(rng), size(rng), 2.0f * size(rng)));
      t.push_back(glm::uvec3(3 * i, 3 * i + 1, 3 * i + 2));
    }
    test::addMesh(scene, p, t, test::colored(glm::vec4(1.0f), AlphaMode::Opaque, inst % 2 == 1));
  }
  return scene;
}

// The serial reference: transform, clip and set up triangle after
// triangle, pieces in fan order, keeping those that may cover a sample.
std::vector<TriangleSetup> serialSetups(const Scene& scene, const ClipSpace& space, const SampleGrid& grid,
                                        const DepthSettings& ds, CullMode cull) {
  std::vector<TriangleSetup> out;
  for (uint32_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& inst = scene.instances[i];
    const CullMode c = scene.materials[inst.material].doubleSided ? CullMode::None : cull;
    for (uint32_t k = 0; k < inst.triangleCount; ++k) {
      if (isDegenerate(scene, inst.firstTriangle + k)) continue;
      const glm::uvec3 idx = scene.triangles[inst.firstTriangle + k];
      glm::dvec4 clip[3];
      for (int v = 0; v < 3; ++v)
        clip[v] = space
                      .project(glm::dvec3(space.viewFromWorld *
                                          glm::dvec4(glm::dvec3(scene.positions[idx[v]]), 1.0)),
                               glm::dvec3(0.0))
                      .position;
      const ClipResult cr = clipTriangle(space, clip);
      for (int f = 1; f + 1 < cr.count; ++f) {
        const ClipVertex fan[3] = {cr.vertices[0], cr.vertices[f], cr.vertices[f + 1]};
        TriangleSetup t;
        t.instance = i;
        t.triangle = k;
        t.fromClipping = cr.outcome == ClipOutcome::Clipped;
        t.centroidDepth = (clip[0].z + clip[1].z + clip[2].z) / 3.0;
        if (setupTriangle(space, grid, ds, fan, c, &t) == SetupOutcome::Ok && mayCoverSample(t, grid))
          out.push_back(t);
      }
    }
  }
  return out;
}

struct Frame {
  Camera camera;
  SampleGrid grid;
  ClipSpace space;
  DepthSettings depth;
};

Frame frameOf(int w, int h, int spp) {
  Frame f{test::perspectiveCamera(w, h, 1.2, glm::dvec3(0), glm::dvec3(0, 0, -1), 0.05),
          makeSampleGrid(spp, w, h),
          {},
          {}};
  f.space = makeClipSpace(f.camera, f.grid.guardPixels);
  f.depth = {DepthFormat::FloatReversed, f.camera.projection, f.camera.znear, f.camera.zfar, 0.0, 0.0};
  return f;
}

TEST(ParallelSetup, MatchesTheSerialOrderAtOneAndTwoThreads) {
  const Scene scene = randomScene(3);
  const Frame f = frameOf(200, 150, 4);
  const std::vector<TriangleSetup> reference = serialSetups(scene, f.space, f.grid, f.depth, CullMode::Back);
  SetupCounters refCounters;
  size_t clippedPieces = 0;
  for (size_t run = 0; run < 6; ++run) {
    const size_t threads = 1 + run / 2;
    const SetupPath path = run % 2 == 0 ? SetupPath::Fast : SetupPath::Reference;
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    SetupCounters n;
    const std::vector<TriangleSetup> setups =
        prepareTriangles(scene, f.space, f.grid, f.depth, CullMode::Back, {}, &n, path);
    ASSERT_EQ(setups.size(), reference.size()) << threads << " threads";
    for (size_t i = 0; i < setups.size(); ++i) expectSameSetup(setups[i], reference[i], i);
    if (run == 0) {
      refCounters = n;
      for (const TriangleSetup& t : setups) clippedPieces += t.fromClipping;
    }
    EXPECT_EQ(n.trianglesIn, refCounters.trianglesIn);
    EXPECT_EQ(n.culled, refCounters.culled);
    EXPECT_EQ(n.outside, refCounters.outside);
    EXPECT_EQ(n.clipped, refCounters.clipped);
    EXPECT_EQ(n.fromClipping, refCounters.fromClipping);
  }
  // The scene exercises what it should: culling, clipping, off-screen triangles.
  EXPECT_GT(refCounters.culled, 0u);
  EXPECT_GT(refCounters.clipped, 0u);
  EXPECT_GT(refCounters.outside, 0u);
  EXPECT_GT(refCounters.fromClipping, 0u);
  EXPECT_GT(clippedPieces, 0u);
}

// Serial bins by bounding box, the old binning, for reference.
std::vector<std::vector<uint32_t>> boundingBoxBins(const TileGrid& grid,
                                                   const std::vector<TriangleSetup>& setups) {
  std::vector<std::vector<uint32_t>> bins(size_t(grid.count()));
  for (size_t i = 0; i < setups.size(); ++i) {
    const TriangleSetup& t = setups[i];
    for (int ty = t.pixelMin.y / kTileSize; ty <= t.pixelMax.y / kTileSize; ++ty)
      for (int tx = t.pixelMin.x / kTileSize; tx <= t.pixelMax.x / kTileSize; ++tx)
        bins[size_t(ty * grid.tilesX + tx)].push_back(uint32_t(i));
  }
  return bins;
}

TEST(ParallelBinning, SameBinsAtAnyThreadCountAndNoCoveredTileLeftOut) {
  const Scene scene = randomScene(4);
  for (int spp : {1, 4, 25}) {
    const Frame f = frameOf(300, 200, spp);
    SetupCounters n;
    const std::vector<TriangleSetup> setups =
        prepareTriangles(scene, f.space, f.grid, f.depth, CullMode::None, {}, &n);
    const TileGrid tiles(300, 200);
    const auto all = [](const TriangleSetup&) { return true; };
    std::vector<std::vector<uint32_t>> one;
    {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
      one = binTriangles(tiles, f.grid, setups, all);
    }
    {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
      EXPECT_EQ(binTriangles(tiles, f.grid, setups, all), one);
    }
    const auto boxes = boundingBoxBins(tiles, setups);
    size_t binned = 0, boxed = 0;
    CoverageScratch scratch;
    for (int tile = 0; tile < tiles.count(); ++tile) {
      const std::vector<uint32_t>& bin = one[size_t(tile)];
      binned += bin.size();
      boxed += boxes[size_t(tile)].size();
      // Increasing, a subset of the bounding-box bin, and every triangle
      // that covers a sample of the tile is in it.
      EXPECT_TRUE(std::is_sorted(bin.begin(), bin.end()));
      EXPECT_TRUE(
          std::includes(boxes[size_t(tile)].begin(), boxes[size_t(tile)].end(), bin.begin(), bin.end()));
      for (uint32_t i : boxes[size_t(tile)]) {
        bool covers = false;
        forEachCoveredSample(setups[i], f.grid, tiles.rect(tile), scratch,
                             [&](int, int, int) { covers = true; });
        if (covers) {
          EXPECT_TRUE(std::binary_search(bin.begin(), bin.end(), i)) << "tile " << tile << " setup " << i;
        }
      }
    }
    // The edge test drops tiles that only the bounding box reaches.
    EXPECT_LT(binned, boxed) << spp << " spp";
  }
}

// The chosen setups only, each in the tiles forEachBinnedTile gives it
// (the filling pass takes a several-tile setup's tiles from the counting
// pass's list, not from the setup).
TEST(ParallelBinning, SelectKeepsOnlyTheChosenSetupsInTheirTiles) {
  const Scene scene = randomScene(5);
  const Frame f = frameOf(128, 128, 1);
  SetupCounters n;
  const auto setups = prepareTriangles(scene, f.space, f.grid, f.depth, CullMode::None, {}, &n);
  const TileGrid tiles(128, 128);
  const auto isOdd = [](const TriangleSetup& t) { return t.triangle % 2 == 1; };
  const auto odd = binTriangles(tiles, f.grid, setups, isOdd);
  size_t count = 0;
  for (const auto& bin : odd)
    for (uint32_t i : bin) {
      EXPECT_EQ(setups[i].triangle % 2, 1u);
      ++count;
    }
  EXPECT_GT(count, 0u);
  std::vector<std::vector<uint32_t>> reference(size_t(tiles.count()));
  size_t severalTiles = 0;
  for (size_t i = 0; i < setups.size(); ++i) {
    if (!isOdd(setups[i])) continue;
    int tilesOf = 0;
    forEachBinnedTile(tiles, f.grid.unitsPerPixel, SampleBox(f.grid), setups[i], [&](int tile) {
      reference[size_t(tile)].push_back(uint32_t(i));
      ++tilesOf;
    });
    severalTiles += tilesOf > 1 ? 1 : 0;
  }
  EXPECT_GT(severalTiles, 5u);
  EXPECT_EQ(odd, reference);
}

// A cube face's candidate bit may be clear only for triangles that set up
// to nothing in that face: checked face by face against a full setup.
TEST(CubeFaceCandidates, EveryTriangleAFaceSetsUpIsACandidateOfIt) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> coord(-3.0f, 3.0f), extent(-0.4f, 0.4f);
  Scene scene;
  std::vector<glm::vec3> p;
  std::vector<glm::uvec3> t;
  for (int i = 0; i < 4000; ++i) {
    const glm::vec3 c(coord(rng), coord(rng), coord(rng));
    for (int k = 0; k < 3; ++k) p.push_back(c + glm::vec3(extent(rng), extent(rng), extent(rng)));
    t.push_back(glm::uvec3(3 * i, 3 * i + 1, 3 * i + 2));
  }
  test::addMesh(scene, p, t, test::colored(glm::vec4(1.0f), AlphaMode::Opaque, true));
  const glm::dvec3 light(0.1, -0.2, 0.05);
  for (int size : {8, 64}) {
    const std::vector<Camera> faces = cubeFaceCameras(light, size, 1e-4);
    const SampleGrid grid = makeSampleGrid(1, size, size);
    const ClipSpace first = makeClipSpace(faces[0], grid.guardPixels);
    const std::vector<uint8_t> mask = cubeFaceCandidates(scene, light, first.scale.x, size);
    size_t skipped = 0;
    for (size_t f = 0; f < faces.size(); ++f) {
      const ClipSpace space = makeClipSpace(faces[f], grid.guardPixels);
      const DepthSettings ds{
          DepthFormat::FloatReversed, faces[f].projection, faces[f].znear, faces[f].zfar, 0, 0};
      SetupCounters n;
      for (const TriangleSetup& s : prepareTriangles(scene, space, grid, ds, CullMode::None, {}, &n))
        ASSERT_TRUE(mask[s.triangle] & (1u << f)) << "face " << f << " triangle " << s.triangle;
      for (uint8_t m : mask) skipped += !(m & (1u << f));
    }
    // Most triangles reach one or two faces, so most (triangle, face) pairs are skipped.
    EXPECT_GT(skipped, 3 * mask.size()) << size;
  }
}

}  // namespace
}  // namespace rastray
