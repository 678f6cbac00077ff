#include "raster/memory_estimate.h"

#include <algorithm>

#include "common/parallel.h"
#include "raster/bin.h"
#include "raster/setup.h"
#include "raster/tile_renderer.h"

namespace rastray {

namespace {

constexpr uint64_t kDepthTargetSampleBytes = 2 * sizeof(uint32_t);  // key + winner
constexpr uint64_t kShadowTexelBytes = sizeof(uint32_t);            // keys only
// A triangle is binned into every tile its box touches: a few on average.
constexpr uint64_t kBinBytesPerTriangle = 4 * sizeof(uint32_t);

}  // namespace

void addRasterFrameMemory(const Scene& scene, const RasterOptions& options, uint64_t samples,
                          double transparentLayers, int threads, MemoryEstimate& transient) {
  const uint64_t triangles = scene.triangleCount();
  const uint64_t setupBytes = mulSat(triangles, sizeof(TriangleSetup));
  transient.add("triangle setups", setupBytes);
  // The camera pass's refinement plane per setup (raster/setup.h: RefinePlane).
  transient.add("refinement planes", mulSat(triangles, sizeof(RefinePlane)));
  // The setup's per-vertex codes, alive while setups are made (raster/setup.h).
  transient.add("setup vertex codes", mulSat(scene.positions.size(), kSetupVertexCodeBytes));
  transient.add("tile bins", mulSat(triangles, kBinBytesPerTriangle));
  // Frame-sized only where the wireframe reads it after the tiles; else
  // one tile's target per thread (raster/tile_renderer.h).
  const uint64_t tileSamples = uint64_t(kTileSize) * kTileSize * uint64_t(options.spp);
  transient.add("depth target",
                options.wireframe ? mulSat(samples, kDepthTargetSampleBytes)
                                  : mulSat(mulSat(tileSamples, uint64_t(threads)), kDepthTargetSampleBytes));
  if (options.shadows == RasterShadows::Map && !scene.lights.empty()) {
    // Every face of every light's map stays until the frame ends; one
    // face's setups and a candidate mask exist while it is drawn.
    uint64_t faces = 0;
    for (const Light& light : scene.lights) faces += light.type == LightType::Point ? 6 : 1;
    const uint64_t texels = uint64_t(options.shadowMapSize) * uint64_t(options.shadowMapSize);
    transient.add("shadow maps", mulSat(mulSat(faces, texels), kShadowTexelBytes));
    transient.add("shadow map setups", addSat(setupBytes, triangles));
  }
  if (transparentLayers > 0.0) {
    // Fragments and shaded layers of the tiles in flight, one per thread.
    const double perTile =
        double(tileSamples) * transparentLayers * double(sizeof(BlendFragment) + sizeof(BlendLayer));
    transient.add("transparency fragments", uint64_t(std::min(perTile * threads, 1.8e19)));
  }
}

uint64_t rasterDeepGatherBytesPerSample() { return sizeof(DeepSample); }

}  // namespace rastray
