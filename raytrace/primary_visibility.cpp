// Primary visibility: the image in tiles of tileSize² pixels in parallel
// (TBB). A tile runs in two phases: first every (pixel, sample) pair's
// primary ray is traced, as single rays or in coherent packets of 4, 8 or
// 16 (rtcIntersect4/8/16) in Morton order; then each ray's surfaces are
// collected and shaded (radiance.cpp, secondary rays included) and the
// samples are box-filtered into the flat image. A ray that gathered no
// BLEND layer (every ray of an opaque scene) is shaded straight from its
// stopping hit when neither deep output nor a ray tree is wanted
// (stoppingSurface: the surface list's result, bit for bit, without
// the list; ≈ 4 % of the frame on the CAD model), those of a tile in one
// batch through the shading kernel (common/shading_kernel.h). The deep output keeps
// every sample's surfaces, per tile in one buffer, and is assembled into
// one flat DeepImage at the end.
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

#include <algorithm>
#include <chrono>

#include "common/interrupt.h"
#include "common/parallel.h"
#include "common/primary_refinement.h"
#include "common/sampling.h"
#include "raytrace/ray_caster_parts.h"

namespace rastray {

namespace {

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
// sample order); packets take them in traceOrder.
struct TileSample {
  glm::ivec2 pixel;
  int sample;
};

void traceOrder(int width, int height, int spp, std::vector<uint32_t>* order);

// What one thread reuses from tile to tile (nothing is allocated per ray
// or per sample once the first tile has grown it), and the seconds its
// tiles spent in each phase.
struct TileScratch {
  std::vector<TileSample> samples;
  std::vector<HitGather> gathers;    // per sample: the traced ray and its gathered layers
  std::vector<GatheredHit> closest;  // per sample: the stopping hit
  std::vector<SurfaceCrossing> crossings;
  std::vector<glm::vec4> sum;  // per pixel of the tile
  // Phase 2: each sample's result, and the stopping hits shaded as one
  // batch by the shading kernel (the samples they belong to, their colours).
  std::vector<SampleResult> results;
  std::vector<uint32_t> stoppingSamples;  // the samples resolved from their stopping hit
  std::vector<Ray> stoppingRays;          // their primary rays, hits (Embree's) and footprint positions
  std::vector<SampleHit> stoppingHits;
  std::vector<glm::dvec2> stoppingFootprints;
  std::vector<ShadeHit> stoppingRefined;  // refined (refinePrimaryHits), then shaded
  std::vector<glm::vec4> stoppingColors;
  // The packets' trace order (traceOrder) for tiles of orderSize × orderSpp.
  std::vector<uint32_t> order;
  glm::ivec2 orderSize{0};
  int orderSpp = 0;
  double primarySeconds = 0.0, shadeSeconds = 0.0;

  void prepare(const Tile& tile, int spp) {
    samples.clear();
    for (int y = tile.y0; y < tile.y1; ++y)
      for (int x = tile.x0; x < tile.x1; ++x)
        for (int s = 0; s < spp; ++s) samples.push_back({{x, y}, s});
    if (gathers.size() < samples.size()) gathers.resize(samples.size());
    if (closest.size() < samples.size()) closest.resize(samples.size());
    if (results.size() < samples.size()) results.resize(samples.size());
    // Not cleared: each pixel's first sample sets its sum (renderTile).
    if (sum.size() < size_t(tile.width() * tile.height())) sum.resize(size_t(tile.width() * tile.height()));
  }

  const std::vector<uint32_t>& traceOrderFor(const Tile& tile, int spp) {
    const glm::ivec2 size(tile.width(), tile.height());
    if (size != orderSize || spp != orderSpp) {
      traceOrder(size.x, size.y, spp, &order);
      orderSize = size;
      orderSpp = spp;
    }
    return order;
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
void tracePackets(const CasterState& state, TileScratch& scratch);
void setupPrimary(const CasterState& state, HitGather& g, glm::ivec2 pixel, const glm::dvec2& position);
SampleResult resolvePrimary(const CasterState& state, const RayTreeContext& context, HitGather& g,
                            const GatheredHit& closest, uint32_t sampleIndex, std::vector<DeepSample>* deep,
                            std::vector<SurfaceCrossing>* crossings);
bool stoppingHitOnly(const HitGather& g, const std::vector<DeepSample>* deep, const RayTreeContext& context);
bool stoppingSurface(const HitGather& g, const GatheredHit& closest, SampleResult* r, SampleHit* hit);
bool shadesStoppingSurface(const CasterState& state, const RayTreeContext& context, const SampleHit& hit);

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
  parallelFor(tbb::blocked_range<int>(0, tilesX * tilesY), [&](const tbb::blocked_range<int>& range) {
    TileScratch& local = scratch.local();
    for (int t = range.begin(); t != range.end(); ++t) {
      // Ctrl-C (common/interrupt.h): the tiles not yet started are
      // skipped, and the unfinished image is thrown away below.
      if (stopRequested(options.cancel)) return;
      const int x0 = (t % tilesX) * size, y0 = (t / tilesX) * size;
      const Tile tile{x0, y0, std::min(x0 + size, camera.width), std::min(y0 + size, camera.height)};
      renderTile(state, tile, positions, centre, local, &out.image,
                 options.keepSamples ? &deep.tiles[size_t(t)] : nullptr, &deep.pixelCounts);
    }
  });
  throwIfStopped(options.cancel);
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
    scratch.traceOrderFor(tile, spp);
    tracePackets(state, scratch);
  }
  const Clock::time_point traced = Clock::now();

