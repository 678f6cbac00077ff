// One pixel explained: both renderers' traces and their hits side by side.
//
// explainPixel renders the scene with the rasterizer and the ray caster,
// each given a TraceLog for the pixel (common/trace.h), and keeps the hits
// of every sample with the mismatch class of each disagreement. The text
// form is what `rastray explain` prints and crossval's report links; the
// JSON form (`rastray explain --json`) carries the same events for
// programs.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/engine/render_setup.h"
#include "common/image.h"
#include "common/trace.h"

namespace rastray {

// Layer k of one sample in both renderers.
struct ExplainedLayer {
  std::optional<DeepSample> raster, raytrace;  // nothing: that renderer has fewer layers
  std::string verdict;                         // "agree" or the mismatch class's display name
  // Distance (pixels) from the sample to the edges of each renderer's
  // triangle, given when the two disagree and that renderer hit something.
  std::optional<double> rasterEdgeDistance, raytraceEdgeDistance;
};

struct ExplainedSample {
  uint32_t index = 0;
  glm::dvec2 position{0.0};            // in pixels, (0, 0) the image's top-left corner
  std::vector<ExplainedLayer> layers;  // front to back; at least one
};

struct PixelExplanation {
  std::string scenePath;
  int x = 0, y = 0, width = 0, height = 0, spp = 0;
  std::string camera;            // Camera::describe()
  glm::dvec3 renderOrigin{0.0};  // traced positions are relative to it
  std::vector<ExplainedSample> samples;
  std::vector<TraceEvent> rasterEvents, rayEvents;  // in the order each renderer recorded them
};

// Renders with the rasterizer and the ray caster (settings must have been
// finish()ed). Throws InputError when (x, y) lies outside the image.
PixelExplanation explainPixel(const Scene& scene, const RenderSettings& settings, int x, int y);

// The explanation as `rastray explain` prints it.
std::string explanationText(const PixelExplanation& e);

// Schema "rastray.explain" version 1: pixel, image, camera, render origin,
// samples (position; layers with each renderer's hit {instance, triangle,
// depth} or null, verdict, edge distances) and, per renderer, the events
// {stage, sample, instance, triangle, depth, outcome, values}. values is an
// object of the event's named values (strings, formatted as in the text),
// in the order the renderer gave them; instance and triangle are null when
// the event names none, sample is null for the pixel or tile as a whole.
nlohmann::ordered_json explanationJson(const PixelExplanation& e);

}  // namespace rastray
