#include "raster/coverage.h"

#include <cstdio>
#include <string>

namespace rastray {

namespace {

std::string hexKey(uint32_t key) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08x", key);
  return buf;
}

// Whether the traced pixel lies in t's pixel bounds within the tile.
bool tracedIn(const TraceRequest& trace, const TriangleSetup& t, const TileRect& rect) {
  return trace.sink && trace.pixel.x >= std::max(rect.x0, t.pixelMin.x) &&
         trace.pixel.x <= std::min(rect.x1 - 1, t.pixelMax.x) &&
         trace.pixel.y >= std::max(rect.y0, t.pixelMin.y) &&
         trace.pixel.y <= std::min(rect.y1 - 1, t.pixelMax.y);
}

// The depth test at a sample: the fragment's key against the stored key and
// the setup that wrote it (instance and triangle -1 when nothing did).
void traceDepthTest(TraceSink& sink, const std::vector<TriangleSetup>& setups, const TriangleSetup& t, int s,
                    uint32_t key, uint32_t stored, uint32_t winner, bool pass) {
  TraceEvent e{TraceStage::Depth, s, t.instance, t.triangle, 1, pass ? "pass" : "fail", {}};
  e.add("key", hexKey(key)).add("stored", hexKey(stored));
  e.add("stored_instance", winner == kNoSetup ? "-1" : std::to_string(setups[winner].instance));
  e.add("stored_triangle", winner == kNoSetup ? "-1" : std::to_string(setups[winner].triangle));
  sink.record(std::move(e));
}

}  // namespace

void rasterDepthPass(const std::vector<TriangleSetup>& setups, const std::vector<uint32_t>& bin,
                     const SampleGrid& grid, const TileRect& rect, DepthFormat format, DepthFunc func,
                     const std::function<bool(const TriangleSetup&, int, int, int)>& alphaTest,
                     const TraceRequest& trace, DepthTarget* target, DepthPassCounters* counters) {
  CoverageScratch scratch;
  const bool keysOnly = target->winners.empty();
  for (uint32_t index : bin) {
    const TriangleSetup& t = setups[index];
    const uint64_t id = t.id();
    const bool traceHere = tracedIn(trace, t, rect);
    if (traceHere) traceCoverage(*trace.sink, t, grid, trace.pixel.x, trace.pixel.y);
    counters->coverageTests += forEachCoveredSample(t, grid, rect, scratch, [&](int px, int py, int s) {
      ++counters->samplesTested;
      const size_t i = target->index(px, py, s);
      const uint32_t key = sampleDepthKey(t, grid, format, px, py, s);
      const uint32_t stored = target->keys[i];
      const uint32_t winner = keysOnly ? kNoSetup : target->winners[i];
      const uint64_t storedId = winner == kNoSetup ? UINT64_MAX : setups[winner].id();
      // Keys only (shadow maps): ties change no key, so the id rule is moot.
      const bool pass = keysOnly ? key < stored : passesDepthTest(func, key, id, stored, storedId);
      const bool traced = traceHere && px == trace.pixel.x && py == trace.pixel.y;
      if (traced) traceDepthTest(*trace.sink, setups, t, s, key, stored, winner, pass);
      if (!pass) return;
      if (alphaTest && !alphaTest(t, px, py, s)) {
        ++counters->alphaRejected;
        if (traced)
          trace.sink->record(TraceEvent{TraceStage::Alpha, s, t.instance, t.triangle, 1, "discarded", {}}.add(
              "coverage", "below the MASK cutoff"));
        return;
      }
      ++counters->samplesPassed;
      target->keys[i] = key;
      if (!keysOnly) target->winners[i] = index;
    });
  }
}

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
