// What one ray-cast frame allocates while it renders, for the engine's
// --max-memory check (app/engine/memory_estimate.h), kept beside the
// renderer. Embree's structures are private to it: the figures are
// measured peaks per unit (scenes of 10^5–10^6 triangles), rounded up.
#pragma once

#include <cstdint>

#include "common/memory_budget.h"
#include "common/scene.h"

namespace rastray {

// Embree's BVH over the scene's triangles with the geometry buffers it
// shares (measured 50–60 bytes per triangle at build quality medium).
void addRayFrameMemory(const Scene& scene, MemoryEstimate& transient);

// Bytes per deep sample gathered per tile and thread before the frame's
// DeepImage is assembled (measured 48; both copies exist at once).
uint64_t rayDeepGatherBytesPerSample();

}  // namespace rastray
