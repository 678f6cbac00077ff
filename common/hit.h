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
  float depth = std::numeric_limits<float>::infinity();  // view depth (SPEC §4), +inf: no hit
  float b1 = 0.0f;
  float b2 = 0.0f;

  bool valid() const { return instance != kNoId; }
};

}  // namespace rastray
