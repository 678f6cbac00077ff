// What a renderer did at one pixel, as events: the trace behind `explain`,
// `--debug-pixel` and its JSON form. The libraries (common, raster,
// raytrace, compare) never print; a renderer given a TraceRequest records
// events into its sink, and app/ decides how to show them.
//
// Cost: a renderer checks `trace.sink && pixel == trace.pixel` once per
// tile (or per ray tree) and does nothing else when no trace is asked for;
// no globals, no thread-locals.
#pragma once

#include <cstdint>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "common/scene.h"

namespace rastray {

// Pipeline stage an event belongs to, in pipeline order.
enum class TraceStage {
  Tile,      // raster: the tile holding the pixel, what was binned into it
  Setup,     // raster: a triangle's fixed-point setup and edge functions
  Coverage,  // raster: edge function values at a sample, covered or not
  Depth,     // raster: the depth test at a sample
  Alpha,     // raster: MASK test
  Shade,     // a shaded sample or layer
  Blend,     // raster: a transparency layer composited
  Final,     // the sample's final colour
  Ray,       // ray caster: one ray of the ray tree
};
const char* toString(TraceStage stage);

// One event. `values` are named, already formatted with the precision that
// matters for them (fixed-point units, 9 significant digits for depths), in
// the order a person reads them; programs read the same pairs from JSON.
struct TraceEvent {
  TraceStage stage = TraceStage::Tile;
  int sample = -1;  // sample index within the pixel; -1: the pixel or tile as a whole
  uint32_t instance = kNoId, triangle = kNoId;
  int depth = 0;        // ray depth (primary 0), or nesting for indentation
  std::string outcome;  // short: "covered", "pass", "fail", "blocked", "hit", ""
  std::vector<std::pair<std::string, std::string>> values;

  TraceEvent& add(std::string name, std::string value) {
    values.emplace_back(std::move(name), std::move(value));
    return *this;
  }
};

// Receives events. Renderers may record from worker threads; a sink must
// accept concurrent record() calls.
class TraceSink {
 public:
  virtual ~TraceSink() = default;
  virtual void record(TraceEvent event) = 0;
};

// One line per event: "<stage> [sample s] [instance i triangle t]: name v ... -> outcome",
// indented by depth; what `explain` and `--debug-pixel` print.
std::string traceText(const std::vector<TraceEvent>& events);

// Keeps the events in arrival order (thread-safe). The order within one
// thread is the order the renderer did things; the traced pixel's work runs
// on one thread per pass, so a pixel's log reads top-down.
class TraceLog : public TraceSink {
 public:
  void record(TraceEvent event) override;
  std::vector<TraceEvent> events() const;
  // traceText(events()).
  std::string text() const;

 private:
  mutable std::mutex mutex_;
  std::vector<TraceEvent> events_;
};

// What a caller asks a renderer to trace: one pixel into one sink. A
// default-constructed request traces nothing.
struct TraceRequest {
  TraceSink* sink = nullptr;
  glm::ivec2 pixel{-1, -1};
  bool at(int x, int y) const { return sink && pixel.x == x && pixel.y == y; }
  explicit operator bool() const { return sink != nullptr; }
};

// Formatting shared by the emitters: "%.9g", "(%.9g, %.9g, %.9g)".
std::string traceNumber(double v);
std::string traceVector(const glm::dvec3& v);
std::string traceColor(const glm::vec4& c);  // "(%.4f, %.4f, %.4f, %.4f)"

}  // namespace rastray
