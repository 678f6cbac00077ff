// One tile of the camera view, from its bins to its pixels. Internal to
// raster/: rasterizer.cpp (the frame) runs it over every tile in parallel.
// The passes, one file each, in the order a tile runs them:
//
//   tile_renderer.cpp   the tile's pipeline and the sampling helpers
//   opaque_pass.cpp     pass 1: OPAQUE and MASK depth test and write, then
//                       deferred shading of the samples that won
//   transparency.cpp    pass 2: BLEND layers per sample (exact, sorted, peel)
//   tile_resolve.cpp    compositing, resolve, per-sample hits, deep samples
//   report.cpp          passes run and left out, counters
//
// Three depths a sample's surface has here, not to be mixed up:
//   depth key            uint32 window depth in the depth format
//                        (sampleDepthKey, coverage.h): what the depth test
//                        compares;
//   interpolated depth   view depth from the screen-space planes d/w ÷ 1/w
//                        (TriangleSetup::viewDepthAt, float in SampleHit):
//                        what Z, the deep samples and the hits report;
//   plane depth          view depth where the primary ray meets the stored
//                        triangle's plane, in double (planeDepth): what
//                        orders BLEND layers, as the ray caster orders them.
// Shading refines the hit on that plane again (refinePrimaryHits, a tile at a
// time: common/primary_refinement.h) and shades a tile's hits as one batch
// (common/shading_kernel.h), as the ray caster does.
#pragma once

#include <cstdint>
#include <vector>

#include "common/analysis.h"
#include "common/camera.h"
#include "common/hit.h"
#include "common/image.h"
#include "common/render_output.h"
#include "common/scene.h"
#include "common/shading.h"
#include "common/shading_kernel.h"
#include "common/surface.h"
#include "raster/bin.h"
#include "raster/coverage.h"
#include "raster/options.h"
#include "raster/primary_samples.h"
#include "raster/resolve.h"
#include "raster/setup.h"

namespace rastray {

// Work counted per thread, summed into RenderOutput::counters (report.cpp).
struct ThreadCounters {
  DepthPassCounters opaque;
  uint64_t blendCoverageTests = 0;
  uint64_t blendSamplesTested = 0;  // covered BLEND samples tested against the opaque depth
  uint64_t fragmentsTransparent = 0;
  uint64_t shadedSamples = 0;
  // Of those, the samples given a primary ray and a refined hit (none in
  // an unlit, emissive scene: PrimaryHitShader::needsHitInputs).
  uint64_t refinedSamples = 0;
  uint64_t peelPasses = 0;
  // Thread-seconds per pass of the tiles (three clock reads per tile):
  // rasterizer.cpp splits the tile loop's wall time among them.
  double depthSeconds = 0.0;         // pass 1: coverage, depth test and write
  double shadeSeconds = 0.0;         // deferred shading of the visible samples
  double transparencySeconds = 0.0;  // pass 2 and compositing
  double resolveSeconds = 0.0;       // resolve, hits, deep samples

  ThreadCounters& operator+=(const ThreadCounters& other);
};

// A covered BLEND sample in front of the opaque depth.
struct BlendFragment {
  uint32_t local;     // TileSampleIndex
  double planeDepth;  // orders the layers (see above)
  uint64_t id;        // (instance, triangle)
  uint32_t setup;
  uint32_t order;  // sorted mode: position in the painter's order
};

// One BLEND layer of a sample, shaded, to be composited front to back.
struct BlendLayer {
  uint32_t local;  // TileSampleIndex
  uint32_t rank;   // front to back within the sample
  SampleHit hit;   // interpolated
  glm::vec4 color;
};

// The tile's bins: OPAQUE + MASK, and BLEND (nullptr: the scene has none).
struct TileBins {
  const std::vector<uint32_t>& opaque;
  const std::vector<uint32_t>* blend;
};

// Where a tile's results go; null members are not wanted.
struct TileOutputs {
  FlatImage* image;
  std::vector<DeepSample>* deep;      // per pixel: its samples' layers, then opaque surfaces
  std::vector<uint32_t>* deepCounts;  // entries of `deep` per pixel, in tile order
  std::vector<SampleHit>* hits;       // whole frame: sample (x, y, s) at (y·width + x)·spp + s
};

class TileRenderer {
 public:
  TileRenderer(const Scene& scene, const SceneAnalysis& analysis, const Camera& camera,
               const RasterOptions& options, const Shader& shader, const SampleGrid& grid,
               const std::vector<TriangleSetup>& setups, const RefinePlane* planes = nullptr);

  // Pass 1, deferred shading, pass 2, compositing, resolve, hits and deep
  // samples of one tile. `frameTarget` is the frame's depth target, for a
  // caller that reads it after the tiles (the wireframe): the tile writes
  // only its own samples, and first clears them when `clearTarget` (reused
  // storage: raster/frame_buffers.h). Null: the tile uses a depth target
  // of its own rectangle (per thread, kept in cache).
  void render(const TileRect& rect, const TileBins& bins, DepthTarget* frameTarget, bool clearTarget,
              const TileOutputs& out, ThreadCounters& n) const;

