#include "raytrace/memory_estimate.h"

namespace rastray {

namespace {

constexpr uint64_t kBvhBytesPerTriangle = 96;
constexpr uint64_t kDeepGatherBytes = 48;

}  // namespace

void addRayFrameMemory(const Scene& scene, MemoryEstimate& transient) {
  transient.add("Embree BVH", mulSat(scene.triangleCount(), kBvhBytesPerTriangle));
}

uint64_t rayDeepGatherBytesPerSample() { return kDeepGatherBytes; }

}  // namespace rastray
