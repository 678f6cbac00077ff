#include "raster/coverage.h"

#include <string>

namespace rastray {

void traceCoverage(TraceSink& sink, const TriangleSetup& t, const SampleGrid& grid, int px, int py) {
  const int64_t U = grid.unitsPerPixel;
  const auto point = [](int64_t x, int64_t y) {
    return "(" + std::to_string(x) + ", " + std::to_string(y) + ")";
  };
  TraceEvent setup{TraceStage::Setup, -1, t.instance, t.triangle, 0, "", {}};
  if (t.fromClipping) setup.add("piece", "clipped");
  setup.add("facing", t.frontFacing ? "front" : "back").add("units", "1/" + std::to_string(U) + " px");
  for (int i = 0; i < 3; ++i) setup.add("v" + std::to_string(i), point(t.vertex[i].x, t.vertex[i].y));
  sink.record(std::move(setup));
  for (int e = 0; e < 3; ++e) {
    TraceEvent edge{TraceStage::Setup, -1, kNoId, kNoId, 1, "", {}};
    edge.add("edge", std::to_string(e))
        .add("a", std::to_string(t.edge[e].a))
        .add("b", std::to_string(t.edge[e].b))
        .add("c", std::to_string(t.edge[e].c))
        .add("rule", t.edge[e].topLeft ? "top-left (samples on it are inside)"
                                       : "right/bottom (samples on it are outside)");
    sink.record(std::move(edge));
  }
  for (int s = 0; s < grid.spp; ++s) {
    const int64_t sx = int64_t(px) * U + grid.offsets[size_t(s)].x,
                  sy = int64_t(py) * U + grid.offsets[size_t(s)].y;
    TraceEvent cover{TraceStage::Coverage, s, t.instance, t.triangle, 1, "", {}};
    bool inside = true;
    for (int e = 0; e < 3; ++e) {
      const int64_t v = t.edge[e].at(sx, sy);
      std::string value = std::to_string(v);
      if (v == 0) value += t.edge[e].topLeft ? " (on edge, kept)" : " (on edge, dropped)";
      cover.add("E" + std::to_string(e), value);
      inside = inside && v + t.edge[e].bias >= 0;
    }
    cover.outcome = inside ? "covered" : "not covered";
    sink.record(std::move(cover));
  }
}

}  // namespace rastray
