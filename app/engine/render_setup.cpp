#include "app/engine/render_setup.h"

#include <algorithm>
#include <chrono>
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

// --lights: nullopt for "all", else the indices to keep (sorted, unique;
// empty for "none"). Checked against the scene by selectLights.
std::optional<std::vector<size_t>> parseLightList(const std::string& value) {
  if (value == "all") return std::nullopt;
  std::vector<size_t> kept;
  if (value == "none") return kept;
  size_t start = 0;
  while (start <= value.size()) {
    const size_t end = std::min(value.find(',', start), value.size());
    const std::string item = value.substr(start, end - start);
    // At most 9 digits: no scene holds a billion lights, and stoul cannot overflow.
    if (item.empty() || item.size() > 9 ||
        !std::all_of(item.begin(), item.end(), [](char c) { return c >= '0' && c <= '9'; }))
      badOption("--lights", "'" + value + "' is not all, none or comma-separated light indices (e.g. 0,2)");
    kept.push_back(std::stoul(item));
    start = end + 1;
  }
  std::sort(kept.begin(), kept.end());
  kept.erase(std::unique(kept.begin(), kept.end()), kept.end());
  return kept;
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

namespace {

constexpr RendererKind kRendererKinds[] = {RendererKind::Raster, RendererKind::Raytrace,
                                           RendererKind::Hybrid};
constexpr RendererSet kRaster = rendererBit(RendererKind::Raster);
constexpr RendererSet kRaytrace = rendererBit(RendererKind::Raytrace);
constexpr RendererSet kHybrid = rendererBit(RendererKind::Hybrid);
// Rasterized primary visibility: the rasterizer alone and hybrid.
constexpr RendererSet kRasterized = kRaster | kHybrid;
// Traced rays beyond the primary hit (secondary and shadow rays): the ray
// caster and hybrid; the rasterizer alone traces none.
constexpr RendererSet kTraced = kRaytrace | kHybrid;

const char* toString(ShadowMode mode) {
  switch (mode) {
    case ShadowMode::None:
      return "none";
    case ShadowMode::Map:
      return "map";
    case ShadowMode::Rays:
      return "rays";
  }
  return "?";
}

// "raster", "raster and hybrid", "raster, raytrace and hybrid".
std::string describeRenderers(RendererSet set) {
  std::vector<std::string> names;
  for (RendererKind kind : kRendererKinds)
    if (set & rendererBit(kind)) names.push_back(toString(kind));
  std::string out;
  for (size_t i = 0; i < names.size(); ++i)
    out += (i == 0 ? "" : i + 1 == names.size() ? " and " : ", ") + names[i];
  return out;
}

// Registration of one table row: binds the option to its field of `s`.
#define RASTRAY_BIND(...)                                                                                  \
  [](CLI::App& cmd, RenderSettings& s, const std::string& name, const std::string& help) -> CLI::Option* { \
    return __VA_ARGS__;                                                                                    \
  }

const std::vector<RenderOptionSpec> kRenderOptions = {
    // Camera (SPEC §2): registered by CameraOptions, shared with info and compare.
    {"--camera", kAllRenderers, OptionCondition::Always, nullptr, nullptr},
    {"--eye", kAllRenderers, OptionCondition::Always, nullptr, nullptr},
    {"--target", kAllRenderers, OptionCondition::Always, nullptr, nullptr},
    {"--up", kAllRenderers, OptionCondition::Always, nullptr, nullptr},
    {"--yfov", kAllRenderers, OptionCondition::Always, nullptr, nullptr},
    {"--znear", kAllRenderers, OptionCondition::Always, nullptr, nullptr},
    {"--zfar", kAllRenderers, OptionCondition::Always, nullptr, nullptr},
    {"--size", kAllRenderers, OptionCondition::Always, nullptr, nullptr},
    // Every renderer.
    {"--spp", kAllRenderers, OptionCondition::Always, "Samples per pixel",
     RASTRAY_BIND(cmd.add_option(name, s.spp, help + ": " + supportedSampleCounts())->capture_default_str())},
    {"--threads", kAllRenderers, OptionCondition::Always, "Worker threads (0: all cores)",
     RASTRAY_BIND(cmd.add_option(name, s.threads, help)->check(CLI::Range(0, 1024)))},
    {"--debug-pixel", kAllRenderers, OptionCondition::Always,
     "Trace what each stage did at pixel X Y (stderr)",
     RASTRAY_BIND(cmd.add_option(name, s.debugPixelXY, help)->expected(2))},
    {"--max-memory", kAllRenderers, OptionCondition::Always,
     "Refuse (exit 2) work whose estimated peak memory exceeds this: bytes or K, M, G, T (default: 80% "
     "of physical memory)",
     RASTRAY_BIND(cmd.add_option(name, s.maxMemory, help))},
    {"--texture-filter", kAllRenderers, OptionCondition::Always,
     "sampler (as the file says), nearest, bilinear or trilinear",
     RASTRAY_BIND(cmd.add_option(name, s.textureFilter, help)->capture_default_str())},
    {"--origin", kAllRenderers, OptionCondition::Always,
     "camera (rebase the scene on the eye before rounding to float) or world (no rebasing)",
     RASTRAY_BIND(cmd.add_option(name, s.origin, help)->capture_default_str())},
    {"--lights", kAllRenderers, OptionCondition::Always,
     "Lights to keep: all, none, or indices as `info` lists them, e.g. 0,2 (none left: the eye light)",
     RASTRAY_BIND(cmd.add_option(name, s.lights, help)->capture_default_str())},
    {"--cull", kAllRenderers, OptionCondition::Always, "Cull single-sided triangles: back, front or none",
     RASTRAY_BIND(cmd.add_option(name, s.cull, help)->capture_default_str())},
    {"--shadows", kAllRenderers, OptionCondition::Always,
     "map (shadow maps: raster, hybrid), rays (raytrace, hybrid) or none (every renderer); default map, "
     "rays for raytrace and hybrid",
     RASTRAY_BIND(cmd.add_option(name, s.shadows, help))},
    // Rasterized primary visibility.
    {"--depth-format", kRasterized, OptionCondition::Always, "float-reversed, float, unorm24 or unorm16",
     RASTRAY_BIND(cmd.add_option(name, s.depthFormat, help)->capture_default_str())},
    {"--depth-func", kRasterized, OptionCondition::Always, "less or lequal",
     RASTRAY_BIND(cmd.add_option(name, s.depthFunc, help)->capture_default_str())},
    {"--polygon-offset", kRasterized, OptionCondition::Always, "FACTOR UNITS, as glPolygonOffset",
     RASTRAY_BIND(cmd.add_option(name, s.polygonOffset, help)->expected(2))},
    {"--transparency", kRasterized, OptionCondition::Always,
     "sorted, peel:N or exact (per-sample fragment lists)",
     RASTRAY_BIND(cmd.add_option(name, s.transparency, help)->capture_default_str())},
    {"--shading-rate", kRasterized, OptionCondition::Always,
     "sample (shade every sample) or pixel (once per pixel and triangle, as MSAA)",
     RASTRAY_BIND(cmd.add_option(name, s.shadingRate, help)->capture_default_str())},
    {"--wireframe", kRasterized, OptionCondition::Always, "Draw visible triangle edges over the image",
     RASTRAY_BIND(cmd.add_flag(name, s.raster.wireframe, help))},
    {"--halo", kRasterized, OptionCondition::Wireframe, "Gap each edge where a nearer edge crosses it",
     RASTRAY_BIND(cmd.add_flag(name, s.raster.halo, help))},
    {"--shadow-map-size", kRasterized, OptionCondition::ShadowMaps, "Shadow map resolution",
     RASTRAY_BIND(cmd.add_option(name, s.raster.shadowMapSize, help)
                      ->check(CLI::Range(16, 16384))
                      ->capture_default_str())},
    {"--shadow-bias", kRasterized, OptionCondition::ShadowMaps, "CONSTANT SLOPE shadow-map depth bias",
     RASTRAY_BIND(cmd.add_option(name, s.shadowBias, help)->expected(2))},
    // Traced rays.
    {"--max-depth", kTraced, OptionCondition::Always, "Deepest secondary ray (reflection/refraction)",
     RASTRAY_BIND(
         cmd.add_option(name, s.shading.maxDepth, help)->check(CLI::Range(0, 64))->capture_default_str())},
    {"--no-reflection", kTraced, OptionCondition::Always,
     "Trace no reflection ray (mirror or Fresnel); that part of the colour is black",
     RASTRAY_BIND(cmd.add_flag("!" + name, s.shading.reflection, help))},
    {"--no-refraction", kTraced, OptionCondition::Always,
     "Trace no refraction ray; that part of the colour is black",
     RASTRAY_BIND(cmd.add_flag("!" + name, s.shading.refraction, help))},
    {"--transparency-cutoff", kTraced, OptionCondition::Always,
     "Stop compositing along a ray once the remaining transmittance is below this",
     RASTRAY_BIND(cmd.add_option(name, s.ray.transparencyCutoff, help)
                      ->check(CLI::Range(0.0, 1.0))
                      ->capture_default_str())},
    {"--ray-offset", kTraced, OptionCondition::Always,
     "error-bound (from the hit's triangle, pbrt-v4) or float-ulps (from the hit point, Ray Tracing Gems "
     "ch. 6): where secondary and shadow rays start",
     RASTRAY_BIND(cmd.add_option(name, s.rayOffset, help)->capture_default_str())},
    {"--terminator", kTraced, OptionCondition::Always,
     "shading-normal (lift ray origins towards the smooth surface the vertex normals describe, Hanika "
     "2021) or none (start on the flat triangle: low-poly smooth meshes show facets in shadow edges)",
     RASTRAY_BIND(cmd.add_option(name, s.terminator, help)->capture_default_str())},
    // Traced primary rays.
    {"--no-packets", kRaytrace, OptionCondition::Always,
     "Trace primary rays one by one instead of in coherent packets",
     RASTRAY_BIND(cmd.add_flag("!" + name, s.ray.packets, help))},
};

#undef RASTRAY_BIND

}  // namespace

const std::vector<RenderOptionSpec>& renderOptionTable() { return kRenderOptions; }

std::string describeWhereApplies(const RenderOptionSpec& spec) {
  std::string out = describeRenderers(spec.renderers);
  switch (spec.condition) {
    case OptionCondition::Always:
      break;
    case OptionCondition::ShadowMaps:
      out += " with --shadows map";
      break;
    case OptionCondition::Wireframe:
      out += " with --wireframe";
      break;
  }
  return out;
}

void addRenderSettings(CLI::App& cmd, RenderSettings& s, bool withRenderer) {
  const size_t existing = cmd.get_options().size();
  s.allRenderers = !withRenderer;
  if (withRenderer)
    cmd.add_option("--renderer", s.rendererName,
                   "raster, raytrace or hybrid (rasterized primary visibility, traced "
                   "shadow/reflection/refraction rays)")
        ->capture_default_str();
  s.camera.addTo(cmd);
  s.cliOptions.clear();
  for (const RenderOptionSpec& spec : kRenderOptions) {
    if (!spec.add) {
      s.cliOptions.push_back(cmd.get_option(spec.name));
      continue;
    }
    std::string help = spec.help;
    if (spec.renderers != kAllRenderers || spec.condition != OptionCondition::Always)
      help += " [" + describeWhereApplies(spec) + "]";
    s.cliOptions.push_back(spec.add(cmd, s, spec.name, help));
  }
  // Where an option applies is never left unsaid: every option registered
  // here but --renderer has a row.
  const auto options = cmd.get_options();
  for (size_t i = existing; i < options.size(); ++i) {
    const bool listed =
        std::any_of(kRenderOptions.begin(), kRenderOptions.end(),
                    [&](const RenderOptionSpec& spec) { return options[i]->check_name(spec.name); });
    RASTRAY_CHECK(listed || options[i]->check_name("--renderer"),
                  options[i]->get_name() + " has no row in the render-option table");
  }
}

RenderSettings renderSettingsFrom(const std::vector<std::string>& args, bool allRenderers) {
  CLI::App app;
  RenderSettings settings;
  addRenderSettings(app, settings, /*withRenderer=*/!allRenderers);
  settings.allRenderers = allRenderers;
  std::vector<std::string> reversed(args.rbegin(), args.rend());  // CLI11 takes them last first
  app.parse(reversed);
  settings.finish();
  settings.cliOptions.clear();  // they point into `app`, which is about to go
  settings.camera.detach();
  return settings;
}

ShadowMode RenderSettings::shadowModeFor(RendererKind kind) const {
  const ShadowMode traced = ray.shadows ? ShadowMode::Rays : ShadowMode::None;
  if (kind == RendererKind::Raytrace) return traced;
  if (kind == RendererKind::Hybrid && allRenderers) return traced;
  return raster.shadows;
}

bool RenderSettings::applies(const RenderOptionSpec& spec, RendererKind kind) const {
  if (!(spec.renderers & rendererBit(kind))) return false;
  switch (spec.condition) {
    case OptionCondition::Always:
      return true;
    case OptionCondition::ShadowMaps:
      return shadowModeFor(kind) == ShadowMode::Map;
    case OptionCondition::Wireframe:
      return raster.wireframe;
  }
  return false;
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
  renderOrigin = pick<RenderOrigin>("--origin", origin,
                                    {{"camera", RenderOrigin::Camera}, {"world", RenderOrigin::World}});
  ray.offset = pick<RayOffsetMethod>(
      "--ray-offset", rayOffset,
      {{"error-bound", RayOffsetMethod::ErrorBound}, {"float-ulps", RayOffsetMethod::FloatUlps}});
  ray.terminator = pick<ShadowTerminator>(
      "--terminator", terminator,
      {{"shading-normal", ShadowTerminator::ShadingNormal}, {"none", ShadowTerminator::None}});
  keptLights = parseLightList(lights);
  if (!debugPixelXY.empty()) debugPixel = glm::ivec2(debugPixelXY[0], debugPixelXY[1]);
  memory = maxMemory.empty() ? MemoryBudget::machineDefault() : MemoryBudget::parse(maxMemory);

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

  // Shadows: map needs the rasterizer, rays a ray tracer, none applies to
  // every renderer (the ray caster then traces no shadow rays, nor does
  // hybrid for its secondary hits). raster.shadows is the rasterizer's
  // technique; with allRenderers, that of the rasterizer alone.
  const bool shadowsGiven = !shadows.empty();
  const RendererKind rasterizing = allRenderers ? RendererKind::Raster : renderer;
  const ShadowMode shadowMode =
      pick<ShadowMode>("--shadows",
                       shadowsGiven                          ? shadows
                       : rasterizing == RendererKind::Raster ? "map"
                                                             : "rays",
                       {{"map", ShadowMode::Map}, {"rays", ShadowMode::Rays}, {"none", ShadowMode::None}});
  const RendererSet shadowModeRenderers = shadowMode == ShadowMode::Rays   ? kTraced
                                          : shadowMode == ShadowMode::None ? kAllRenderers
                                                                           : kRasterized;
  if (!allRenderers && !(shadowModeRenderers & rendererBit(renderer)))
    badOption("--shadows", "'" + shadows + "' applies to " + describeRenderers(shadowModeRenderers) +
                               ", not to --renderer " + toString(renderer));
  raster.shadows = allRenderers && shadowMode == ShadowMode::Rays ? ShadowMode::Map : shadowMode;
  ray.shadows = shadowMode != ShadowMode::None;
  if (!shadowBias.empty()) {
    raster.shadowBiasConstant = shadowBias[0];
    raster.shadowBiasSlope = shadowBias[1];
  }
  raster.shadingRate = pick<ShadingRate>("--shading-rate", shadingRate,
                                         {{"sample", ShadingRate::Sample}, {"pixel", ShadingRate::Pixel}});
  raster.shading = shading;
  raster.keepSamples = keepSamples;

  ray.spp = spp;
  ray.shading = shading;
  ray.keepSamples = keepSamples;

  // Options given where they do not apply are refused, not ignored; given
  // means given (count()), so the default value given to the wrong
  // renderer is refused too.
  for (size_t i = 0; i < kRenderOptions.size() && i < cliOptions.size(); ++i) {
    const RenderOptionSpec& spec = kRenderOptions[i];
    if (!cliOptions[i] || cliOptions[i]->count() == 0) continue;
    const std::string where = "applies to " + describeWhereApplies(spec);
    if (allRenderers) {
      if (std::none_of(std::begin(kRendererKinds), std::end(kRendererKinds),
                       [&](RendererKind kind) { return applies(spec, kind); }))
        badOption(spec.name, where + ", and none of the renderers here " +
                                 (spec.condition == OptionCondition::ShadowMaps ? "uses shadow maps"
                                                                                : "draws a wireframe"));
    } else if (!applies(spec, renderer)) {
      std::string context;
      if (spec.renderers & rendererBit(renderer))
        context = spec.condition == OptionCondition::ShadowMaps
                      ? std::string(" with --shadows ") + toString(shadowModeFor(renderer))
                      : std::string(" without --wireframe");
      badOption(spec.name, where + ", not to --renderer " + toString(renderer) + context);
    }
  }
}

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
  Scene scene = loadScene(path, settings.memory);
  prepareSceneForRender(scene, settings);
  return scene;
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
      raster_(raster),
      ray_(ray),
      analysis_(analyzeScene(scene)),
      camera_(makeCamera(scene, s.camera.overrides(), s.camera.width(), s.camera.height())) {
  if (renderer_ == RendererKind::Raster) return;
  if (sharedCaster) {
    caster_ = std::move(sharedCaster);
  } else {
    const auto start = std::chrono::steady_clock::now();
    caster_ = std::make_shared<RayCaster>(scene, analysis_, raster.cull);
    bvhBuildSeconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  // Bound to this camera and options in frame(), before each render.
}

FrameRenderer::~FrameRenderer() = default;

RenderOutput FrameRenderer::frame() {
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
      const bool traced = raster_.shadows == ShadowMode::Rays;
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
