// What the rasterizer is asked to do: RasterOptions and its enums. Its own
// header so the stage headers (depth.h, setup.h, shadow_map.h) need not
// include the top-level rasterizer.h for an enum.
#pragma once

#include "common/cull.h"
#include "common/depth_formula.h"
#include "common/interrupt.h"
#include "common/shading.h"
#include "common/trace.h"

namespace rastray {

class RasterFrameBuffers;  // raster/frame_buffers.h

// DepthFormat (what the depth buffer stores, its precision): common/depth_formula.h.
// Equal depths are decided by (instance, triangle) as if submitted in that
// order: Less keeps the lower id, LEqual lets the higher win (depth.h).
enum class DepthFunc { Less, LEqual };
enum class TransparencyMode { Sorted, Peel, Exact };
// Where the camera pass learns whether a light reaches a point: nowhere
// (all lit), its own shadow maps, or the LightVisibility its caller passes
// (hybrid: the ray caster's shadow rays). The user's --shadows value is the
// engine's ShadowMode (app/engine/render_options.h).
enum class RasterShadows { None, Map, Traced };
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
  RasterShadows shadows = RasterShadows::Map;
  int shadowMapSize = 1024;         // texels per side (per cube face for point lights); docs/SHADOWS.md
  float shadowBiasConstant = 1.0f;  // in depth-format units, as glPolygonOffset's
  float shadowBiasSlope = 1.0f;     // × the occluder's max depth slope per texel
  // Sample: shade every visible sample; Pixel: once per pixel and triangle
  // at its first covered sample, with the pixel centre's texture footprint.
  ShadingRate shadingRate = ShadingRate::Sample;
  bool wireframe = false;
  bool halo = false;         // with wireframe: gap lines where a nearer line crosses them
  bool keepSamples = false;  // fill RenderOutput::samples (deep output, crossval)
  // The camera passes walk coverage with the scalar reference loop instead
  // of the block-classified one (raster/coverage.h); the results are
  // identical, only slower. For the tests that prove it.
  bool referenceCoverage = false;
  ShadingOptions shading;
  // Records what each stage did at one pixel into trace.sink (common/trace.h):
  // tile, setup and edge functions, coverage, depth and MASK tests, shading,
  // blend layers, final colours. Checked once per tile; no sink, no cost.
  TraceRequest trace;
  // Stops the render at its next tile when cancelled (common/interrupt.h);
  // nullptr: a signal alone stops it. Must outlive the render.
  const CancelToken* cancel = nullptr;
  // Buffers kept between frames (raster/frame_buffers.h) by a caller that
  // renders frame after frame and hands each image back; null: every frame
  // allocates its own. The picture is the same either way.
  RasterFrameBuffers* frameBuffers = nullptr;
};

}  // namespace rastray
