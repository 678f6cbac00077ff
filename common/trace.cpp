#include "common/trace.h"

#include <cstdio>

namespace rastray {

const char* toString(TraceStage stage) {
  switch (stage) {
    case TraceStage::Tile:
      return "tile";
    case TraceStage::Setup:
      return "setup";
    case TraceStage::Coverage:
      return "cover";
    case TraceStage::Depth:
      return "depth";
    case TraceStage::Alpha:
      return "alpha";
    case TraceStage::Shade:
      return "shade";
    case TraceStage::Blend:
      return "blend";
    case TraceStage::Final:
      return "final";
    case TraceStage::Ray:
      return "ray";
  }
  return "?";
}

void TraceLog::record(TraceEvent event) {
  std::lock_guard<std::mutex> lock(mutex_);
  events_.push_back(std::move(event));
}

std::vector<TraceEvent> TraceLog::events() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return events_;
}

std::string TraceLog::text() const { return traceText(events()); }

std::string traceText(const std::vector<TraceEvent>& events) {
  std::string out;
  for (const TraceEvent& e : events) {
    out += std::string(2 * size_t(e.depth > 0 ? e.depth : 0), ' ');
    out += toString(e.stage);
    if (e.sample >= 0) out += " sample " + std::to_string(e.sample);
    if (e.instance != kNoId) out += " instance " + std::to_string(e.instance);
    if (e.triangle != kNoId) out += " triangle " + std::to_string(e.triangle);
    out += ':';
    for (const auto& [name, value] : e.values) out += " " + name + " " + value;
    if (!e.outcome.empty()) out += " -> " + e.outcome;
    out += '\n';
  }
  return out;
}

std::string traceNumber(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

std::string traceVector(const glm::dvec3& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%.9g, %.9g, %.9g)", v.x + 0.0, v.y + 0.0, v.z + 0.0);
  return buf;
}

std::string traceColor(const glm::vec4& c) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%.4f, %.4f, %.4f, %.4f)", double(c.r), double(c.g), double(c.b),
                double(c.a));
  return buf;
}

}  // namespace rastray
