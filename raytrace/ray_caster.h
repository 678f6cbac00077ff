// The pixel-order ray caster on Embree 3. Only raytrace/ includes Embree.
//
// It renders images on its own (render) and, for the hybrid renderer,
// serves the rasterizer's shading through the SecondaryRayTracer and
// LightVisibility interfaces of common/shading.h.
#pragma once

#include <memory>
#include <optional>

#include <glm/glm.hpp>

#include "common/analysis.h"
#include "common/camera.h"
#include "common/render_output.h"
#include "common/scene.h"
#include "common/shading.h"

namespace rastray {

struct RayOptions {
  int spp = 1;
  ShadingOptions shading;            // maxDepth, throughput cut-off, texture filter
  float transparencyCutoff = 1e-4f;  // stop compositing once remaining transmittance is below
  bool keepSamples = false;          // fill RenderOutput::samples (deep output, crossval)
  bool packets = true;               // coherent packets for primary rays where faster
  std::optional<glm::ivec2> debugPixel;
};

class RayCaster : public SecondaryRayTracer, public LightVisibility {
 public:
  // Builds the Embree device and scene from the shared triangle store.
  RayCaster(const Scene& scene, const SceneAnalysis& analysis);
  ~RayCaster() override;
  RayCaster(const RayCaster&) = delete;
  RayCaster& operator=(const RayCaster&) = delete;

  // Binds a camera and options: required before render() and before the
  // interfaces below are used (hybrid rendering).
  void bind(const Camera& camera, const RayOptions& options);

  RenderOutput render();

  // SecondaryRayTracer / LightVisibility (thread-safe; count rays by kind).
  glm::vec3 radiance(const SurfacePoint& from, const glm::dvec3& direction, RayKind kind, int depth,
                     float throughput) const override;
  glm::vec3 transmittance(const SurfacePoint& point, int lightIndex, const glm::dvec3& toLight,
                          double distance) const override;

  // Rays traced since bind(), by kind (SPEC §8: zero for what the scene
  // does not need).
  CounterSet counters() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rastray
