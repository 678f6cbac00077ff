// primaryShadeHits (raster/primary_samples.h): the interpolated hits,
// primary ray directions and refined hits computed in double SIMD lanes
// have the scalar reference's bits (interpolatedHit, PrimaryRays,
// refinePrimaryHit) for every sample, on every compiled
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

// Random triangles around `centre` (some degenerate, some slivers), each
// with its own corners, one instance: stored planes the primary rays meet
// ahead, behind and nearly edge-on.
Scene trianglesAround(std::mt19937& rng, const glm::dvec3& centre, double size) {
  Scene s;
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const auto near = [&] { return glm::vec3(centre + size * glm::dvec3(unit(rng), unit(rng), unit(rng))); };
  for (uint32_t i = 0; i < 40; ++i) {
    const glm::vec3 p0 = near(), p1 = near();
    const glm::vec3 p2 = i % 7 == 0 ? p0 : i % 5 == 0 ? p1 + 1e-6f * (near() - p1) : near();
    const uint32_t first = uint32_t(s.positions.size());
    for (const glm::vec3& p : {p0, p1, p2}) {
      s.positions.push_back(p);
      s.normals.push_back(glm::vec3(0.0f));
      s.texcoords.push_back(glm::vec2(0.0f));
    }
    s.triangles.push_back({first, first + 1, first + 2});
  }
  Instance inst;
  inst.vertexCount = uint32_t(s.positions.size());
  inst.triangleCount = uint32_t(s.triangles.size());
  s.instances.push_back(inst);
  s.materials.push_back(Material{});
  return s;
}

bool sameBits(const ShadeHit& a, const ShadeHit& b) {
  return a.instance == b.instance && a.triangle == b.triangle && std::memcmp(&a.b1, &b.b1, 4) == 0 &&
         std::memcmp(&a.b2, &b.b2, 4) == 0 &&
         std::memcmp(&a.direction, &b.direction, sizeof a.direction) == 0 &&
         a.footprintPosition == b.footprintPosition && a.throughput == b.throughput;
}

// The fused pass's interpolated hits and primary ray directions against the
// scalar reference, on planes of every magnitude the renderer produces.
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
    std::vector<TriangleSetup> setups = randomSetups(rng, w, h);
    // The stored triangles the fused pass refines on (its refinement is
    // the next test's subject).
    const Scene scene = trianglesAround(rng, glm::dvec3(0.0), 2.0);
    for (size_t i = 0; i < setups.size(); ++i) {
      setups[i].instance = 0;
      setups[i].triangle = uint32_t(i % scene.triangles.size());
    }
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
        std::vector<ShadeHit> out(n);
        for (size_t first = 0; first < n; first += batch)
          primaryShadeHits(constants, scene, setups.data(), &winners[first], &positions[first],
                           &positions[first], std::min(batch, n - first), &hits[first], &out[first]);
        for (size_t i = 0; i < n; ++i) {
          ASSERT_TRUE(sameBits(hits[i], expectedHits[i])) << "batch " << batch << " sample " << i;
          ASSERT_EQ(0, std::memcmp(&out[i].direction, &expectedRays[i].direction, sizeof(glm::dvec3)))
              << "batch " << batch << " sample " << i;
        }
      }
    }
    hwy::SetSupportedTargetsForTest(0);
  }
}

// Cameras for the fused-pass tests, each with where its random triangles
// lie (centre, extent): an ordinary view, an eye 1e6 from the origin, a
// 2.9 rad field of view with triangles around the eye, orthographic.
struct CameraCase {
  std::string name;
  Camera camera;
  glm::dvec3 centre;
  double size;
};

std::vector<CameraCase> cameraCases() {
  return {{"1920x1080 60deg",
           test::perspectiveCamera(1920, 1080, 1.047, {0.3, 0.2, 4.0}, {0, 0, 0}),
           {0, 0, 0},
           1.5},
          {"97x61 far eye",
           test::perspectiveCamera(97, 61, 0.7, {1e6, -3e5, 2e6}, {1e6 + 1, -3e5, 0}),
           {1e6, -3e5, 1e6},
           3e5},
          {"333x777 wide, triangles around the eye",
           test::perspectiveCamera(333, 777, 2.9, {-2, 1, 1}, {3, 2, -7}),
           {-2, 1, 1},
           2.0},
          {"orthographic", test::orthoCamera(128, 3.0), {0, 0, 0}, 2.0}};
}

