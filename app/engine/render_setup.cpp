#include "app/engine/render_setup.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iterator>

#include "app/engine/memory_estimate.h"
#include "common/error.h"
#include "common/sampling.h"
#include "common/trace.h"

namespace rastray {

namespace {

[[noreturn]] void badOption(const std::string& option, const std::string& message) {
  throw InputError("command line", option, message);
}

}  // namespace

void selectLights(Scene& scene, const RenderSettings& settings) {
  if (!settings.keptLights) return;
  const std::vector<size_t>& kept = *settings.keptLights;
  const size_t count = scene.lights.size();
  if (!kept.empty() && kept.back() >= count)
    badOption("--lights", "light " + std::to_string(kept.back()) + " does not exist: the scene has " +
                              std::to_string(count) + " light" + (count == 1 ? "" : "s"));
  std::vector<Light> lights;
  for (size_t i : kept) lights.push_back(scene.lights[i]);
  scene.lights = std::move(lights);
}

void prepareSceneForRender(Scene& scene, const RenderSettings& settings) {
  selectLights(scene, settings);
  applyRenderOrigin(scene, settings.renderOrigin, settings.camera.overrides());
}

Scene loadSceneForRender(const std::string& path, const RenderSettings& settings) {
  Scene scene = loadScene(path, settings.memory, settings.pose);
  prepareSceneForRender(scene, settings);
  return scene;
}

ClassifierSettings classifierSettings(const Scene& scene, const Camera& camera, DepthFormat depthFormat) {
  ClassifierSettings c;
  c.depthFormat = depthFormat;
  c.planes = {true, camera.projection, camera.znear, camera.zfar};
  c.scene = &scene;
  c.camera = &camera;
  return c;
}

std::string rayTreeText(const std::vector<TraceEvent>& events, glm::ivec2 pixel) {
  size_t rays = 0;
  for (const TraceEvent& e : events) rays += e.stage == TraceStage::Ray;
  if (rays == 0) return "";
  return "ray tree of pixel (" + std::to_string(pixel.x) + ", " + std::to_string(pixel.y) +
         "): " + std::to_string(rays) + " rays\n" + traceText(events);
}

FrameRenderer::FrameRenderer(const Scene& scene, const RenderSettings& s, const RasterOptions& raster,
                             const RayOptions& ray, std::shared_ptr<RayCaster> sharedCaster)
    : scene_(scene),
      renderer_(s.renderer),
      exposureScale_(float(std::exp2(s.exposure))),
      raster_(raster),
      ray_(ray),
      analysis_(analyzeScene(scene)),
      camera_(makeCamera(scene, s.camera.overrides(), s.camera.width(), s.camera.height())) {
  if (renderer_ == RendererKind::Raster) return;
  if (sharedCaster) {
    caster_ = std::move(sharedCaster);
  } else {
    const auto start = std::chrono::steady_clock::now();
    caster_ = std::make_shared<RayCaster>(scene, analysis_, s.cull);
    bvhBuildSeconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  // Bound to this camera and options in frame(), before each render.
}

FrameRenderer::~FrameRenderer() = default;

namespace {

// --exposure: premultiplied RGB times `scale`, in the image and in every
// deep layer (alpha, depth and IDs unchanged), after the renderers, so
// both renderers and the comparison see the same scaling.
void applyExposure(RenderOutput& output, float scale) {
  if (scale == 1.0f) return;
  for (glm::vec4& c : output.image.color) c = glm::vec4(glm::vec3(c) * scale, c.a);
  for (DeepSample& d : output.samples.samples) d.color = glm::vec4(glm::vec3(d.color) * scale, d.color.a);
}

}  // namespace

RenderOutput FrameRenderer::frame() {
  RenderOutput output = renderFrame();
  applyExposure(output, exposureScale_);
  return output;
}

RenderOutput FrameRenderer::renderFrame() {
  // The caster may be shared (serve) and bound to another frame's camera
  // and options since: bind this frame's (cheap next to a frame).
  if (caster_) caster_->bind(camera_, ray_);
  // Each frame reports its own rays (hybrid's shading calls the caster
  // outside RayCaster::render, which restarts them itself).
  if (caster_) caster_->resetCounters();
  switch (renderer_) {
    case RendererKind::Raster:
      return renderRaster(scene_, analysis_, camera_, raster_);
    case RendererKind::Raytrace:
      return caster_->render();
    case RendererKind::Hybrid: {
      const bool traced = raster_.shadows == RasterShadows::Traced;
      RenderOutput output =
          renderRaster(scene_, analysis_, camera_, raster_, caster_.get(), traced ? caster_.get() : nullptr);
      caster_->throwIfError();  // an Embree error in the rays the rasterizer's shading traced
      output.counters.merge(caster_->counters());
      return output;
    }
  }
  return {};
}

RenderRun renderScene(const Scene& scene, const RenderSettings& s, const MemoryEstimate* checked) {
  RasterOptions raster = s.raster;
  RayOptions ray = s.ray;
  raster.keepSamples = ray.keepSamples = s.keepSamples;
  const glm::ivec2 size(s.camera.width(), s.camera.height());
  if (s.debugPixel &&
      (s.debugPixel->x < 0 || s.debugPixel->y < 0 || s.debugPixel->x >= size.x || s.debugPixel->y >= size.y))
    badOption("--debug-pixel", "pixel lies outside the image");
  // --debug-pixel without a caller's sink: the rasterizer records into this
  // log, printed to stderr after the render (the libraries never print).
  TraceLog rasterTrace;
  if (s.debugPixel && !raster.trace.sink) raster.trace = {&rasterTrace, *s.debugPixel};
  TraceLog rayTrace;  // the ray caster's ray tree, likewise (--renderer raytrace)
  if (s.debugPixel && !ray.trace.sink) ray.trace = {&rayTrace, *s.debugPixel};
  const MemoryEstimate memory = checked ? *checked : estimateRenderMemory(scene, s);
  if (!checked) checkMemory(memory, s.memory, scene.path, "", describeRenderWork(s, toString(s.renderer)));

  const auto start = std::chrono::steady_clock::now();
  FrameRenderer renderer(scene, s, raster, ray);
  RenderRun run;
  run.camera = renderer.camera();
  run.analysis = renderer.analysis();
  run.output = renderer.frame();
  // The Embree scene (BVH) is built once per scene, whatever the camera:
  // reported apart so a sweep can tell it from the frame's own work.
  if (renderer.bvhBuildSeconds() >= 0.0)
    run.output.timings.insert(run.output.timings.begin(), {"raytrace.bvh_build", renderer.bvhBuildSeconds()});
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  run.memoryEstimate = memory;
  if (raster.trace.sink == &rasterTrace) std::fputs(rasterTrace.text().c_str(), stderr);
  if (ray.trace.sink == &rayTrace) std::fputs(rayTreeText(rayTrace.events(), *s.debugPixel).c_str(), stderr);
  return run;
}

nlohmann::json renderReportJson(const Scene& scene, const RenderSettings& s, const RenderRun& run) {
  nlohmann::json j;
  j["schema"] = "rastray.render";
  j["version"] = 1;
  j["scene"] = scene.path;
  j["renderer"] = toString(s.renderer);
  j["width"] = run.camera.width;
  j["height"] = run.camera.height;
  j["spp"] = s.spp;
  j["seconds"] = run.seconds;
  nlohmann::json counters = nlohmann::json::object();
  for (const auto& [name, value] : run.output.counters.values) counters[name] = value;
  j["counters"] = counters;
  nlohmann::json timings = nlohmann::json::object();
  for (const auto& [name, value] : run.output.timings) timings[name] = value;
  j["timings"] = timings;
  j["passesRun"] = run.output.passesRun;
  j["passesLeftOut"] = run.output.passesLeftOut;
  // The estimate checked against --max-memory before rendering, and the
  // process's measured peak so far (this render and what came before it).
  nlohmann::json parts = nlohmann::json::object();
  for (const auto& [name, bytes] : run.memoryEstimate.parts()) parts[name] = bytes;
  j["memory"] = {{"estimatedPeakBytes", run.memoryEstimate.total()},
                 {"estimatedParts", parts},
                 {"measuredPeakBytes", peakRssBytes()},
                 {"limitBytes", s.memory.bytes}};
  return j;
}

void printRenderStats(const RenderRun& run) {
  std::printf("\n%-36s %16s\n", "counter", "value");
  for (const auto& [name, value] : run.output.counters.values)
    std::printf("%-36s %16llu\n", name.c_str(), static_cast<unsigned long long>(value));
  if (!run.output.timings.empty()) {
    std::printf("\n%-36s %16s\n", "stage", "seconds");
    for (const auto& [name, value] : run.output.timings) std::printf("%-36s %16.4f\n", name.c_str(), value);
  }
  std::printf("\npasses run:\n");
  for (const std::string& p : run.output.passesRun) std::printf("  %s\n", p.c_str());
  std::printf("left out:\n");
  for (const std::string& p : run.output.passesLeftOut) std::printf("  %s\n", p.c_str());
  std::printf("\nmemory: estimated peak %s (%s); measured peak %s\n",
              formatBytes(run.memoryEstimate.total()).c_str(), run.memoryEstimate.largest(3).c_str(),
              formatBytes(peakRssBytes()).c_str());
}

}  // namespace rastray
