#include "app/crossval/crossval.h"

#include "app/engine/memory_estimate.h"
#include "common/interrupt.h"
#include "compare/classify.h"

namespace rastray {

CrossvalResult crossvalidate(const Scene& scene, const RenderSettings& settings,
                             const std::function<void(const std::string&)>& progress) {
  CrossvalResult r;
  r.scenePath = scene.path;
  auto say = [&](const std::string& line) {
    if (progress) progress(line);
  };

  // Three deep frames are kept until they are compared: refused up front
  // when they would not fit, not after the first two.
  const MemoryEstimate memory = estimateCrossvalMemory(scene, settings);
  checkMemory(memory, settings.memory, scene.path, "",
              "cross-validating " + std::to_string(settings.camera.width()) + "x" +
                  std::to_string(settings.camera.height()) + " at " + std::to_string(settings.spp) +
                  " spp (three deep frames)");
  RenderSettings s = settings;
  s.keepSamples = true;
  s.renderer = RendererKind::Raster;
  say("raster");
  r.raster = renderScene(scene, s, &memory);
  s.renderer = RendererKind::Raytrace;
  say("raytrace");
  r.raytrace = renderScene(scene, s, &memory);
  s.renderer = RendererKind::Hybrid;
  s.raster.shadows =
      s.ray.shadows ? RasterShadows::Traced : RasterShadows::None;  // --shadows none: none anywhere
  say("hybrid");
  r.hybrid = renderScene(scene, s, &memory);
  r.camera = r.raytrace.camera;
  r.analysis = r.raytrace.analysis;

  // Ctrl-C (common/interrupt.h) between the stages; the renderers check
  // their tiles themselves.
  throwIfInterrupted();
  say("compare");
  const ClassifierSettings classifier = classifierSettings(scene, r.camera, settings.raster.depthFormat);
  const FrameNames rasterNames{"raster", "raytrace"}, hybridNames{"hybrid", "raytrace"};
  r.rasterVsRay = compareVisibility(r.raster.output.samples, r.raytrace.output.samples, settings.spp,
                                    classifier, rasterNames);
  throwIfInterrupted();
  r.hybridVsRay = compareVisibility(r.hybrid.output.samples, r.raytrace.output.samples, settings.spp,
                                    classifier, hybridNames);
  r.rasterVsRayColor = compareColors(r.raster.output.image, r.raytrace.output.image);
  r.hybridVsRayColor = compareColors(r.hybrid.output.image, r.raytrace.output.image);
  r.hybridWhereAgree = colorWhereHitsAgree(r.hybrid.output.samples, r.raytrace.output.samples);
  r.rasterWhereAgree = colorWhereHitsAgree(r.raster.output.samples, r.raytrace.output.samples);
  return r;
}

}  // namespace rastray
