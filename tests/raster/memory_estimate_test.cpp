// The rasterizer's own memory estimate: which parts it counts and how they
// scale (app/engine's MaxMemory tests check the whole against measured peaks).
#include "raster/memory_estimate.h"

#include <gtest/gtest.h>

#include "raster/setup.h"

namespace rastray {
namespace {

uint64_t part(const MemoryEstimate& e, const std::string& name) {
  for (const auto& [n, bytes] : e.parts())
    if (n == name) return bytes;
  return 0;
}

Scene quads(size_t count) {
  Scene scene;
  for (size_t i = 0; i < count; ++i) {
    const uint32_t base = uint32_t(scene.positions.size());
    scene.positions.insert(scene.positions.end(), {{0, 0, -1}, {1, 0, -1}, {1, 1, -1}, {0, 1, -1}});
    scene.triangles.push_back({base, base + 1, base + 2});
    scene.triangles.push_back({base, base + 2, base + 3});
  }
  return scene;
}

TEST(RasterMemoryEstimate, SetupsAndDepthTargetScaleWithTrianglesAndSamples) {
  const Scene scene = quads(1000);
  RasterOptions options;
  options.spp = 4;
  MemoryEstimate e;
  addRasterFrameMemory(scene, options, 640 * 480 * 4, 0.0, 2, e);
  EXPECT_EQ(part(e, "triangle setups"), 2000 * sizeof(TriangleSetup));
  EXPECT_EQ(part(e, "refinement planes"), 2000 * sizeof(RefinePlane));
  EXPECT_EQ(part(e, "setup vertex codes"), 4000 * kSetupVertexCodeBytes);
  // Key and winner per sample: one tile's per thread, the whole frame's
  // only where the wireframe reads it after the tiles.
  EXPECT_EQ(part(e, "depth target"), 2u * 64u * 64u * 4u * 8u);
  EXPECT_EQ(part(e, "shadow maps"), 0u);             // no lights
  EXPECT_EQ(part(e, "transparency fragments"), 0u);  // nothing transparent
  options.wireframe = true;
  MemoryEstimate wire;
  addRasterFrameMemory(scene, options, 640 * 480 * 4, 0.0, 2, wire);
  EXPECT_EQ(part(wire, "depth target"), 640u * 480u * 4u * 8u);
}

TEST(RasterMemoryEstimate, ShadowMapsOnlyWhenDrawnSixFacesPerPointLight) {
  Scene scene = quads(10);
  Light point, sun;
  sun.type = LightType::Directional;
  scene.lights = {point, sun};
  RasterOptions options;
  options.shadowMapSize = 512;
  options.shadows = RasterShadows::Map;
  MemoryEstimate maps;
  addRasterFrameMemory(scene, options, 1000, 0.0, 1, maps);
  EXPECT_EQ(part(maps, "shadow maps"), (6u + 1u) * 512u * 512u * 4u);
  options.shadows = RasterShadows::None;
  MemoryEstimate none;
  addRasterFrameMemory(scene, options, 1000, 0.0, 1, none);
  EXPECT_EQ(part(none, "shadow maps"), 0u);
  EXPECT_EQ(part(none, "shadow map setups"), 0u);
}

TEST(RasterMemoryEstimate, TransparencyGrowsWithLayersAndThreads) {
  const Scene scene = quads(1);
  RasterOptions options;
  MemoryEstimate one, two;
  addRasterFrameMemory(scene, options, 1000, 3.0, 1, one);
  addRasterFrameMemory(scene, options, 1000, 3.0, 2, two);
  EXPECT_GT(part(one, "transparency fragments"), 0u);
  EXPECT_EQ(part(two, "transparency fragments"), 2 * part(one, "transparency fragments"));
}

}  // namespace
}  // namespace rastray
