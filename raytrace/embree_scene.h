// The Embree device and scene built from the shared triangle store
// (common/scene.h). Internal to raytrace/: Embree is included here and by
// the ray caster's parts (ray_caster_parts.h), nowhere else.
//
// IDs: one triangle geometry per instance, attached with geomID == instance
// index, and the index buffer in triangle-ID order, so Embree's (geomID,
// primID) is exactly SPEC §1's (instance, triangle). Instances without
// triangles get no geometry (their ID stays unused).
//
// Scene flags and build quality:
// - RTC_SCENE_FLAG_ROBUST: Embree's watertight triangle test (no
//   optimisations that lose accuracy), so a ray through an edge shared by
//   two triangles of a closed mesh hits at least one of them: no sample
//   slips through a closed surface (SPEC §3).
// - RTC_BUILD_QUALITY_MEDIUM: one frame per build, so build time counts;
//   and unlike HIGH it makes no spatial splits, so each triangle is
//   referenced by one BVH leaf and filter callbacks see each crossing once
//   (we still drop identical (instance, triangle) repeats defensively).
//
// Degenerate triangles (zero area in world space, the loader's test) keep
// their primID but get the index triple (v0, v0, v0): Embree's triangle
// test rejects a zero denominator, so they cover nothing (SPEC §1).
//
// Filters: only on the geometries that need them: MASK, BLEND or refractive
// materials (when SceneAnalysis::needsRayFilters), and, with face culling,
// single-sided materials (SPEC §3). Every other geometry is accepted by
// Embree directly.
#pragma once

#include <embree3/rtcore.h>

#include <mutex>
#include <string>

#include "common/analysis.h"
#include "common/cull.h"
#include "common/scene.h"

namespace rastray {

class EmbreeScene {
 public:
  // `filterUserPtr` is handed to the filter callbacks as geometryUserPtr.
  EmbreeScene(const Scene& scene, const SceneAnalysis& analysis, CullMode cull,
              RTCFilterFunctionN intersectFilter, RTCFilterFunctionN occludedFilter, void* filterUserPtr);
  ~EmbreeScene();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  RTCScene handle() const { return scene_; }
  bool hasFilters() const { return filterGeometries_ > 0; }
  size_t filterGeometries() const { return filterGeometries_; }
  // Throws std::runtime_error("embree: <error>: <message>") with the first
  // error the device reported since the last call (the callback cannot
  // throw through Embree, and does not print); app/ prints it as one line.
  void throwIfError();

 private:
  static void onError(void* userPtr, RTCError code, const char* message);

  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  size_t filterGeometries_ = 0;
  std::mutex errorMutex_;
  std::string firstError_;
};

// True for materials whose hits a filter callback must see.
bool needsFilter(const Material& material, bool sceneNeedsFilters, CullMode cull);

}  // namespace rastray
