// What one raster frame allocates while it renders, sized from the scene
// and the options before anything large is allocated: the engine adds it
// to the output and what is resident for the --max-memory check
// (app/engine/memory_estimate.h). Kept beside the structures it counts so
// that a change to their size changes the estimate with it.
#pragma once

#include <cstdint>

#include "common/memory_budget.h"
#include "common/scene.h"
#include "raster/options.h"

namespace rastray {

// Triangle setups and their vertex codes, tile bins, the depth target,
// shadow maps (when the options draw them and the scene has lights) and
// the transparency fragments of the tiles in flight. `samples` is the
// frame's width × height × spp; `transparentLayers` the expected
// transparent layers over a sample (projected area, no occlusion: an upper
// bound); `threads` the tiles in flight.
void addRasterFrameMemory(const Scene& scene, const RasterOptions& options, uint64_t samples,
                          double transparentLayers, int threads, MemoryEstimate& transient);

// Bytes per deep sample while the tiles gather them, before they are
// assembled into one DeepImage (both copies exist at once).
uint64_t rasterDeepGatherBytesPerSample();

}  // namespace rastray
