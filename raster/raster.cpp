#include "raster/raster.h"

#include <cinttypes>

namespace rastray {

void rasterDepthPass(const std::vector<TriangleSetup>& setups, const std::vector<uint32_t>& bin,
                     const SampleGrid& grid, const TileRect& rect, DepthFormat format, DepthFunc func,
                     const std::function<bool(const TriangleSetup&, int, int, int)>& alphaTest,
                     const glm::ivec2* debugPixel, DepthTarget* target, DepthPassCounters* counters) {
  CoverageScratch scratch;
  const bool keysOnly = target->winners.empty();
  for (uint32_t index : bin) {
    const TriangleSetup& t = setups[index];
    const uint64_t id = t.id();
    const bool debugHere = debugPixel && debugPixel->x >= std::max(rect.x0, t.pixelMin.x) &&
                           debugPixel->x <= std::min(rect.x1 - 1, t.pixelMax.x) &&
                           debugPixel->y >= std::max(rect.y0, t.pixelMin.y) &&
                           debugPixel->y <= std::min(rect.y1 - 1, t.pixelMax.y);
    if (debugHere) traceCoverage(stderr, t, grid, debugPixel->x, debugPixel->y);
    counters->coverageTests += forEachCoveredSample(t, grid, rect, scratch, [&](int px, int py, int s) {
      ++counters->samplesTested;
      const size_t i = target->index(px, py, s);
      const uint32_t key = sampleDepthKey(t, grid, format, px, py, s);
      const uint32_t stored = target->keys[i];
      const uint32_t winner = keysOnly ? kNoSetup : target->winners[i];
      const uint64_t storedId = winner == kNoSetup ? UINT64_MAX : setups[winner].id();
      // Keys only (shadow maps): ties change no key, so the id rule is moot.
      const bool pass = keysOnly ? key < stored : passesDepthTest(func, key, id, stored, storedId);
      const bool debug = debugHere && px == debugPixel->x && py == debugPixel->y;
      if (debug)
        std::fprintf(stderr,
                     "  depth  sample %d: instance %u triangle %u key 0x%08x vs stored 0x%08x (instance %d "
                     "triangle %d): %s\n",
                     s, t.instance, t.triangle, key, stored,
                     winner == kNoSetup ? -1 : int(setups[winner].instance),
                     winner == kNoSetup ? -1 : int(setups[winner].triangle), pass ? "pass" : "fail");
      if (!pass) return;
      if (alphaTest && !alphaTest(t, px, py, s)) {
        ++counters->alphaRejected;
        if (debug) std::fprintf(stderr, "  alpha  sample %d: below the MASK cutoff, discarded\n", s);
        return;
      }
      ++counters->samplesPassed;
      target->keys[i] = key;
      if (!keysOnly) target->winners[i] = index;
    });
  }
}

void traceCoverage(std::FILE* out, const TriangleSetup& t, const SampleGrid& grid, int px, int py) {
  const int64_t U = grid.unitsPerPixel;
  std::fprintf(out, "setup  instance %u triangle %u%s: %s-facing, vertices (units of 1/%" PRId64 " px)",
               t.instance, t.triangle, t.fromClipping ? " (clipped piece)" : "",
               t.frontFacing ? "front" : "back", U);
  for (int i = 0; i < 3; ++i) std::fprintf(out, " (%" PRId64 ", %" PRId64 ")", t.vertex[i].x, t.vertex[i].y);
  std::fprintf(out, "\n");
  for (int e = 0; e < 3; ++e)
    std::fprintf(out, "  edge %d: a %" PRId64 " b %" PRId64 " c %" PRId64 " %s\n", e, t.edge[e].a,
                 t.edge[e].b, t.edge[e].c,
                 t.edge[e].topLeft ? "top-left (samples on it are inside)"
                                   : "right/bottom (samples on it are outside)");
  for (int s = 0; s < grid.spp; ++s) {
    const int64_t sx = int64_t(px) * U + grid.offsets[size_t(s)].x,
                  sy = int64_t(py) * U + grid.offsets[size_t(s)].y;
    bool inside = true;
    std::fprintf(out, "  cover  sample %d:", s);
    for (int e = 0; e < 3; ++e) {
      const int64_t v = t.edge[e].at(sx, sy);
      std::fprintf(out, " E%d=%" PRId64 "%s", e, v,
                   v == 0 ? (t.edge[e].topLeft ? "(on edge, kept)" : "(on edge, dropped)") : "");
      inside = inside && v + t.edge[e].bias >= 0;
    }
    std::fprintf(out, " -> %s\n", inside ? "covered" : "not covered");
  }
}

}  // namespace rastray