 private:
  // Sampling helpers (tile_renderer.cpp).
  SampleHit interpolatedHit(const TriangleSetup& t, const glm::dvec2& pos) const;
  double planeDepth(const TriangleSetup& t, const glm::dvec2& pos) const;
  // `hit`: interpolatedHit at `pos` (computed once by the caller, which keeps it too).
  SurfacePoint surfaceAt(const SampleHit& hit, const glm::dvec2& pos, Ray* ray) const;
  TextureFootprint footprint(const SurfacePoint& p, const glm::dvec2& pos) const;
  glm::vec4 shadeAt(const SampleHit& hit, const glm::dvec2& pos, const glm::dvec2& footprintPos,
                    ThreadCounters& n) const;
  bool alphaCovered(const TriangleSetup& t, int px, int py, int s) const;
  glm::dvec2 samplePosition(const TileSampleIndex& index, uint32_t local) const;
  // The shading kernel's path for this frame's primary hits (opaque pass
  // and BLEND layers alike): the kernel unless the reference is asked for.
  ShadingPath shadingPath() const {
    return shader_.options().referenceShading ? ShadingPath::Reference : ShadingPath::Kernel;
  }
  CoveragePath coveragePath() const {
    return options_.referenceCoverage ? CoveragePath::Reference : CoveragePath::Fast;
  }

  // Pass 1 (opaque_pass.cpp).
  void opaquePass(const TileRect& rect, const std::vector<uint32_t>& bin, const TraceRequest& trace,
                  DepthTarget* target, ThreadCounters& n) const;
  // `allFronts`: every sample's front hit is read (per-sample hits out);
  // else only the centre sample's and the traced pixel's need to be set
  // where shading once per pixel reuses a colour.
  // Fills `samples` in the form `samples.lean` names (raster/resolve.h);
  // any previous contents are replaced.
  void shadeVisible(const TileSampleIndex& index, const DepthTarget& target, const TraceRequest& trace,
                    bool allFronts, TileSamples& samples, ThreadCounters& n) const;

  // Pass 2 (transparency.cpp): layers sorted by local index, front to back
  // within a sample.
  std::vector<BlendLayer> transparencyPass(const TileSampleIndex& index, const std::vector<uint32_t>& bin,
                                           const DepthTarget& target, ThreadCounters& n) const;
  template <typename F>
  void forEachFragment(const TileSampleIndex& index, const std::vector<uint32_t>& triangles,
                       const DepthTarget& target, CoverageScratch& scratch, ThreadCounters& n, F&& f) const;
  BlendLayer shadeLayer(const TileSampleIndex& index, const BlendFragment& f, uint32_t rank,
                        ThreadCounters& n) const;
  // Shades fragments grouped by sample, each group front to back; a
  // fragment's rank is its position within its sample's group.
  std::vector<BlendLayer> shadeInSampleOrder(const TileSampleIndex& index,
                                             const std::vector<BlendFragment>& fragments,
                                             ThreadCounters& n) const;
  std::vector<BlendLayer> exactLayers(const TileSampleIndex& index, const std::vector<uint32_t>& bin,
                                      const DepthTarget& target, ThreadCounters& n) const;
  std::vector<BlendLayer> sortedLayers(const TileSampleIndex& index, const std::vector<uint32_t>& bin,
                                       const DepthTarget& target, ThreadCounters& n) const;
  std::vector<BlendLayer> peeledLayers(const TileSampleIndex& index, const std::vector<uint32_t>& bin,
                                       const DepthTarget& target, ThreadCounters& n) const;

  // Compositing and output (tile_resolve.cpp).
  std::vector<glm::vec4> compositeLayers(const std::vector<BlendLayer>& layers, TileSamples* samples) const;
  void traceLayersAndFinal(const TileSampleIndex& index, const TraceRequest& trace,
                           const std::vector<BlendLayer>& layers, const TileSamples& samples) const;
  void copyHits(const TileSampleIndex& index, const TileSamples& samples, std::vector<SampleHit>* hits) const;
  void appendDeepSamples(const TileSampleIndex& index, const std::vector<BlendLayer>& layers,
                         const DepthTarget& target, const std::vector<glm::vec4>& opaqueColor,
                         const TileOutputs& out) const;

  const Scene& scene_;
  const SceneAnalysis& analysis_;
  const Camera& camera_;
  const RasterOptions& options_;
  const Shader& shader_;
  const SampleGrid& grid_;
  const std::vector<TriangleSetup>& setups_;
  const RefinePlane* planes_;             // per setup, or null (PrimaryBatch)
  PrimaryRays rays_;                      // camera_'s primary rays (bit-identical to Camera::primaryRay)
  PrimaryRayConstants primaryConstants_;  // the same rays for primarySamples' lanes
  int centre_;
  // PrimaryHitShader::needsHitInputs for the frame, asked once here: it
  // looks at every instance, too much to ask per tile.
  bool refinesHits_;
};

// The frame's deep image from every tile's deep samples and per-pixel counts
// (TileOutputs::deep, deepCounts; tile_resolve.cpp).
DeepImage assembleDeepImage(const TileGrid& tiles, const std::vector<std::vector<DeepSample>>& deep,
                            const std::vector<std::vector<uint32_t>>& deepCounts);

}  // namespace rastray
