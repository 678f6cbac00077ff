#include "raytrace/embree_scene.h"

#include <stdexcept>

#include "common/error.h"

namespace rastray {

namespace {

const char* errorName(RTCError code) {
  switch (code) {
    case RTC_ERROR_NONE:
      return "none";
    case RTC_ERROR_UNKNOWN:
      return "unknown";
    case RTC_ERROR_INVALID_ARGUMENT:
      return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION:
      return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY:
      return "out of memory";
    case RTC_ERROR_UNSUPPORTED_CPU:
      return "unsupported CPU";
    case RTC_ERROR_CANCELLED:
      return "cancelled";
  }
  return "?";
}

}  // namespace

bool needsFilter(const Material& material, bool sceneNeedsFilters, CullMode cull) {
  if (cull != CullMode::None && !material.doubleSided) return true;
  return sceneNeedsFilters && (material.alphaMode != AlphaMode::Opaque || material.isRefractive());
}

// Called by Embree on the thread that made the failing call, possibly
// inside a traversal: it cannot throw through Embree and must not print
// (the libraries never write to stderr), so it keeps the first message and
// throwIfError() raises it on the caller's side of the call.
void EmbreeScene::onError(void* userPtr, RTCError code, const char* message) {
  auto* self = static_cast<EmbreeScene*>(userPtr);
  const std::string text = std::string("embree: ") + errorName(code) + ": " + (message ? message : "");
  std::lock_guard<std::mutex> lock(self->errorMutex_);
  if (self->firstError_.empty()) self->firstError_ = text;
}

void EmbreeScene::throwIfError() {
  std::lock_guard<std::mutex> lock(errorMutex_);
  if (firstError_.empty()) return;
  const std::string text = firstError_;
  firstError_.clear();
  throw std::runtime_error(text);
}

EmbreeScene::EmbreeScene(const Scene& scene, const SceneAnalysis& analysis, CullMode cull,
                         RTCFilterFunctionN intersectFilter, RTCFilterFunctionN occludedFilter,
                         void* filterUserPtr) {
  device_ = rtcNewDevice(nullptr);
  // rtcGetDeviceError(nullptr) says why: out of memory under a memory
  // limit (the crossover study's children), or an unsupported CPU.
  if (!device_)
    throw std::runtime_error(std::string("embree: cannot create a device: ") +
                             errorName(rtcGetDeviceError(nullptr)));
  rtcSetDeviceErrorFunction(device_, &EmbreeScene::onError, this);

  scene_ = rtcNewScene(device_);
  rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_MEDIUM);

  const bool filters = analysis.needsRayFilters();
  for (uint32_t id = 0; id < uint32_t(scene.instances.size()); ++id) {
    const Instance& inst = scene.instances[id];
    if (inst.triangleCount == 0) continue;
    RTCGeometry geometry = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    // Copies, not shared buffers: Embree wants 16 readable bytes at the
    // last vertex, which rtcSetNewGeometryBuffer pads for us.
    auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
        geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), inst.vertexCount));
    auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
        geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), inst.triangleCount));
    if (!vertices || !indices) {
      rtcReleaseGeometry(geometry);
      throwIfError();
      throw std::runtime_error("embree: cannot allocate geometry buffers");
    }
    for (uint32_t v = 0; v < inst.vertexCount; ++v) {
      const glm::vec3& p = scene.positions[inst.firstVertex + v];
      vertices[3 * v + 0] = p.x;
      vertices[3 * v + 1] = p.y;
      vertices[3 * v + 2] = p.z;
    }
    for (uint32_t t = 0; t < inst.triangleCount; ++t) {
      const glm::uvec3 tri = scene.triangles[inst.firstTriangle + t];
      RASTRAY_CHECK(tri.x >= inst.firstVertex && tri.x < inst.firstVertex + inst.vertexCount &&
                        tri.y >= inst.firstVertex && tri.y < inst.firstVertex + inst.vertexCount &&
                        tri.z >= inst.firstVertex && tri.z < inst.firstVertex + inst.vertexCount,
                    "instance " + std::to_string(id) + " triangle " + std::to_string(t) +
                        " indexes a vertex outside the instance's range");
      glm::uvec3 local = tri - glm::uvec3(inst.firstVertex);
      // SPEC §1: zero area covers nothing (Embree is handed a point).
      if (isDegenerate(scene, inst.firstTriangle + t)) local = glm::uvec3(local.x);
      indices[3 * t + 0] = local.x;
      indices[3 * t + 1] = local.y;
      indices[3 * t + 2] = local.z;
    }
    if (needsFilter(scene.materials[inst.material], filters, cull)) {
      rtcSetGeometryUserData(geometry, filterUserPtr);
      rtcSetGeometryIntersectFilterFunction(geometry, intersectFilter);
      rtcSetGeometryOccludedFilterFunction(geometry, occludedFilter);
      ++filterGeometries_;
    }
    rtcCommitGeometry(geometry);
    rtcAttachGeometryByID(scene_, geometry, id);
    rtcReleaseGeometry(geometry);
  }
  rtcCommitScene(scene_);
  throwIfError();
}

EmbreeScene::~EmbreeScene() {
  if (scene_) rtcReleaseScene(scene_);
  if (device_) rtcReleaseDevice(device_);
}

}  // namespace rastray
