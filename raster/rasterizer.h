// The triangle-order z-buffer rasterizer: transform → clip → screen map →
// triangle setup → per-sample coverage and depth test → shading →
// compositing → resolve, every stage explicit and testable on its own
// (clip.h, setup.h, raster.h, resolve.h).
#pragma once

#include <optional>

#include <glm/glm.hpp>

#include "common/analysis.h"
#include "common/camera.h"
#include "common/render_output.h"
#include "common/scene.h"
#include "common/shading.h"

namespace rastray {

enum class CullMode { None, Back, Front };        // applies to single-sided materials only
enum class DepthFormat { FloatReversed, Float, Unorm24, Unorm16 };
enum class DepthFunc { Less, LEqual };
enum class TransparencyMode { Sorted, Peel, Exact };
enum class ShadowMode { None, Map, Rays };        // Rays: hybrid only (traced shadow rays)
enum class ShadingRate { Pixel, Sample };

struct RasterOptions {
  int spp = 1;
  CullMode cull = CullMode::None;
  DepthFormat depthFormat = DepthFormat::FloatReversed;
  DepthFunc depthFunc = DepthFunc::Less;
  float polygonOffsetFactor = 0.0f;  // glPolygonOffset semantics
  float polygonOffsetUnits = 0.0f;
  TransparencyMode transparency = TransparencyMode::Exact;
  int peelLayers = 8;
  ShadowMode shadows = ShadowMode::Map;
  int shadowMapSize = 2048;
  float shadowBiasConstant = 1.0f;  // in depth-format units, as glPolygonOffset's
  float shadowBiasSlope = 1.0f;
  ShadingRate shadingRate = ShadingRate::Sample;
  bool wireframe = false;
  bool halo = false;
  bool keepSamples = false;  // fill RenderOutput::samples (deep output, crossval)
  ShadingOptions shading;
  std::optional<glm::ivec2> debugPixel;  // print what each stage did at this pixel (stderr)
};

// Renders the scene. With `secondary` and `visibility` from the ray caster
// this is the hybrid renderer: rasterized primary visibility, traced
// shadow, reflection and refraction rays (shadows must then be Rays).
// Throws InputError for options that make no sense together.
RenderOutput renderRaster(const Scene& scene, const SceneAnalysis& analysis, const Camera& camera,
                          const RasterOptions& options, const SecondaryRayTracer* secondary = nullptr,
                          const LightVisibility* visibility = nullptr);

}  // namespace rastray
