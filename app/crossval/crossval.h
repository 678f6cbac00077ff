// Cross-validation of the two renderers on one scene: render with the
// rasterizer, the ray caster and hybrid under identical settings in one
// process, then compare every sample and every transparency layer.
#pragma once

#include <string>
#include <vector>

#include "app/engine/render_setup.h"
#include "compare/classify.h"
#include "compare/color_metrics.h"
#include "compare/visibility.h"

namespace rastray {

struct CrossvalResult {
  std::string scenePath;
  std::string name;  // file stem, for the report
  Camera camera;
  SceneAnalysis analysis;
  RenderRun raster, raytrace, hybrid;
  VisibilityReport rasterVsRay;   // visibility, raster against the ray caster
  VisibilityReport hybridVsRay;   // visibility, hybrid against the ray caster
  ColorMetrics rasterVsRayColor;  // resolved pixels
  ColorMetrics hybridVsRayColor;
  AgreeingColorStats hybridWhereAgree;  // must be 0: identical shading inputs
  AgreeingColorStats rasterWhereAgree;
};

// Renders and compares one scene. `progress` (may be null) receives one
// short line per stage.
CrossvalResult crossvalidate(const Scene& scene, const RenderSettings& settings,
                             const std::function<void(const std::string&)>& progress);

}  // namespace rastray