// primaryShadeHits, the rasterizer's fused pass (interpolation, primary ray
// and refinement in one pass of lanes per block), against the two steps it
// replaces: primarySamplesReference, then refinePrimaryHit on each ray.
TEST(PrimarySamples, FusedPassGivesTheTwoStepsBitsOnEveryTarget) {
  std::mt19937 rng(9);
  const std::vector<CameraCase> cases = cameraCases();
  for (const CameraCase& c : cases) {
    SCOPED_TRACE(c.name);
    const int w = c.camera.width, h = c.camera.height;
    const Scene scene = trianglesAround(rng, c.centre, c.size);
    std::vector<TriangleSetup> setups = randomSetups(rng, w, h);
    for (size_t i = 0; i < setups.size(); ++i) {
      setups[i].instance = 0;
      setups[i].triangle = uint32_t(i % scene.triangles.size());
    }
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<uint32_t> winners;
    std::vector<glm::dvec2> positions, footprints;
    for (int k = 0; k < 3001; ++k) {
      // Long runs on one setup (whole vectors of lanes on one run: the
      // broadcast path), then runs of 1 and 7 mixed (the gather path).
      winners.push_back(k < 1500 ? uint32_t((k / 23) % setups.size())
                                 : uint32_t((k / (k % 2 ? 1 : 7)) % setups.size()));
      positions.push_back(k % 11 == 0 ? glm::dvec2(k % w, (k / w) % h) + 0.5
                                      : glm::dvec2(u(rng) * w, u(rng) * h));
      footprints.push_back(k % 3 == 0 ? positions.back() : glm::dvec2(k % w, k % h) + 0.5);
    }
    const size_t n = winners.size();
    const PrimaryRayConstants constants(c.camera);
    std::vector<SampleHit> expectedHits(n);
    std::vector<Ray> rays(n);
    primarySamplesReference(constants, setups.data(), winners.data(), positions.data(), n,
                            expectedHits.data(), rays.data());
    std::vector<ShadeHit> expected(n);
    size_t refined = 0;
    for (size_t i = 0; i < n; ++i) {
      expected[i] = refinePrimaryHit(scene, rays[i], expectedHits[i], footprints[i]);
      refined += expected[i].b1 != expectedHits[i].b1 || expected[i].b2 != expectedHits[i].b2;
    }
    // Both outcomes occur: refined on the plane, and kept (degenerate,
    // behind the eye).
    EXPECT_GT(refined, n / 4);
    EXPECT_LT(refined, n);
    for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
      SCOPED_TRACE(hwy::TargetName(target));
      hwy::SetSupportedTargetsForTest(target);
      for (size_t batch : {size_t(1), size_t(5), size_t(64), size_t(100), n}) {
        std::vector<SampleHit> hits(n);
        std::vector<ShadeHit> out(n);
        for (size_t first = 0; first < n; first += batch)
          primaryShadeHits(constants, scene, setups.data(), &winners[first], &positions[first],
                           &footprints[first], std::min(batch, n - first), &hits[first], &out[first]);
        for (size_t i = 0; i < n; ++i) {
          ASSERT_TRUE(sameBits(hits[i], expectedHits[i])) << "batch " << batch << " sample " << i;
          ASSERT_TRUE(sameBits(out[i], expected[i])) << "batch " << batch << " sample " << i;
        }
      }
    }
    hwy::SetSupportedTargetsForTest(0);
  }
}

