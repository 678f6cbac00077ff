// The triangle-order z-buffer rasterizer: transform → clip → screen map →
// triangle setup → per-sample coverage and depth test → shading →
// compositing → resolve, every stage explicit and testable on its own
// (clip.h, setup.h, raster.h, resolve.h).
#pragma once

#include <glm/glm.hpp>
#include <optional>
#include <vector>

#include "common/analysis.h"
#include "common/cull.h"
#include "common/camera.h"
#include "common/hit.h"
#include "common/render_output.h"
#include "common/scene.h"
#include "common/shading.h"

namespace rastray {

enum class DepthFormat { FloatReversed, Float, Unorm24, Unorm16 };  // precision: depth.h
// Equal depths are decided by (instance, triangle) as if submitted in that
// order: Less keeps the lower id, LEqual lets the higher win (depth.h).
enum class DepthFunc { Less, LEqual };
enum class TransparencyMode { Sorted, Peel, Exact };
enum class ShadowMode { None, Map, Rays };  // Rays: hybrid only (traced shadow rays)
enum class ShadingRate { Pixel, Sample };

struct RasterOptions {
  int spp = 1;
  CullMode cull = CullMode::None;
  DepthFormat depthFormat = DepthFormat::FloatReversed;
  DepthFunc depthFunc = DepthFunc::Less;
  float polygonOffsetFactor = 0.0f;  // glPolygonOffset semantics; positive pushes away
  float polygonOffsetUnits = 0.0f;
  TransparencyMode transparency = TransparencyMode::Exact;
  int peelLayers = 8;  // Peel: layers kept per sample; those behind are dropped
  ShadowMode shadows = ShadowMode::Map;
  int shadowMapSize = 2048;         // texels per side (per cube face for point lights)
  float shadowBiasConstant = 1.0f;  // in depth-format units, as glPolygonOffset's
  float shadowBiasSlope = 1.0f;     // × the occluder's max depth slope per texel
  // Sample: shade every visible sample; Pixel: once per pixel and triangle
  // at its first covered sample, with the pixel centre's texture footprint.
  ShadingRate shadingRate = ShadingRate::Sample;
  bool wireframe = false;
  bool halo = false;         // with wireframe: gap lines where a nearer line crosses them
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

// renderRaster that also returns, per sample ((y·width + x)·spp + s), the
// rasterizer's own hit of the nearest visible surface (front-most layer,
// else the opaque surface; SampleHit{} where nothing): depth and (b1, b2)
// from the perspective-correct interpolation of 1/w, before the shading
// refinement. For tests and sample-by-sample comparison.
RenderOutput renderRasterWithHits(const Scene& scene, const SceneAnalysis& analysis, const Camera& camera,
                                  const RasterOptions& options, std::vector<SampleHit>* hits,
                                  const SecondaryRayTracer* secondary = nullptr,
                                  const LightVisibility* visibility = nullptr);

}  // namespace rastray
