// The triangle-order z-buffer rasterizer: transform → clip → screen map →
// triangle setup → per-sample coverage and depth test → shading →
// compositing → resolve, every stage explicit and testable on its own
// (clip.h, setup.h, coverage.h, resolve.h). The options: options.h.
#pragma once

#include <vector>

#include "common/analysis.h"
#include "common/camera.h"
#include "common/hit.h"
#include "common/render_output.h"
#include "common/scene.h"
#include "common/shading.h"
#include "raster/options.h"

namespace rastray {

// Renders the scene. With `secondary` and `visibility` from the ray caster
// this is the hybrid renderer: rasterized primary visibility, traced
// shadow, reflection and refraction rays (shadows must then be Rays).
// Throws InputError for options that make no sense together.
RenderOutput renderRaster(const Scene& scene, const SceneAnalysis& analysis, const Camera& camera,
                          const RasterOptions& options, const SecondaryRayTracer* secondary = nullptr,
                          const LightVisibility* visibility = nullptr);

// renderRaster that also returns, per sample ((y·width + x)·spp + s), the
// rasterizer's own hit of the nearest visible surface (front-most layer,
// else the opaque surface; SampleHit{} where nothing): depth and (b1, b2)
// from the perspective-correct interpolation of 1/w, before the shading
// refinement. For tests and sample-by-sample comparison.
RenderOutput renderRasterWithHits(const Scene& scene, const SceneAnalysis& analysis, const Camera& camera,
                                  const RasterOptions& options, std::vector<SampleHit>* hits,
                                  const SecondaryRayTracer* secondary = nullptr,
                                  const LightVisibility* visibility = nullptr);

}  // namespace rastray
