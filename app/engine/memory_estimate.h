// What a render, a cross-validation or a sweep cell will hold in memory,
// estimated before anything large is allocated (issue 13: resource
// limits). The estimate is an upper bound of the process's peak RSS:
// what is resident now (the loaded scene, the libraries) plus the
// renderer's structures, sized from the scene, the camera and the
// options: sample buffers, deep lists (samples × expected layers), shadow
// maps, triangle setups and bins, the Embree BVH, mip chains.
// tests/app/memory_test.cpp checks it against measured peaks.
#pragma once

#include <cstdint>

#include "app/engine/render_setup.h"
#include "common/memory_budget.h"

namespace rastray {

// What covers an average sample, from the projected area of triangles
// clipped to the near plane and the image, over the image area (no
// occlusion, so an upper bound of fragments): transparent layers (BLEND
// and transmissive materials) and the fraction an opaque surface covers
// (at most 1; only computed withOpaque, else 1).
struct ProjectedCoverage {
  double opaque = 1.0;
  double transparentLayers = 0.0;
};
// One pass over the triangles (clipping only those that cross the near
// plane or the image's border), parallel, the same sum at any thread count.
ProjectedCoverage projectedCoverage(const Scene& scene, const Camera& camera, bool withOpaque);
// The same for the camera `settings` render with.
ProjectedCoverage projectedCoverage(const Scene& scene, const RenderSettings& settings, bool withOpaque);

// One frame of `kind`: what its output keeps (image, deep samples) and
// what exists only while it renders (setups, bins, depth target, shadow
// maps, BVH, tile scratch).
struct RenderMemory {
  MemoryEstimate kept;
  MemoryEstimate transient;
  double deepEntries = 0.0;  // expected deep samples (with keepSamples)
};
RenderMemory estimateFrameMemory(const Scene& scene, const RenderSettings& settings, RendererKind kind,
                                 bool keepSamples, const ProjectedCoverage& coverage);

// The peak of renderScene(scene, settings): resident now + kept + transient.
MemoryEstimate estimateRenderMemory(const Scene& scene, const RenderSettings& settings);
// The peak of crossvalidate(): three deep frames kept at once, the largest
// transient part, and the comparison's per-pixel maps.
MemoryEstimate estimateCrossvalMemory(const Scene& scene, const RenderSettings& settings);
// The peak of `render -o FILE`: the frame, then (after the frame's
// transient structures are freed) the encoder's buffers for the file.
enum class OutputFormat { Png, Exr, DeepExr };
MemoryEstimate estimateRenderCommandMemory(const Scene& scene, const RenderSettings& settings,
                                           OutputFormat format);

// "rendering 1920x1080 at 16 spp (raster)": the work a refusal names.
std::string describeRenderWork(const RenderSettings& settings, const char* renderer);

}  // namespace rastray
