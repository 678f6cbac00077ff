// Render settings shared by `render`, `crossval` and `bench`: the options
// of both renderers, their CLI, and one function that runs a renderer on a
// scene (the composition point of hybrid rendering: app/ wires raster/ and
// raytrace/, neither knows the other).
#pragma once

#include <optional>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "app/cli_options.h"
#include "common/analysis.h"
#include "common/camera.h"
#include "common/render_output.h"
#include "common/scene.h"
#include "raster/rasterizer.h"
#include "raytrace/ray_caster.h"

namespace rastray {

enum class RendererKind { Raster, Raytrace, Hybrid };
const char* toString(RendererKind kind);

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
  std::vector<float> polygonOffset, shadowBias;
  std::vector<int> debugPixelXY;

  // Validates combinations and fills the option structures; throws
  // InputError("command line", option, message).
  void finish();
};

// `withRenderer`: whether --renderer is an option (crossval runs all three).
void addRenderSettings(CLI::App& cmd, RenderSettings& settings, bool withRenderer = true);

struct RenderRun {
  Camera camera;
  SceneAnalysis analysis;
  RenderOutput output;
  double seconds = 0.0;
};

// Runs the chosen renderer; settings.finish() must have been called.
RenderRun renderScene(const Scene& scene, const RenderSettings& settings);

nlohmann::json renderReportJson(const Scene& scene, const RenderSettings& settings, const RenderRun& run);
void printRenderStats(const RenderRun& run);

}  // namespace rastray
