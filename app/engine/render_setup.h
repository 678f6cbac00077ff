// Render settings shared by `render`, `crossval` and `bench`: the options
// of both renderers, their CLI, and one function that runs a renderer on a
// scene (the composition point of hybrid rendering: app/ wires raster/ and
// raytrace/, neither knows the other).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "app/engine/cli_options.h"
#include "common/analysis.h"
#include "common/camera.h"
#include "common/gltf/loader.h"
#include "common/memory_budget.h"
#include "common/render_output.h"
#include "common/scene.h"
#include "common/trace.h"
#include "raster/rasterizer.h"
#include "raytrace/ray_caster.h"

namespace rastray {

enum class RendererKind { Raster, Raytrace, Hybrid };
const char* toString(RendererKind kind);

// A set of renderers, one bit per RendererKind.
using RendererSet = unsigned;
constexpr RendererSet rendererBit(RendererKind kind) { return 1u << unsigned(kind); }
constexpr RendererSet kAllRenderers = 0b111;

// Within its renderers, when an option applies.
enum class OptionCondition {
  Always,
  ShadowMaps,  // the renderer uses shadow maps (--shadows map)
  Wireframe,   // --wireframe is given
};

struct RenderSettings;

// One row of the render-option table: every option addRenderSettings
// registers has one, and the table alone decides both the registration and
// the refusal of an option the user gave where it does not apply.
struct RenderOptionSpec {
  const char* name;  // "--shadow-map-size"
  RendererSet renderers;
  OptionCondition condition;
  const char* help;  // nullptr: a camera option, registered with its help by CameraOptions
  // Registers the option bound to its field of `s`; nullptr for camera options.
  CLI::Option* (*add)(CLI::App& cmd, RenderSettings& s, const std::string& name, const std::string& help);
  const char* example;  // a value every renderer it applies to accepts ("" for flags)
};

// The table, in --help order.
const std::vector<RenderOptionSpec>& renderOptionTable();
// "raster and hybrid with --shadows map": where an option applies.
std::string describeWhereApplies(const RenderOptionSpec& spec);

struct RenderSettings {
  RendererKind renderer = RendererKind::Raster;
  int spp = 1;
  CameraOptions camera;
  RasterOptions raster;
  RayOptions ray;
  ShadingOptions shading;
  int threads = 0;  // 0: all cores
  bool keepSamples = false;
  std::optional<glm::ivec2> debugPixel;

  // Raw CLI values, turned into the structures above by finish().
  std::string rendererName = "raster";
  std::string transparency = "exact";
  std::string shadows;  // empty: map for raster, rays for hybrid
  std::string cull = "none", depthFormat = "float-reversed", depthFunc = "less", shadingRate = "sample";
  std::string textureFilter = "sampler";
  std::string origin = "camera", rayOffset = "error-bound", terminator = "shading-normal";
  std::string lights = "all";                     // --lights: all, none or indices "0,2"
  std::optional<std::vector<size_t>> keptLights;  // set by finish(): nullopt keeps all
  RenderOrigin renderOrigin = RenderOrigin::Camera;
  std::vector<float> polygonOffset, shadowBias;
  std::vector<int> debugPixelXY;
  std::string maxMemory;  // empty: MemoryBudget::machineDefault()
  MemoryBudget memory;    // set by finish(); loads and renders are refused above it

  // Set by addRenderSettings: each table row's CLI option (its count()
  // tells whether the user gave it), and whether the command runs every
  // renderer (crossval, explain) rather than the one --renderer names.
  std::vector<const CLI::Option*> cliOptions;
  bool allRenderers = false;

  // Validates combinations and fills the option structures; throws
  // InputError("command line", option, message). An option the user gave
  // must apply to the chosen renderer (with allRenderers: to at least one
  // of them), even when the value given is its default.
  void finish();

  // Whether a table row applies to `kind` under these settings (after
  // finish()). With allRenderers, hybrid traces shadow rays whatever
  // --shadows says: crossval compares its colours with the ray caster's.
  bool applies(const RenderOptionSpec& spec, RendererKind kind) const;
  // The shadow technique `kind` uses under these settings (after finish()).
  ShadowMode shadowModeFor(RendererKind kind) const;
};

// Registers --renderer (when `withRenderer`; crossval and explain run every
// renderer), the camera options and every row of renderOptionTable().
void addRenderSettings(CLI::App& cmd, RenderSettings& settings, bool withRenderer = true);

// Render options exactly as the command line gives them to `rastray render`
// (allRenderers false: "--renderer X" among them) or `crossval`
// (allRenderers true): registered with addRenderSettings, parsed by CLI11,
// checked and completed by RenderSettings::finish(). How the studies,
// sweep cells and serve's requests build settings in process. Throws
// InputError (file "command line") or CLI::ParseError on a bad list.
// The result's cliOptions are cleared (they point into a parser that is gone).
RenderSettings renderSettingsFrom(const std::vector<std::string>& args, bool allRenderers = false);

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
  // scene and raster.cull, shared with other FrameRenderers (serve keeps one
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
  const Scene& scene_;
  RendererKind renderer_;
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

// The ray caster's events of one pixel (TraceStage::Ray) as text under a
// "ray tree of pixel (x, y): N rays" line; empty without ray events.
std::string rayTreeText(const std::vector<TraceEvent>& events, glm::ivec2 pixel);

nlohmann::json renderReportJson(const Scene& scene, const RenderSettings& settings, const RenderRun& run);
void printRenderStats(const RenderRun& run);

}  // namespace rastray
