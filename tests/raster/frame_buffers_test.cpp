// Frame buffers reused between frames (raster/frame_buffers.h): a frame
// rendered into another frame's stale storage is bit-identical to one
// rendered into fresh buffers, and the storage really is reused.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <thread>
#include <tuple>

#include <tbb/task_arena.h>

#include "common/gltf/loader.h"
#include "raster/frame_buffers.h"
#include "raster_test_util.h"

#include "tests/test_labels.h"

// Every test here renders on 2 or more threads (the ThreadSanitizer stage runs them).
RASTRAY_TEST_LABELS("threads");

namespace rastray {
namespace {

void expectSameImage(const FlatImage& a, const FlatImage& b, const std::string& what) {
  ASSERT_EQ(a.width, b.width) << what;
  ASSERT_EQ(a.height, b.height) << what;
  ASSERT_EQ(a.color.size(), b.color.size()) << what;
  EXPECT_TRUE(a.hasColor && b.hasColor) << what;
  // Bits, not values: NaN-free, but +inf depth and -0 must match too.
  EXPECT_EQ(0, std::memcmp(a.color.data(), b.color.data(), a.color.size() * sizeof(a.color[0]))) << what;
  EXPECT_EQ(0, std::memcmp(a.depth.data(), b.depth.data(), a.depth.size() * sizeof(float))) << what;
  EXPECT_EQ(a.instance, b.instance) << what;
  EXPECT_EQ(a.triangle, b.triangle) << what;
}

// A single triangle over most of an empty background: where the previous
// frame (the Cornell box, which fills the image) left keys, winners,
// colours and ids, this frame must show background.
Scene oneTriangle() {
  Scene scene;
  test::addMesh(scene, {{-0.8f, -0.8f, -2.0f}, {0.8f, -0.8f, -2.0f}, {0.0f, 0.8f, -2.0f}}, {{0, 1, 2}},
                test::colored(glm::vec4(0.2f, 0.6f, 0.9f, 1.0f)));
  return scene;
}

TEST(FrameBuffers, StaleStorageGivesTheFreshFrameBitForBit) {
  const Scene cornell = loadScene(test::scenePath("cornell-box.gltf"));
  const Scene triangle = oneTriangle();
  RasterFrameBuffers pool;
  for (const int spp : {1, 4}) {
    for (const auto& [w, h] : {std::pair{96, 72}, std::pair{130, 67}}) {
      const std::string what = std::to_string(w) + "x" + std::to_string(h) + " spp " + std::to_string(spp);
      RasterOptions options;
      options.spp = spp;
      options.shadows = RasterShadows::None;
      const Camera cornellCamera = makeCamera(cornell, {}, w, h);
      const Camera triangleCamera = test::orthoCamera(w, 1.0);
      Camera camera = triangleCamera;
      camera.height = h;
      camera.ymag = double(h) / double(w);

      const RenderOutput freshCornell = test::render(cornell, cornellCamera, options);
      const RenderOutput freshTriangle = test::render(triangle, camera, options);

      RasterOptions pooled = options;
      pooled.frameBuffers = &pool;
      // Cornell, triangle, Cornell, triangle through the same storage.
      for (int round = 0; round < 2; ++round) {
        RenderOutput a = test::render(cornell, cornellCamera, pooled);
        expectSameImage(a.image, freshCornell.image, what + " cornell round " + std::to_string(round));
        const void* storage = a.image.color.data();
        pool.recycle(std::move(a.image));
        RenderOutput b = test::render(triangle, camera, pooled);
        expectSameImage(b.image, freshTriangle.image, what + " triangle round " + std::to_string(round));
        // Same size: the recycled image's storage served this frame.
        EXPECT_EQ(storage, static_cast<const void*>(b.image.color.data())) << what;
        pool.recycle(std::move(b.image));
      }
    }
  }
}

// The wireframe reads the whole depth target after the tiles: the reused
// target must be cleared everywhere it reads.
TEST(FrameBuffers, WireframeOverStaleTargetMatchesFresh) {
  const Scene cornell = loadScene(test::scenePath("cornell-box.gltf"));
  const Scene triangle = oneTriangle();
  RasterOptions options;
  options.shadows = RasterShadows::None;
  options.wireframe = true;
  const Camera camera = test::orthoCamera(80, 1.0);
  const RenderOutput fresh = test::render(triangle, camera, options);
  RasterFrameBuffers pool;
  RasterOptions pooled = options;
  pooled.frameBuffers = &pool;
  RenderOutput first = test::render(cornell, makeCamera(cornell, {}, 80, 80), pooled);
  pool.recycle(std::move(first.image));
  const RenderOutput second = test::render(triangle, camera, pooled);
  expectSameImage(second.image, fresh.image, "wireframe");
}

// The triangle setups and their refinement planes (hundreds of MB at
// 10^6 triangles) live in the pool between frames: a second frame of the
// same scene sets up into the first frame's storage (same address, same
// capacity: no fresh pages mapped, faulted in and zeroed), and a frame
// that needs less keeps the larger storage instead of shrinking it.
TEST(FrameBuffers, SecondFrameSetsUpIntoTheFirstFramesStorage) {
  const Scene cornell = loadScene(test::scenePath("cornell-box.gltf"));
  const Scene triangle = oneTriangle();
  const Camera camera = makeCamera(cornell, {}, 64, 48);
  RasterOptions options;
  options.shadows = RasterShadows::None;
  RasterFrameBuffers pool;
  RasterOptions pooled = options;
  pooled.frameBuffers = &pool;
  const auto storage = [&pool] {
    FrameBufferLease lease(&pool);
    return std::tuple(static_cast<const void*>(lease.setups().data()), lease.setups().capacity(),
                      static_cast<const void*>(lease.planes().data()), lease.planes().capacity());
  };
  RenderOutput first = test::render(cornell, camera, pooled);
  const auto [setups, setupCapacity, planes, planeCapacity] = storage();
  ASSERT_NE(setups, nullptr);
  ASSERT_NE(planes, nullptr);
  EXPECT_GE(setupCapacity, size_t(first.counters.get("raster.triangles_setup")));
  pool.recycle(std::move(first.image));
  for (int frame = 0; frame < 2; ++frame) {
    RenderOutput next = test::render(frame == 0 ? cornell : triangle, camera, pooled);
    EXPECT_EQ(storage(), std::tuple(setups, setupCapacity, planes, planeCapacity)) << "frame " << frame;
    pool.recycle(std::move(next.image));
  }
  // Without a pool each frame's storage is its own (and freed with it).
  FrameBufferLease own(nullptr);
  EXPECT_EQ(own.setups().capacity(), size_t(0));
}

// A pool in use by one frame: a second frame at the same time takes its
// own buffers and still gets its picture.
TEST(FrameBuffers, BusyPoolFallsBackToOwnBuffers) {
  const Scene triangle = oneTriangle();
  const Camera camera = test::orthoCamera(64, 1.0);
  RasterOptions options;
  options.shadows = RasterShadows::None;
  const RenderOutput fresh = test::render(triangle, camera, options);
  RasterFrameBuffers pool;
  FrameBufferLease held(&pool);  // the pool is busy
  FrameBufferLease second(&pool);
  bool cleared = false;
  const DepthTarget& target = second.target(64, 64, 1, &cleared);
  EXPECT_TRUE(cleared);  // own, freshly filled
  EXPECT_EQ(target.keys.size(), size_t(64 * 64));
  RasterOptions pooled = options;
  pooled.frameBuffers = &pool;
  const RenderOutput busy = test::render(triangle, camera, pooled);
  expectSameImage(busy.image, fresh.image, "busy pool");
}

// The tile's samples (per-thread scratch, raster/tile_renderer.cpp) are
// sized, not filled, before each tile: the deferred shading writes every
// sample once, background included. On one thread (a task arena of one,
// so the tile order and the scratch are the same each time) a small
// triangle, whose tiles are mostly background, is rendered after two
// different frames that leave different samples behind: the pictures,
// ids and per-sample hits must not differ, at both shading rates; nor
// may the lean form's pictures (no per-sample hits asked for) differ from
// them.
TEST(FrameBuffers, TileSamplesLeftByAnotherFrameDoNotShow) {
  const Scene cornell = loadScene(test::scenePath("cornell-box.gltf"));
  Scene quad;
  test::addMesh(quad,
                {{-5.0f, -5.0f, -2.0f}, {5.0f, -5.0f, -2.0f}, {5.0f, 5.0f, -2.0f}, {-5.0f, 5.0f, -2.0f}},
                {{0, 1, 2}, {0, 2, 3}}, test::colored(glm::vec4(0.9f, 0.1f, 0.3f, 1.0f)));
  Scene small;
  test::addMesh(small, {{-0.2f, -0.2f, -2.0f}, {0.2f, -0.2f, -2.0f}, {0.0f, 0.2f, -2.0f}}, {{0, 1, 2}},
                test::colored(glm::vec4(0.2f, 0.6f, 0.9f, 1.0f)));
  const Camera camera = test::orthoCamera(192, 1.0);
  tbb::task_arena one(1);
  for (const int spp : {1, 4}) {
    for (const ShadingRate rate : {ShadingRate::Sample, ShadingRate::Pixel}) {
      const std::string what =
          "spp " + std::to_string(spp) + (rate == ShadingRate::Pixel ? " pixel" : " sample");
      RasterOptions options;
      options.spp = spp;
      options.shadingRate = rate;
      options.shadows = RasterShadows::None;
      RenderOutput after[2], lean[2];
      std::vector<SampleHit> hits[2];
      for (int k = 0; k < 2; ++k) {
        one.execute([&] {
          const Scene& before = k == 0 ? cornell : quad;
          const Camera beforeCamera = k == 0 ? makeCamera(cornell, {}, 192, 192) : camera;
          test::render(before, beforeCamera, options);
          after[k] = renderRasterWithHits(small, analyzeScene(small), camera, options, &hits[k]);
          // Without per-sample hits the tiles take the lean form
          // (raster/resolve.h: no front hits; at 1 spp no background
          // colours, the resolve writes them): the same picture.
          test::render(before, beforeCamera, options);
          lean[k] = test::render(small, camera, options);
        });
      }
      expectSameImage(after[0].image, after[1].image, what);
      expectSameImage(lean[0].image, after[0].image, what + " lean after cornell");
      expectSameImage(lean[1].image, after[0].image, what + " lean after quad");
      ASSERT_EQ(hits[0].size(), hits[1].size()) << what;
      EXPECT_EQ(0, std::memcmp(hits[0].data(), hits[1].data(), hits[0].size() * sizeof(SampleHit))) << what;
      // And the background is background (at 1 spp a pixel is its sample;
      // at 4 an edge pixel's centre may miss while other samples hit).
      size_t background = 0;
      for (size_t i = 0; i < after[0].image.instance.size(); ++i) {
        if (spp != 1 || after[0].image.instance[i] != kNoId) continue;
        ++background;
        EXPECT_EQ(after[0].image.color[i], glm::vec4(0.0f)) << what << " pixel " << i;
      }
      if (spp == 1) {
        EXPECT_GT(background, after[0].image.instance.size() / 2) << what;
      }
    }
  }
}

// A frame's fresh image (no pool, or an empty one) has FlatImage(w, h)'s
// pixels, bit for bit, also where its planes are large enough for the
// huge-page advice and the one-call fault-in (640×480: 4.9 MB of colour).
TEST(FrameBuffers, FreshImageIsTheEmptyImage) {
  for (const auto& [w, h] : {std::pair{640, 480}, std::pair{7, 3}}) {
    const FlatImage empty(w, h);
    RasterFrameBuffers pool;
    for (RasterFrameBuffers* p : {static_cast<RasterFrameBuffers*>(nullptr), &pool}) {
      FrameBufferLease lease(p);
      expectSameImage(lease.image(w, h), empty,
                      std::to_string(w) + "x" + std::to_string(h) + (p ? " pool" : " no pool"));
    }
  }
}

}  // namespace
}  // namespace rastray