  // Phase 2: their surfaces shaded, filtered into the tile's pixels. A
  // sample whose surface list is its stopping hit alone (every sample of
  // an opaque scene) joins the tile's batch for the shading kernel
  // (common/shading_kernel.h), which the rasterizer's samples go through
  // too; the others are resolved one by one, their deep samples appended
  // in sample order.
  FlatImage& img = *image;
  std::vector<SampleResult>& results = scratch.results;
  scratch.stoppingSamples.clear();
  scratch.stoppingRays.clear();
  scratch.stoppingHits.clear();
  scratch.stoppingFootprints.clear();
  for (size_t i = 0; i < n; ++i) {
    const TileSample& s = samples[i];
    HitGather& g = scratch.gathers[i];
    if (stoppingHitOnly(g, tileDeep, context)) {
      SampleHit hit;
      if (stoppingSurface(g, scratch.closest[i], &results[i], &hit)) {
        scratch.stoppingSamples.push_back(uint32_t(i));
        scratch.stoppingRays.push_back(g.ray);
        scratch.stoppingHits.push_back(hit);
        scratch.stoppingFootprints.push_back(g.imagePosition);
      }
      continue;
    }
    const size_t pixel = img.index(s.pixel.x, s.pixel.y);
    const size_t before = tileDeep ? tileDeep->size() : 0;
    results[i] = resolvePrimary(state, context, g, scratch.closest[i], uint32_t(s.sample), tileDeep,
                                &scratch.crossings);
    if (tileDeep) (*pixelCounts)[pixel] += uint32_t(tileDeep->size() - before);
  }
  // The stopping hits refined in double lanes (refinePrimaryHit's bits):
  // the front surface reports the refined barycentrics, as the list's
  // entry has them. Then shaded as one batch, unless the cutoff stops
  // every sample (nothing is in front of a stopping hit: the same test for
  // all).
  const size_t stopping = scratch.stoppingSamples.size();
  scratch.stoppingRefined.resize(stopping);
  refinePrimaryHits(state.scene, scratch.stoppingRays.data(), scratch.stoppingHits.data(),
                    scratch.stoppingFootprints.data(), stopping, scratch.stoppingRefined.data());
  bool shade = false;
  for (size_t k = 0; k < stopping; ++k) {
    SampleResult& r = results[scratch.stoppingSamples[k]];
    r.front.b1 = scratch.stoppingRefined[k].b1;
    r.front.b2 = scratch.stoppingRefined[k].b2;
    shade = shadesStoppingSurface(state, context, scratch.stoppingHits[k]);
  }
  if (shade) {
    scratch.stoppingColors.resize(stopping);
    shadePrimaryHits(*context.shader, scratch.stoppingRefined.data(), stopping, scratch.stoppingColors.data(),
                     shadingPath(state));
    for (size_t k = 0; k < stopping; ++k) {
      // composite's first `over` of a surface with nothing in front of it:
      // 0 + remaining·c, remaining = 1 (−0 becomes +0).
      const float remaining = 1.0f - 0.0f;
      results[scratch.stoppingSamples[k]].color = glm::vec4(0.0f) + remaining * scratch.stoppingColors[k];
    }
  }
  for (size_t i = 0; i < n; ++i) {
    const TileSample& s = samples[i];
    const size_t pixel = img.index(s.pixel.x, s.pixel.y);
    const SampleResult& r = results[i];
    glm::vec4& sum = scratch.sum[size_t((s.pixel.y - tile.y0) * tile.width() + (s.pixel.x - tile.x0))];
    // The sum from 0 in sample order: 0 + the first (as a cleared sum
    // would give: −0 becomes +0), then += the others.
    sum = s.sample == 0 ? glm::vec4(0.0f) + r.color : sum + r.color;
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
  parallelFor(size_t(0), deep.tiles.size(), [&](size_t t) {
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

// --- coherent packets -------------------------------------------------------

// Embree's packet of N rays: its type and call.
template <int N>
struct Packet;
template <>
struct Packet<4> {
  using RayHit = RTCRayHit4;
  static void intersect(const int* valid, RTCScene scene, RTCIntersectContext* context, RayHit* rh) {
    rtcIntersect4(valid, scene, context, rh);
  }
};
template <>
struct Packet<8> {
  using RayHit = RTCRayHit8;
  static void intersect(const int* valid, RTCScene scene, RTCIntersectContext* context, RayHit* rh) {
    rtcIntersect8(valid, scene, context, rh);
  }
};
template <>
struct Packet<16> {
  using RayHit = RTCRayHit16;
  static void intersect(const int* valid, RTCScene scene, RTCIntersectContext* context, RayHit* rh) {
    rtcIntersect16(valid, scene, context, rh);
  }
};

// Morton (Z) order of the bits of x and y, interleaved.
uint32_t mortonCode(uint32_t x, uint32_t y) {
  uint32_t code = 0;
  for (uint32_t bit = 0; bit < 16; ++bit)
    code |= ((x >> bit) & 1u) << (2 * bit) | ((y >> bit) & 1u) << (2 * bit + 1);
  return code;
}

// The order packets trace a tile's samples in (indices into the tile's
// pixel-order samples): pixels in Morton order, each pixel's samples
// together, so a packet's lanes cover a compact block (16 lanes at 1 spp:
// 4×4 pixels; 8 lanes: 4×2) rather than a strip of a row.
void traceOrder(int width, int height, int spp, std::vector<uint32_t>* order) {
  std::vector<std::pair<uint32_t, uint32_t>> pixels;  // (Morton code, pixel index)
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      pixels.push_back({mortonCode(uint32_t(x), uint32_t(y)), uint32_t(y * width + x)});
  std::sort(pixels.begin(), pixels.end());
  order->clear();
  for (const auto& p : pixels)
    for (int s = 0; s < spp; ++s) order->push_back(p.second * uint32_t(spp) + uint32_t(s));
}

// Up to N samples of the tile (set up in scratch.gathers) in one coherent
// packet. Each lane's ray id is its sample's index, so the filters gather
// into that sample's HitGather; its stopping hit goes to scratch.closest.
template <int N>
void tracePacket(const CasterState& state, TileScratch& scratch, const uint32_t* samples, size_t n) {
  using P = Packet<N>;
  alignas(64) int valid[N];
  alignas(64) typename P::RayHit rh;
  for (size_t i = 0; i < size_t(N); ++i) {
    // Lanes without a sample: invalid, and a harmless ray should Embree read them.
    const bool used = i < n;
    const Ray* ray = used ? &scratch.gathers[samples[i]].ray : nullptr;
    const glm::vec3 o = used ? glm::vec3(ray->origin) : glm::vec3(0.0f);
    const glm::vec3 d = used ? glm::vec3(ray->direction) : glm::vec3(0.0f, 0.0f, -1.0f);
    valid[i] = used ? -1 : 0;
    rh.ray.org_x[i] = o.x;
    rh.ray.org_y[i] = o.y;
    rh.ray.org_z[i] = o.z;
    rh.ray.dir_x[i] = d.x;
    rh.ray.dir_y[i] = d.y;
    rh.ray.dir_z[i] = d.z;
    rh.ray.tnear[i] = used ? float(ray->tNear) : 0.0f;
    rh.ray.tfar[i] = used ? float(ray->tFar) : -kInf;
    rh.ray.time[i] = 0.0f;
    rh.ray.mask[i] = 0xFFFFFFFFu;
    rh.ray.id[i] = used ? samples[i] : 0u;
    rh.ray.flags[i] = 0;
    rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID[i] = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
  }
  GatherContext gatherContext;
  rtcInitIntersectContext(&gatherContext.embree);
  gatherContext.embree.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  gatherContext.gathers = scratch.gathers.data();
  {
    FlushDenormalsScope ftz;
    P::intersect(valid, state.embree->handle(), &gatherContext.embree, &rh);
  }
  for (size_t i = 0; i < n; ++i) {
    GatheredHit& closest = scratch.closest[samples[i]];
    closest = GatheredHit{};
    if (rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID) {
      closest.traversalT = rh.ray.tfar[i];
      closest.instance = rh.hit.geomID[i];
      closest.triangle = rh.hit.primID[i];
      closest.u = rh.hit.u[i];
      closest.v = rh.hit.v[i];
    }
  }
}

// Every sample of the tile in packets of RayOptions::packetWidth, in
// scratch.order.
void tracePackets(const CasterState& state, TileScratch& scratch) {
  const size_t width = size_t(state.options.packetWidth), n = scratch.order.size();
  for (size_t first = 0; first < n; first += width) {
    const uint32_t* samples = &scratch.order[first];
    const size_t count = std::min(width, n - first);
    if (width == 4)
      tracePacket<4>(state, scratch, samples, count);
    else if (width == 16)
      tracePacket<16>(state, scratch, samples, count);
    else
      tracePacket<8>(state, scratch, samples, count);
  }
}

void setupPrimary(const CasterState& state, HitGather& g, glm::ivec2 pixel, const glm::dvec2& position) {
  g.mode = GatherMode::Radiance;
  g.primary = true;
  g.imagePosition = glm::dvec2(pixel) + position;
  g.ray = (*state.primaryRays)(g.imagePosition);
  g.hits.clear();
}

// Whether a traced primary ray's surface list is its stopping hit alone
// (it gathered no layer: every ray of an opaque scene) and neither deep
// samples nor a ray tree are wanted: then it is resolved from that hit
// (stoppingSurface), without building the list.
bool stoppingHitOnly(const HitGather& g, const std::vector<DeepSample>* deep, const RayTreeContext& context) {
  return g.hits.empty() && !deep && !context.recorder;
}

// collectCrossings and composite for that one surface, kept in registers
// rather than built in the crossing list and read back (the list's entry
// was written field by field and read back in wider pieces: a
// store-forwarding stall per ray). The same operations in the same order,
// so the same bits: the hit refined as appendSurfaceCrossing refines it
// (refinePrimaryHit, or refinePrimaryHits for a tile: surfacePointOnRay's
// steps), depth Embree's t × depthPerT, the colour c of the refined hit
// making r.color = 0 + 1·c, as composite's first `over`.
//
// stoppingSurface: r's front surface (its barycentrics still Embree's, to
// be replaced by the refined ones) and the hit to refine; false for a
// miss (no surface, colour 0).
bool stoppingSurface(const HitGather& g, const GatheredHit& closest, SampleResult* r, SampleHit* hit) {
  *r = SampleResult{};
  if (closest.instance == kNoId) return false;
  r->front.instance = closest.instance;
  r->front.triangle = closest.triangle;
  r->front.depth = float(double(closest.traversalT) * g.ray.depthPerT);
  *hit = SampleHit{closest.instance, closest.triangle, r->front.depth, closest.u, closest.v};
  r->front.b1 = hit->b1;
  r->front.b2 = hit->b2;
  return true;
}

// Whether the stopping surface is shaded: not when the transparency
// cutoff stops even the first surface. Counts a BLEND surface that stopped
// the ray (no filter gathered it): the ray would continue behind it, but
// nothing was found there.
bool shadesStoppingSurface(const CasterState& state, const RayTreeContext& context, const SampleHit& hit) {
  const float remaining = 1.0f - 0.0f;  // nothing in front of it
  if (remaining < state.options.transparencyCutoff) return false;
  if (state.scene.materialOf(hit.instance).alphaMode == AlphaMode::Blend)
    context.count(RayKind::Transparency);
  return true;
}

// A traced primary ray's surfaces, shaded: the sample's colour, and its
// front-most surface with the traversal depth (the Z output).
SampleResult resolvePrimary(const CasterState& state, const RayTreeContext& context, HitGather& g,
                            const GatheredHit& closest, uint32_t sampleIndex, std::vector<DeepSample>* deep,
                            std::vector<SurfaceCrossing>* crossings) {
  if (stoppingHitOnly(g, deep, context)) {
    SampleResult r;
    SampleHit hit;
    if (!stoppingSurface(g, closest, &r, &hit)) return r;
    const ShadeHit refined = refinePrimaryHit(state.scene, g.ray, hit, g.imagePosition);
    r.front.b1 = refined.b1;
    r.front.b2 = refined.b2;
    if (shadesStoppingSurface(state, context, hit)) {
      glm::vec4 c;
      shadePrimaryHits(*context.shader, &refined, 1, &c, shadingPath(state));
      r.color = glm::vec4(0.0f) + 1.0f * c;
    }
    return r;
  }
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
