// The preliminary hit record both renderers produce for a sample (pbrt's
// and Mitsuba's split between a small hit and a full surface interaction).
//
// Barycentrics follow Embree's (u, v) convention: the hit point is
// (1 − b1 − b2)·v0 + b1·v1 + b2·v2 over the triangle's *stored* vertex
// order (common/scene.h). The compare tool compares these, not colours.
#pragma once

#include <cstdint>
#include <limits>

#include "common/scene.h"

namespace rastray {

struct SampleHit {
  uint32_t instance = kNoId;
  uint32_t triangle = kNoId;
  // View depth (SPEC §4), +inf: no hit; never a depth-buffer key. Which
  // view depth depends on where the hit comes from: the rasterizer's
  // interpolated depth (d/w ÷ 1/w at the sample, raster/tile_renderer.h),
  // the ray caster's traversal depth (Embree's t · depthPerT), or, after
  // refineHit (common/surface.h), the plane depth (the stored triangle's
  // plane along the ray, in double). On one surface they differ only by
  // rounding.
  float depth = std::numeric_limits<float>::infinity();
  float b1 = 0.0f;
  float b2 = 0.0f;

  bool valid() const { return instance != kNoId; }
};

}  // namespace rastray
