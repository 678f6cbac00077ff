// Primary visibility: the image in tiles of tileSize² pixels in parallel
// (TBB). A tile runs in two phases: first every (pixel, sample) pair's
// primary ray is traced, as single rays or eight at a time in coherent
// packets (rtcIntersect8); then each ray's surfaces are collected and
// shaded (radiance.cpp, secondary rays included) and the samples are
// box-filtered into the flat image. The deep output keeps every sample's
// surfaces, per tile in one buffer, and is assembled into one flat
// DeepImage at the end.
//
// Timings (RenderOutput::timings): each tile reads the clock three times,
// and each thread sums the seconds of its tiles' two phases. The wall time
// of the tile loop is then split between "raytrace.primary" (ray setup
// and traversal of the primary rays, their filter callbacks included:
// alpha test, gathering BLEND layers) and "raytrace.shade" (surface
// lists, refinement, shading with every secondary and shadow ray, the
// tile's output) in proportion to those thread-seconds, so the two add up
// to the loop's wall time on any thread count. "raytrace.deep_output" is
// the wall time of assembling the deep image (keepSamples only).
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>

#include "common/sampling.h"
#include "raytrace/ray_caster_parts.h"

namespace rastray {

namespace {

constexpr int kPacket = 8;

using Clock = std::chrono::steady_clock;

double secondsBetween(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

struct Tile {
  int x0, y0, x1, y1;  // pixels [x0, x1) × [y0, y1)
  int width() const { return x1 - x0; }
  int height() const { return y1 - y0; }
};

// One primary sample of a tile. A tile's samples run in pixel order (then
// sample order); packets take eight consecutive ones.
struct TileSample {
  glm::ivec2 pixel;
  int sample;
};

// What one thread reuses from tile to tile (nothing is allocated per ray
// or per sample once the first tile has grown it), and the seconds its
// tiles spent in each phase.
struct TileScratch {
  std::vector<TileSample> samples;
  std::vector<HitGather> gathers;    // per sample: the traced ray and its gathered layers
  std::vector<GatheredHit> closest;  // per sample: the stopping hit
  std::vector<SurfaceCrossing> crossings;
  std::vector<glm::vec4> sum;  // per pixel of the tile
  double primarySeconds = 0.0, shadeSeconds = 0.0;

  void prepare(const Tile& tile, int spp) {
    samples.clear();
    for (int y = tile.y0; y < tile.y1; ++y)
      for (int x = tile.x0; x < tile.x1; ++x)
        for (int s = 0; s < spp; ++s) samples.push_back({{x, y}, s});
    if (gathers.size() < samples.size()) gathers.resize(samples.size());
    if (closest.size() < samples.size()) closest.resize(samples.size());
    sum.assign(size_t(tile.width() * tile.height()), glm::vec4(0.0f));
  }
};

// The deep output while tiles run: each tile's samples in one buffer in
// tile sample order (which is pixel order), and each pixel's count.
struct DeepTiles {
  std::vector<std::vector<DeepSample>> tiles;
  std::vector<uint32_t> pixelCounts;  // per image pixel
};

// Defined below, in the order the image needs them.
void renderTile(const CasterState& state, const Tile& tile, const std::vector<glm::dvec2>& positions,
                int centre, TileScratch& scratch, FlatImage* image, std::vector<DeepSample>* tileDeep,
                std::vector<uint32_t>* pixelCounts);
DeepImage assembleDeepImage(int width, int height, int tileSize, int tilesX, const DeepTiles& deep);
void tracePacket(const CasterState& state, HitGather* gathers, GatheredHit* closest, size_t n);
void setupPrimary(const CasterState& state, HitGather& g, glm::ivec2 pixel, const glm::dvec2& position);
void clearPacket(RTCRayHit8& rh, int valid[kPacket]);
void setLane(RTCRayHit8& rh, int valid[kPacket], size_t i, const Ray& ray);
GatheredHit laneHit(const RTCRayHit8& rh, size_t i);
SampleResult resolvePrimary(const CasterState& state, const RayTreeContext& context, HitGather& g,
                            const GatheredHit& closest, uint32_t sampleIndex, std::vector<DeepSample>* deep,
                            std::vector<SurfaceCrossing>* crossings);

}  // namespace

// --- the image -------------------------------------------------------------------

RenderOutput renderPrimaryVisibility(const CasterState& state) {
  const Camera& camera = state.camera;
  const RayOptions& options = state.options;
  RenderOutput out;
  out.image = FlatImage(camera.width, camera.height);
  const std::vector<glm::dvec2> positions = samplePositions(options.spp);
  const int centre = centreSampleIndex(options.spp);

  const int size = std::max(1, options.tileSize);
  const int tilesX = (camera.width + size - 1) / size, tilesY = (camera.height + size - 1) / size;
  DeepTiles deep;
  if (options.keepSamples) {
    deep.tiles.resize(size_t(tilesX) * size_t(tilesY));
    deep.pixelCounts.assign(size_t(camera.width) * size_t(camera.height), 0);
  }
  tbb::enumerable_thread_specific<TileScratch> scratch;
  const Clock::time_point start = Clock::now();
  tbb::parallel_for(tbb::blocked_range<int>(0, tilesX * tilesY), [&](const tbb::blocked_range<int>& range) {
    TileScratch& local = scratch.local();
    for (int t = range.begin(); t != range.end(); ++t) {
      const int x0 = (t % tilesX) * size, y0 = (t / tilesX) * size;
      const Tile tile{x0, y0, std::min(x0 + size, camera.width), std::min(y0 + size, camera.height)};
      renderTile(state, tile, positions, centre, local, &out.image,
                 options.keepSamples ? &deep.tiles[size_t(t)] : nullptr, &deep.pixelCounts);
    }
  });
  const double tilesWall = secondsBetween(start, Clock::now());
  double primary = 0.0, shade = 0.0;
  for (const TileScratch& local : scratch) {
    primary += local.primarySeconds;
    shade += local.shadeSeconds;
  }
  const double busy = primary + shade;
  out.timings.push_back({"raytrace.primary", busy > 0.0 ? tilesWall * primary / busy : 0.0});
  out.timings.push_back({"raytrace.shade", busy > 0.0 ? tilesWall * shade / busy : 0.0});
  if (options.keepSamples) {
    const Clock::time_point deepStart = Clock::now();
    out.hasSamples = true;
    out.samples = assembleDeepImage(camera.width, camera.height, size, tilesX, deep);
    out.timings.push_back({"raytrace.deep_output", secondsBetween(deepStart, Clock::now())});
  }
  return out;
}

bool usePackets(const CasterState& state) {
  return state.options.packets && (state.options.forcePackets || !state.analysis.transparency);
}

namespace {

void renderTile(const CasterState& state, const Tile& tile, const std::vector<glm::dvec2>& positions,
                int centre, TileScratch& scratch, FlatImage* image, std::vector<DeepSample>* tileDeep,
                std::vector<uint32_t>* pixelCounts) {
  const RayTreeContext context = untracedContext(state);
  const int spp = int(positions.size());
  scratch.prepare(tile, spp);
  const std::vector<TileSample>& samples = scratch.samples;
  const size_t n = samples.size();
  const Clock::time_point start = Clock::now();

  // Phase 1: every primary ray of the tile.
  for (size_t i = 0; i < n; ++i)
    setupPrimary(state, scratch.gathers[i], samples[i].pixel, positions[size_t(samples[i].sample)]);
  context.count(RayKind::Primary, n);
  if (!usePackets(state)) {
    for (size_t i = 0; i < n; ++i)
      scratch.closest[i] = intersectClosest(state, scratch.gathers[i], /*coherent=*/true);
  } else {
    for (size_t first = 0; first < n; first += kPacket)
      tracePacket(state, &scratch.gathers[first], &scratch.closest[first],
                  std::min(size_t(kPacket), n - first));
  }
  const Clock::time_point traced = Clock::now();

  // Phase 2: their surfaces shaded, filtered into the tile's pixels.
  FlatImage& img = *image;
  for (size_t i = 0; i < n; ++i) {
    const TileSample& s = samples[i];
    const size_t pixel = img.index(s.pixel.x, s.pixel.y);
    const size_t before = tileDeep ? tileDeep->size() : 0;
    const SampleResult r = resolvePrimary(state, context, scratch.gathers[i], scratch.closest[i],
                                          uint32_t(s.sample), tileDeep, &scratch.crossings);
    if (tileDeep) (*pixelCounts)[pixel] += uint32_t(tileDeep->size() - before);
    scratch.sum[size_t((s.pixel.y - tile.y0) * tile.width() + (s.pixel.x - tile.x0))] += r.color;
    if (s.sample == centre) {
      img.depth[pixel] = r.front.depth;
      img.instance[pixel] = r.front.instance;
      img.triangle[pixel] = r.front.triangle;
    }
  }
  for (int y = tile.y0; y < tile.y1; ++y)
    for (int x = tile.x0; x < tile.x1; ++x)
      img.color[img.index(x, y)] =
          scratch.sum[size_t((y - tile.y0) * tile.width() + (x - tile.x0))] / float(spp);
  const Clock::time_point shaded = Clock::now();
  scratch.primarySeconds += secondsBetween(start, traced);
  scratch.shadeSeconds += secondsBetween(traced, shaded);
}

// The tiles' deep samples as one DeepImage: offsets from the per-pixel
// counts, then each tile's buffer copied pixel run by pixel run (in
// parallel over tiles; every pixel's run has its own place).
DeepImage assembleDeepImage(int width, int height, int tileSize, int tilesX, const DeepTiles& deep) {
  DeepImage image;
  image.width = width;
  image.height = height;
  const size_t pixels = deep.pixelCounts.size();
  image.offsets.assign(pixels + 1, 0);
  uint64_t total = 0;
  for (size_t i = 0; i < pixels; ++i) {
    image.offsets[i] = total;
    total += deep.pixelCounts[i];
  }
  image.offsets[pixels] = total;
  image.samples.resize(total);
  tbb::parallel_for(size_t(0), deep.tiles.size(), [&](size_t t) {
    const int x0 = int(t % size_t(tilesX)) * tileSize, y0 = int(t / size_t(tilesX)) * tileSize;
    const int x1 = std::min(x0 + tileSize, width), y1 = std::min(y0 + tileSize, height);
    const std::vector<DeepSample>& buffer = deep.tiles[t];
    size_t cursor = 0;
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) {
        const size_t pixel = size_t(y) * size_t(width) + size_t(x);
        const uint32_t count = deep.pixelCounts[pixel];
        std::copy_n(buffer.begin() + std::ptrdiff_t(cursor), count,
                    image.samples.begin() + std::ptrdiff_t(image.offsets[pixel]));
        cursor += count;
      }
  });
  return image;
}

}  // namespace

// --- one sample ------------------------------------------------------------------

SampleResult tracePrimarySample(const CasterState& state, const RayTreeContext& context, glm::ivec2 pixel,
                                const glm::dvec2& position, uint32_t sampleIndex, HitGather& g,
                                std::vector<DeepSample>* deep, std::vector<SurfaceCrossing>* crossings) {
  setupPrimary(state, g, pixel, position);
  context.count(RayKind::Primary);
  const GatheredHit closest = intersectClosest(state, g, /*coherent=*/true);
  return resolvePrimary(state, context, g, closest, sampleIndex, deep, crossings);
}

namespace {

// --- 8-wide packets -----------------------------------------------------------

// Up to eight consecutive samples of a tile (rays already set up in
// `gathers`) in one coherent packet; lane i's filters gather into
// gathers[i], its stopping hit goes to closest[i].
void tracePacket(const CasterState& state, HitGather* gathers, GatheredHit* closest, size_t n) {
  alignas(32) int valid[kPacket];
  alignas(32) RTCRayHit8 rh;
  clearPacket(rh, valid);
  for (size_t i = 0; i < n; ++i) setLane(rh, valid, i, gathers[i].ray);
  GatherContext gatherContext;
  rtcInitIntersectContext(&gatherContext.embree);
  gatherContext.embree.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  gatherContext.gathers = gathers;
  {
    FlushDenormalsScope ftz;
    rtcIntersect8(valid, state.embree->handle(), &gatherContext.embree, &rh);
  }
  for (size_t i = 0; i < n; ++i) closest[i] = laneHit(rh, i);
}

// Lanes without a sample: invalid, and a harmless ray should Embree read them.
void clearPacket(RTCRayHit8& rh, int valid[kPacket]) {
  for (int i = 0; i < kPacket; ++i) {
    valid[i] = 0;
    rh.ray.org_x[i] = rh.ray.org_y[i] = rh.ray.org_z[i] = 0.0f;
    rh.ray.dir_x[i] = rh.ray.dir_y[i] = 0.0f;
    rh.ray.dir_z[i] = -1.0f;
    rh.ray.tnear[i] = 0.0f;
    rh.ray.tfar[i] = -kInf;
    rh.ray.time[i] = 0.0f;
    rh.ray.mask[i] = 0xFFFFFFFFu;
    rh.ray.id[i] = unsigned(i);
    rh.ray.flags[i] = 0;
    rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID[i] = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
    rh.hit.u[i] = rh.hit.v[i] = 0.0f;
    rh.hit.Ng_x[i] = rh.hit.Ng_y[i] = rh.hit.Ng_z[i] = 0.0f;
  }
}

void setLane(RTCRayHit8& rh, int valid[kPacket], size_t i, const Ray& ray) {
  const glm::vec3 o(ray.origin), d(ray.direction);
  valid[i] = -1;
  rh.ray.org_x[i] = o.x;
  rh.ray.org_y[i] = o.y;
  rh.ray.org_z[i] = o.z;
  rh.ray.dir_x[i] = d.x;
  rh.ray.dir_y[i] = d.y;
  rh.ray.dir_z[i] = d.z;
  rh.ray.tnear[i] = float(ray.tNear);
  rh.ray.tfar[i] = float(ray.tFar);
}

GatheredHit laneHit(const RTCRayHit8& rh, size_t i) {
  GatheredHit closest;
  if (rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID) {
    closest.traversalT = rh.ray.tfar[i];
    closest.instance = rh.hit.geomID[i];
    closest.triangle = rh.hit.primID[i];
    closest.u = rh.hit.u[i];
    closest.v = rh.hit.v[i];
  }
  return closest;
}

void setupPrimary(const CasterState& state, HitGather& g, glm::ivec2 pixel, const glm::dvec2& position) {
  g.mode = GatherMode::Radiance;
  g.primary = true;
  g.imagePosition = glm::dvec2(pixel) + position;
  g.ray = (*state.primaryRays)(g.imagePosition);
  g.hits.clear();
}

// A traced primary ray's surfaces, shaded: the sample's colour, and its
// front-most surface with the traversal depth (the Z output).
SampleResult resolvePrimary(const CasterState& state, const RayTreeContext& context, HitGather& g,
                            const GatheredHit& closest, uint32_t sampleIndex, std::vector<DeepSample>* deep,
                            std::vector<SurfaceCrossing>* crossings) {
  collectCrossings(state, g, closest, crossings);
  SampleResult r;
  if (!crossings->empty()) {
    r.front = crossings->front().refined;
    r.front.depth = crossings->front().traversalDepth;
  }
  r.color =
      shadeRay(state, context, RayKind::Primary, 0, 1.0f, g, *crossings, DeepTarget{deep, sampleIndex}).color;
  return r;
}

}  // namespace

}  // namespace rastray
