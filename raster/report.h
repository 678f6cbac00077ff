// What a frame reports besides its pixels: the passes it ran and left out
// (with the reason from the scene analysis) and its counters. Internal to
// raster/.
#pragma once

#include <cstdint>

#include "common/analysis.h"
#include "common/render_output.h"
#include "raster/options.h"
#include "raster/setup.h"
#include "raster/tile_renderer.h"

namespace rastray {

struct ShadowMapStats {
  uint64_t maps = 0, triangles = 0, transmissiveFragments = 0;
};

// The camera passes, in pipeline order: opaque, alpha test, transparency,
// secondary rays (`secondary`: the hybrid's tracer is there), textures.
void describeCameraPasses(const SceneAnalysis& analysis, const RasterOptions& options, bool secondary,
                          RenderOutput* out);

// Sets every raster.* counter of `out` (the tiles' counters summed).
void reportCounters(const SetupCounters& setup, uint64_t trianglesSetup, const ThreadCounters& tiles,
                    const ShadowMapStats& shadows, uint64_t wireframePixels, CounterSet* out);

}  // namespace rastray
