// Rendering under RenderSettings (app/engine/render_options.h): one
// function that runs a renderer on a scene (the composition point of hybrid
// rendering: app/ wires raster/ and raytrace/, neither knows the other).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/engine/render_options.h"
#include "common/analysis.h"
#include "common/camera.h"
#include "common/gltf/loader.h"
#include "common/memory_budget.h"
#include "common/render_output.h"
#include "common/scene.h"
#include "common/trace.h"
#include "compare/classify.h"
#include "raster/rasterizer.h"
#include "raytrace/ray_caster.h"

namespace rastray {

// A scene made ready for frames under fixed settings: its analysis, the
// camera and, for the ray caster and hybrid, the Embree scene (BVH), built
// once here. frame() renders one frame; calling it again renders the same
// frame again without rebuilding anything (what `bench` times). The scene
// and the options must outlive it.
class FrameRenderer {
 public:
  // settings.finish() must have been called; `raster` and `ray` are the
  // options the renderers run with (settings' own, plus keepSamples and
  // trace requests the caller set); they must outlive this object.
  // `sharedCaster`: a ray caster (its Embree BVH) already built for this
  // scene and settings.cull, shared with other FrameRenderers (serve keeps one
  // per prepared scene); it is bound to this camera and options before each
  // frame. Null: one is built here when the renderer needs it.
  FrameRenderer(const Scene& scene, const RenderSettings& settings, const RasterOptions& raster,
                const RayOptions& ray, std::shared_ptr<RayCaster> sharedCaster = nullptr);
  ~FrameRenderer();
  FrameRenderer(const FrameRenderer&) = delete;
  FrameRenderer& operator=(const FrameRenderer&) = delete;

  RenderOutput frame();

  const Camera& camera() const { return camera_; }
  const SceneAnalysis& analysis() const { return analysis_; }
  // Seconds the Embree scene took to build here; negative without a ray
  // caster or with a shared one.
  double bvhBuildSeconds() const { return bvhBuildSeconds_; }
  // The ray caster this renderer uses (null for the rasterizer alone).
  const std::shared_ptr<RayCaster>& caster() const { return caster_; }

 private:
  RenderOutput renderFrame();

  const Scene& scene_;
  RendererKind renderer_;
  float exposureScale_;  // 2^--exposure, exact in float for whole stops
  const RasterOptions& raster_;
  const RayOptions& ray_;
  SceneAnalysis analysis_;
  Camera camera_;
  std::shared_ptr<RayCaster> caster_;
  double bvhBuildSeconds_ = -1.0;
};

struct RenderRun {
  Camera camera;
  SceneAnalysis analysis;
  RenderOutput output;
  double seconds = 0.0;
  MemoryEstimate memoryEstimate;  // checked against RenderSettings::memory before rendering
};

// Keeps only the lights --lights names (Scene::lights indices, as `info`
// lists them), before the scene is analysed: with none left, SPEC §8's
// decisions follow (the eye light, no shadow work). Throws InputError
// naming --lights and the light count for an index out of range.
void selectLights(Scene& scene, const RenderSettings& settings);

// What loadSceneForRender does to a loaded scene: selectLights, then the
// rebasing on the render origin --origin names (applyRenderOrigin).
void prepareSceneForRender(Scene& scene, const RenderSettings& settings);

// Loads a scene and prepares it (prepareSceneForRender); settings.finish()
// must have been called.
Scene loadSceneForRender(const std::string& path, const RenderSettings& settings);

// Runs the chosen renderer; settings.finish() must have been called.
// Refuses (InputError, exit 2) before allocating when the estimated peak
// memory (app/engine/memory_estimate.h) exceeds settings.memory, unless the
// caller passes `checked`: an estimate covering this render that it has
// checked already (render -o, crossval), which the run then reports.
// With settings.debugPixel, what the renderer recorded at that pixel is
// printed to stderr afterwards, unless the caller gave the renderer's
// options a trace sink of its own (explain).
RenderRun renderScene(const Scene& scene, const RenderSettings& settings,
                      const MemoryEstimate* checked = nullptr);

// How mismatches between renders of `scene` through `camera` are
// classified: geometrically, against the depth buffer `depthFormat`
// (the rasterizing renderer's --depth-format; float-reversed when only the
// ray caster is compared). The one place every caller builds it.
ClassifierSettings classifierSettings(const Scene& scene, const Camera& camera, DepthFormat depthFormat);

// The ray caster's events of one pixel (TraceStage::Ray) as text under a
// "ray tree of pixel (x, y): N rays" line; empty without ray events.
std::string rayTreeText(const std::vector<TraceEvent>& events, glm::ivec2 pixel);

nlohmann::json renderReportJson(const Scene& scene, const RenderSettings& settings, const RenderRun& run);
void printRenderStats(const RenderRun& run);

}  // namespace rastray