// PrimaryBatch::addRow, the winner loop's way in (positions from the tile
// row, view-plane vectors from per-tile tables), gives primaryShadeHits'
// bits for the same samples: the interpolated hits, and the refined
// barycentrics, directions and runs it hands the kernel, on every target,
// at 1 and 4 samples per pixel, with empty samples (kNoSetup) skipped,
// rows that fill a block part way, and tiles at odd offsets.
TEST(PrimarySamples, RowsGiveTheSameBitsAsSamplesOnEveryTarget) {
  std::mt19937 rng(31);
  const std::vector<CameraCase> cases = cameraCases();
  const std::vector<glm::dvec2> grid1 = {{0.5, 0.5}};
  const std::vector<glm::dvec2> grid4 = {{0.375, 0.125}, {0.875, 0.375}, {0.125, 0.625}, {0.625, 0.875}};
  for (const CameraCase& c : cases) {
    SCOPED_TRACE(c.name);
    const int w = c.camera.width, h = c.camera.height;
    const Scene scene = trianglesAround(rng, c.centre, c.size);
    std::vector<TriangleSetup> setups = randomSetups(rng, w, h);
    for (size_t i = 0; i < setups.size(); ++i) {
      setups[i].instance = 0;
      setups[i].triangle = uint32_t(i % scene.triangles.size());
    }
    const PrimaryRayConstants constants(c.camera);
    for (const std::vector<glm::dvec2>* grid : {&grid1, &grid4}) {
      const int spp = int(grid->size());
      // Tiles of 37 columns from odd offsets, 9 rows each; per row, runs
      // on one setup, single samples and empty ones; in every third row
      // long runs (addRow copies spans of 8 or more from its tables).
      struct Row {
        int x0, y;
        std::vector<uint32_t> winners;
      };
      std::vector<Row> rows;
      for (int t = 0; t < 4; ++t) {
        const int x0 = (13 + 29 * t) % std::max(1, w - 37), y0 = (7 * t) % std::max(1, h - 9);
        for (int y = y0; y < y0 + 9 && y < h; ++y) {
          Row row{x0, y, {}};
          for (int i = 0; i < 37 * spp; ++i) {
            const int kind = (i / 11 + y + t) % 4;
            if (y % 3 == 0) {
              row.winners.push_back(i % 29 == 5 ? kNoSetup : uint32_t((i / 23 + y) % setups.size()));
              continue;
            }
            row.winners.push_back(kind == 0   ? kNoSetup
                                  : kind == 1 ? uint32_t((i * 7 + y) % setups.size())
                                              : uint32_t((i / 9 + y * 3) % setups.size()));
          }
          rows.push_back(std::move(row));
        }
      }
      // Expected: the same samples through primaryShadeHits, footprint at the sample.
      std::vector<uint32_t> winners;
      std::vector<glm::dvec2> positions;
      std::vector<uint32_t> locals;
      for (size_t r = 0; r < rows.size(); ++r)
        for (size_t i = 0; i < rows[r].winners.size(); ++i) {
          if (rows[r].winners[i] == kNoSetup) continue;
          winners.push_back(rows[r].winners[i]);
          positions.push_back(glm::dvec2(rows[r].x0 + int(i) / spp, rows[r].y) + (*grid)[i % size_t(spp)]);
          locals.push_back(uint32_t(r * 1000 + i));
        }
      const size_t n = winners.size();
      std::vector<SampleHit> expectedHits(n);
      std::vector<ShadeHit> expected(n);
      primaryShadeHits(constants, scene, setups.data(), winners.data(), positions.data(), positions.data(), n,
                       expectedHits.data(), expected.data());
      // wantInterpolated(false), as the lean tile form runs it: the
      // interpolated barycentrics only where the refinement fails, the
      // same depth and kernel inputs.
      // wantShadingInputs(false), as an emissive scene's tiles run it: the
      // same interpolation and runs, no kernel inputs.
      for (int64_t target : hwy::SupportedAndGeneratedTargets())
        for (const bool interpolated : {true, false})
          for (const bool inputs : {true, false}) {
            SCOPED_TRACE(hwy::TargetName(target) + std::string(interpolated ? "" : " lean") +
                         std::string(inputs ? "" : " no inputs"));
            hwy::SetSupportedTargetsForTest(target);
            PrimaryBatch batch(constants, scene, setups.data());
            batch.wantInterpolated(interpolated);
            batch.wantShadingInputs(inputs);
            uint32_t localOut[kPrimaryHitBlock];
            size_t next = 0;  // the expected sample the batch's first one is
            const auto check = [&] {
              batch.run();
              const PrimaryHitBlock got = batch.hits(batch.x(), batch.y(), localOut);
              ASSERT_EQ(got.count, batch.size());
              for (size_t k = 0; k < got.count; ++k, ++next) {
                ASSERT_LT(next, n);
                const ShadeHit& e = expected[next];
                ASSERT_EQ(localOut[k], locals[next]) << "sample " << next;
                if (interpolated) {
                  ASSERT_TRUE(sameBits(batch.hit(k), expectedHits[next])) << "sample " << next;
                } else {
                  const float depth = batch.depth(k);
                  ASSERT_EQ(0, std::memcmp(&expectedHits[next].depth, &depth, sizeof(float)))
                      << "sample " << next;
                }
                if (k > 0) {
                  ASSERT_LE(got.run[k - 1], got.run[k]);
                }
                if (!inputs) {
                  ASSERT_TRUE(got.dirX == nullptr && got.b1 == nullptr && got.runCorners == nullptr);
                  ASSERT_EQ(got.runInstance[got.run[k]], e.instance) << "sample " << next;
                  ASSERT_EQ(got.runTriangle[got.run[k]], e.triangle) << "sample " << next;
                  continue;
                }
                const ShadeHit a{got.runInstance[got.run[k]],
                                 got.runTriangle[got.run[k]],
                                 got.b1[k],
                                 got.b2[k],
                                 {got.dirX[k], got.dirY[k], got.dirZ[k]},
                                 {got.footprintX[k], got.footprintY[k]},
                                 1.0f};
                ASSERT_TRUE(sameBits(a, e)) << "sample " << next;
              }
              batch.clear();
            };
            for (size_t r = 0; r < rows.size(); ++r) {
              const Row& row = rows[r];
              for (size_t i = 0; i < row.winners.size();) {
                i = batch.addRow(row.winners.data(), i, row.winners.size(), spp, row.x0, row.y, grid->data(),
                                 uint32_t(r * 1000), localOut);
                if (batch.full()) check();
              }
              // Every few rows a partial block, as a tile's last one.
              if (r % 5 == 4 && batch.size() > 0) check();
            }
            if (batch.size() > 0) check();
            EXPECT_EQ(next, n);
          }
      hwy::SetSupportedTargetsForTest(0);
    }
  }
}

}  // namespace
}  // namespace rastray
