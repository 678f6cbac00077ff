// A tile's pipeline: pass 1 → deferred shading → pass 2 → compositing →
// resolve (→ hits, deep samples), and the helpers every pass samples
// triangles with.
#include "raster/tile_renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <string>

#include "common/sampling.h"

namespace rastray {

ThreadCounters& ThreadCounters::operator+=(const ThreadCounters& other) {
  opaque.coverageTests += other.opaque.coverageTests;
  opaque.samplesTested += other.opaque.samplesTested;
  opaque.samplesPassed += other.opaque.samplesPassed;
  opaque.alphaRejected += other.opaque.alphaRejected;
  blendCoverageTests += other.blendCoverageTests;
  blendSamplesTested += other.blendSamplesTested;
  fragmentsTransparent += other.fragmentsTransparent;
  shadedSamples += other.shadedSamples;
  refinedSamples += other.refinedSamples;
  peelPasses += other.peelPasses;
  depthSeconds += other.depthSeconds;
  shadeSeconds += other.shadeSeconds;
  transparencySeconds += other.transparencySeconds;
  resolveSeconds += other.resolveSeconds;
  return *this;
}

TileRenderer::TileRenderer(const Scene& scene, const SceneAnalysis& analysis, const Camera& camera,
                           const RasterOptions& options, const Shader& shader, const SampleGrid& grid,
                           const std::vector<TriangleSetup>& setups, const RefinePlane* planes)
    : scene_(scene),
      analysis_(analysis),
      camera_(camera),
      options_(options),
      shader_(shader),
      grid_(grid),
      setups_(setups),
      planes_(planes),
      rays_(camera),
      primaryConstants_(camera),
      centre_(centreSampleIndex(options.spp)),
      refinesHits_(PrimaryHitShader(shader, shadingPath()).needsHitInputs()) {}

namespace {

// Sets the tile's samples of the depth target to the cleared state (far
// key, no winner): reused storage holds the previous frame's.
void clearTileTarget(const TileRect& rect, DepthTarget* target) {
  const size_t width = size_t(rect.x1 - rect.x0) * size_t(target->spp);
  for (int y = rect.y0; y < rect.y1; ++y) {
    const size_t first = target->index(rect.x0, y, 0);
    std::fill_n(target->keys.begin() + ptrdiff_t(first), width, kClearDepthKey);
    if (!target->winners.empty()) std::fill_n(target->winners.begin() + ptrdiff_t(first), width, kNoSetup);
  }
}

// The tile's samples and its tile-local depth target, kept per thread so
// a tile allocates nothing once they have grown; a tile that finds them in
// use (a nested tile on the same thread) takes its own.
struct SampleScratch {
  TileSamples samples;
  DepthTarget target;
  bool busy = false;
};

// `target` as the depth target of `rect` alone, cleared: a tile's keys and
// winners stay in the core's caches, and no frame-sized target is filled
// or written back.
void makeTileTarget(const TileRect& rect, int spp, DepthTarget* target) {
  target->width = rect.x1 - rect.x0;
  target->height = rect.y1 - rect.y0;
  target->spp = spp;
  target->x0 = rect.x0;
  target->y0 = rect.y0;
  const size_t n = size_t(target->width) * size_t(target->height) * size_t(spp);
  // Both cleared values are all ones: a memset (vector::assign filled
  // them one element at a time).
  static_assert(kClearDepthKey == 0xFFFFFFFFu && kNoSetup == 0xFFFFFFFFu, "all-ones clear values");
  target->keys.resize(n);
  target->winners.resize(n);
  std::memset(target->keys.data(), 0xFF, n * sizeof(uint32_t));
  std::memset(target->winners.data(), 0xFF, n * sizeof(uint32_t));
}

}  // namespace

void TileRenderer::render(const TileRect& rect, const TileBins& bins, DepthTarget* frameTarget,
                          bool clearTarget, const TileOutputs& out, ThreadCounters& n) const {
  thread_local SampleScratch scratch;
  DepthTarget ownTarget;
  const bool reuse = !scratch.busy;
  DepthTarget* target = frameTarget;
  if (!target) {
    target = reuse ? &scratch.target : &ownTarget;
    makeTileTarget(rect, grid_.spp, target);
  } else if (clearTarget) {
    clearTileTarget(rect, target);
  }
  const TileSampleIndex index{rect, grid_.spp};
  // The one trace check of the tile: an empty request unless the traced
  // pixel lies here.
  const TraceRequest& asked = options_.trace;
  const bool traced = asked.sink && asked.pixel.x >= rect.x0 && asked.pixel.x < rect.x1 &&
                      asked.pixel.y >= rect.y0 && asked.pixel.y < rect.y1;
  const TraceRequest trace = traced ? asked : TraceRequest{};
  if (traced) {
    trace.sink->record(TraceEvent{TraceStage::Tile, -1, kNoId, kNoId, 0, "", {}}
                           .add("rect", "[" + std::to_string(rect.x0) + ", " + std::to_string(rect.x1) +
                                            ") x [" + std::to_string(rect.y0) + ", " +
                                            std::to_string(rect.y1) + ")")
                           .add("opaque_mask_binned", std::to_string(bins.opaque.size()))
                           .add("blend_binned", std::to_string(bins.blend ? bins.blend->size() : size_t(0))));
  }

  using Clock = std::chrono::steady_clock;
  const auto seconds = [](Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double>(b - a).count();
  };
  const Clock::time_point t0 = Clock::now();
  opaquePass(rect, bins.opaque, trace, target, n);
  const Clock::time_point t1 = Clock::now();
  TileSamples own;
  TileSamples& samples = reuse ? scratch.samples : own;
  scratch.busy = true;
  struct Release {
    SampleScratch& s;
    bool reused;
    ~Release() {
      if (reused) s.busy = false;
    }
  } release{scratch, reuse};
  // The lean form where the tile's results are only its pixels.
  samples.lean = !out.hits && !out.deep && !traced && !(bins.blend && !bins.blend->empty());
  shadeVisible(index, *target, trace, out.hits != nullptr, samples, n);
  const Clock::time_point t2 = Clock::now();
  std::vector<BlendLayer> layers;
  if (bins.blend && !bins.blend->empty()) layers = transparencyPass(index, *bins.blend, *target, n);
  const std::vector<glm::vec4> opaqueColor = compositeLayers(layers, &samples);
  if (traced) traceLayersAndFinal(index, trace, layers, samples);
  const Clock::time_point t3 = Clock::now();

  if (samples.lean)
    resolveTileLean(rect, grid_.spp, centre_, samples, *target, setups_.data(), out.image);
  else
    resolveTile(rect, grid_.spp, centre_, samples, out.image);
  if (out.hits) copyHits(index, samples, out.hits);
  if (out.deep)
    appendDeepSamples(index, layers, *target, opaqueColor.empty() ? samples.color : opaqueColor, out);
  n.depthSeconds += seconds(t0, t1);
  n.shadeSeconds += seconds(t1, t2);
  n.transparencySeconds += seconds(t2, t3);
  n.resolveSeconds += seconds(t3, Clock::now());
}

SampleHit TileRenderer::interpolatedHit(const TriangleSetup& t, const glm::dvec2& pos) const {
  return interpolatedSampleHit(t, pos);
}

// The depth that orders BLEND layers: the view depth of the stored
// triangle's plane along the primary ray (intersectTrianglePlane, double),
// the key the ray caster sorts its layers by, so both renderers order
// layers alike, and coincident duplicates tie exactly and fall back to
// (instance, triangle). The interpolated depth when the plane is missed.
double TileRenderer::planeDepth(const TriangleSetup& t, const glm::dvec2& pos) const {
  const Ray ray = rays_(pos);
  double th;
  glm::dvec2 b;
  if (intersectTrianglePlane(scene_, t.instance, t.triangle, ray, &th, &b) && th > 0.0) {
    const double d = th * ray.depthPerT;
    if (std::isfinite(d)) return d;
  }
  return t.viewDepthAt(pos.x, pos.y);
}

// The same inputs the ray caster shades from: the hit refined on the
// stored triangle's plane along the primary ray through `pos`.
SurfacePoint TileRenderer::surfaceAt(const SampleHit& hit, const glm::dvec2& pos, Ray* ray) const {
  *ray = rays_(pos);
  return makeSurfacePoint(scene_, refineHit(scene_, *ray, hit));
}

TextureFootprint TileRenderer::footprint(const SurfacePoint& p, const glm::dvec2& pos) const {
  return analysis_.textures ? pixelFootprint(scene_, camera_, p, pos) : TextureFootprint{};
}

glm::vec4 TileRenderer::shadeAt(const SampleHit& hit, const glm::dvec2& pos, const glm::dvec2& footprintPos,
                                ThreadCounters& n) const {
  // One hit through the kernel: its rule (BLEND and tracing materials to
  // Shader::shade) picks the path, as for the ray caster's same hit.
  const ShadeHit request = refinePrimaryHit(scene_, rays_(pos), hit, footprintPos);
  glm::vec4 c;
  shadePrimaryHits(shader_, &request, 1, &c, shadingPath());
  ++n.shadedSamples;
  ++n.refinedSamples;
  return c;
}

bool TileRenderer::alphaCovered(const TriangleSetup& t, int px, int py, int s) const {
  const Material& m = scene_.materialOf(t.instance);
  if (m.alphaMode != AlphaMode::Mask) return true;
  const glm::dvec2 pos = glm::dvec2(px, py) + grid_.positions[size_t(s)];
  Ray ray;
  const SurfacePoint p = surfaceAt(interpolatedHit(t, pos), pos, &ray);
  return shader_.coverageAlpha(p, footprint(p, pos)) >= m.alphaCutoff;
}

glm::dvec2 TileRenderer::samplePosition(const TileSampleIndex& index, uint32_t local) const {
  return glm::dvec2(index.pixel(local)) + grid_.positions[size_t(index.sample(local))];
}

}  // namespace rastray
