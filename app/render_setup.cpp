#include "app/render_setup.h"

#include <chrono>
#include <cstdio>

#include "common/error.h"
#include "common/sampling.h"

namespace rastray {

namespace {

[[noreturn]] void badOption(const std::string& option, const std::string& message) {
  throw InputError("command line", option, message);
}

template <typename Enum>
Enum pick(const std::string& option, const std::string& value,
          std::initializer_list<std::pair<const char*, Enum>> choices) {
  std::string names;
  for (const auto& [name, e] : choices) {
    if (value == name) return e;
    names += (names.empty() ? "" : ", ") + std::string(name);
  }
  badOption(option, "'" + value + "' is not one of " + names);
}

}  // namespace

const char* toString(RendererKind kind) {
  switch (kind) {
    case RendererKind::Raster:
      return "raster";
    case RendererKind::Raytrace:
      return "raytrace";
    case RendererKind::Hybrid:
      return "hybrid";
  }
  return "?";
}

void addRenderSettings(CLI::App& cmd, RenderSettings& s, bool withRenderer) {
  if (withRenderer)
    cmd.add_option("--renderer", s.rendererName,
                   "raster, raytrace or hybrid (rasterized primary visibility, traced "
                   "shadow/reflection/refraction rays)")
        ->capture_default_str();
  cmd.add_option("--spp", s.spp, "Samples per pixel: " + supportedSampleCounts())->capture_default_str();
  s.camera.addTo(cmd);
  cmd.add_option("--threads", s.threads, "Worker threads (0: all cores)")->check(CLI::Range(0, 1024));
  cmd.add_option("--debug-pixel", s.debugPixelXY, "Trace what each stage did at pixel X Y (stderr)")
      ->expected(2);
  cmd.add_option("--texture-filter", s.textureFilter,
                 "sampler (as the file says), nearest, bilinear or trilinear")
      ->capture_default_str();
  cmd.add_option("--max-depth", s.shading.maxDepth, "Deepest secondary ray (reflection/refraction)")
      ->check(CLI::Range(0, 64))
      ->capture_default_str();
  // Rasterizer.
  cmd.add_option("--cull", s.cull, "Cull single-sided triangles: back, front or none")->capture_default_str();
  cmd.add_option("--depth-format", s.depthFormat, "float-reversed, float, unorm24 or unorm16")
      ->capture_default_str();
  cmd.add_option("--depth-func", s.depthFunc, "less or lequal")->capture_default_str();
  cmd.add_option("--polygon-offset", s.polygonOffset, "FACTOR UNITS, as glPolygonOffset")->expected(2);
  cmd.add_option("--transparency", s.transparency, "sorted, peel:N or exact (per-sample fragment lists)")
      ->capture_default_str();
  cmd.add_option("--shadows", s.shadows,
                 "map (shadow maps), rays (hybrid) or none; default map, rays for hybrid");
  cmd.add_option("--shadow-map-size", s.raster.shadowMapSize, "Shadow map resolution")
      ->check(CLI::Range(16, 16384))
      ->capture_default_str();
  cmd.add_option("--shadow-bias", s.shadowBias, "CONSTANT SLOPE shadow-map depth bias")->expected(2);
  cmd.add_option("--shading-rate", s.shadingRate,
                 "sample (shade every sample) or pixel (once per pixel and "
                 "triangle, as MSAA)")
      ->capture_default_str();
  cmd.add_flag("--wireframe", s.raster.wireframe, "Draw visible triangle edges over the image");
  cmd.add_flag("--halo", s.raster.halo, "With --wireframe: gap each edge where a nearer edge crosses it");
  // Ray caster.
  cmd.add_option("--transparency-cutoff", s.ray.transparencyCutoff,
                 "Stop compositing along a ray once the remaining transmittance is below this")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  cmd.add_flag("!--no-packets", s.ray.packets,
               "Trace primary rays one by one instead of in coherent packets");
}

void RenderSettings::finish() {
  renderer = pick<RendererKind>("--renderer", rendererName,
                                {{"raster", RendererKind::Raster},
                                 {"raytrace", RendererKind::Raytrace},
                                 {"hybrid", RendererKind::Hybrid}});
  if (!isSupportedSampleCount(spp))
    badOption("--spp", std::to_string(spp) + " is not supported (use " + supportedSampleCounts() + ")");
  shading.textureFilter = pick<TextureFilter>("--texture-filter", textureFilter,
                                              {{"sampler", TextureFilter::Sampler},
                                               {"nearest", TextureFilter::Nearest},
                                               {"bilinear", TextureFilter::Bilinear},
                                               {"trilinear", TextureFilter::Trilinear}});
  if (!debugPixelXY.empty()) debugPixel = glm::ivec2(debugPixelXY[0], debugPixelXY[1]);

  raster.spp = spp;
  raster.cull = pick<CullMode>(
      "--cull", cull, {{"none", CullMode::None}, {"back", CullMode::Back}, {"front", CullMode::Front}});
  raster.depthFormat = pick<DepthFormat>("--depth-format", depthFormat,
                                         {{"float-reversed", DepthFormat::FloatReversed},
                                          {"float", DepthFormat::Float},
                                          {"unorm24", DepthFormat::Unorm24},
                                          {"unorm16", DepthFormat::Unorm16}});
  raster.depthFunc =
      pick<DepthFunc>("--depth-func", depthFunc, {{"less", DepthFunc::Less}, {"lequal", DepthFunc::LEqual}});
  if (!polygonOffset.empty()) {
    raster.polygonOffsetFactor = polygonOffset[0];
    raster.polygonOffsetUnits = polygonOffset[1];
  }
  if (transparency == "sorted") {
    raster.transparency = TransparencyMode::Sorted;
  } else if (transparency == "exact") {
    raster.transparency = TransparencyMode::Exact;
  } else if (transparency.rfind("peel:", 0) == 0) {
    raster.transparency = TransparencyMode::Peel;
    try {
      size_t used = 0;
      raster.peelLayers = std::stoi(transparency.substr(5), &used);
      if (used != transparency.size() - 5) throw std::invalid_argument("trailing characters");
    } catch (const std::exception&) {
      badOption("--transparency", "'" + transparency + "': peel needs a layer count, e.g. peel:8");
    }
    if (raster.peelLayers < 1 || raster.peelLayers > 1024)
      badOption("--transparency", "peel layer count must lie in [1, 1024]");
  } else {
    badOption("--transparency", "'" + transparency + "' is not one of sorted, peel:N, exact");
  }
  const std::string shadowName =
      shadows.empty() ? (renderer == RendererKind::Hybrid ? "rays" : "map") : shadows;
  raster.shadows =
      pick<ShadowMode>("--shadows", shadowName,
                       {{"map", ShadowMode::Map}, {"rays", ShadowMode::Rays}, {"none", ShadowMode::None}});
  if (raster.shadows == ShadowMode::Rays && renderer == RendererKind::Raster)
    badOption("--shadows", "'rays' needs --renderer hybrid or raytrace");
  if (renderer == RendererKind::Raytrace && raster.shadows == ShadowMode::Map && !shadows.empty())
    badOption("--shadows", "shadow maps are a rasterizer technique; the ray caster traces shadow rays");
  if (!shadowBias.empty()) {
    raster.shadowBiasConstant = shadowBias[0];
    raster.shadowBiasSlope = shadowBias[1];
  }
  raster.shadingRate = pick<ShadingRate>("--shading-rate", shadingRate,
                                         {{"sample", ShadingRate::Sample}, {"pixel", ShadingRate::Pixel}});
  if (raster.halo && !raster.wireframe) badOption("--halo", "needs --wireframe");
  raster.shading = shading;
  raster.debugPixel = debugPixel;
  raster.keepSamples = keepSamples;

  ray.spp = spp;
  ray.shading = shading;
  ray.debugPixel = debugPixel;
  ray.keepSamples = keepSamples;

  if (renderer == RendererKind::Raytrace) {
    // Rasterizer-only options are refused rather than silently ignored.
    if (cull != "none") badOption("--cull", "applies to the rasterizer (raster, hybrid) only");
    if (depthFormat != "float-reversed") badOption("--depth-format", "applies to the rasterizer only");
    if (depthFunc != "less") badOption("--depth-func", "applies to the rasterizer only");
    if (!polygonOffset.empty()) badOption("--polygon-offset", "applies to the rasterizer only");
    if (transparency != "exact") badOption("--transparency", "the ray caster always composites exactly");
    if (raster.wireframe) badOption("--wireframe", "applies to the rasterizer only");
  }
}

RenderRun renderScene(const Scene& scene, const RenderSettings& s) {
  RenderRun run;
  run.analysis = analyzeScene(scene);
  run.camera = makeCamera(scene, s.camera.overrides(), s.camera.width(), s.camera.height());
  RasterOptions raster = s.raster;
  RayOptions ray = s.ray;
  raster.keepSamples = ray.keepSamples = s.keepSamples;
  if (run.camera.width > 0 && s.debugPixel &&
      (s.debugPixel->x < 0 || s.debugPixel->y < 0 || s.debugPixel->x >= run.camera.width ||
       s.debugPixel->y >= run.camera.height))
    badOption("--debug-pixel", "pixel lies outside the image");

  const auto start = std::chrono::steady_clock::now();
  switch (s.renderer) {
    case RendererKind::Raster:
      run.output = renderRaster(scene, run.analysis, run.camera, raster);
      break;
    case RendererKind::Raytrace: {
      RayCaster caster(scene, run.analysis);
      caster.bind(run.camera, ray);
      run.output = caster.render();
      break;
    }
    case RendererKind::Hybrid: {
      RayCaster caster(scene, run.analysis);
      caster.bind(run.camera, ray);
      const bool traced = raster.shadows == ShadowMode::Rays;
      run.output = renderRaster(scene, run.analysis, run.camera, raster, &caster, traced ? &caster : nullptr);
      run.output.counters.merge(caster.counters());
      break;
    }
  }
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return run;
}

nlohmann::json renderReportJson(const Scene& scene, const RenderSettings& s, const RenderRun& run) {
  nlohmann::json j;
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
}

}  // namespace rastray
