// Primary visibility: the image in tiles of tileSize² pixels in parallel
// (TBB). In a tile, every (pixel, sample) pair's primary ray is traced,
// as single rays or eight at a time in coherent packets (rtcIntersect8),
// its surfaces are collected and shaded (radiance.cpp), and the samples
// are box-filtered into the flat image; the deep output keeps every
// sample's surfaces.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>

#include "common/sampling.h"
#include "raytrace/ray_caster_parts.h"

namespace rastray {

namespace {

constexpr int kPacket = 8;

struct Tile {
  int x0, y0, x1, y1;  // pixels [x0, x1) × [y0, y1)
  int width() const { return x1 - x0; }
  int height() const { return y1 - y0; }
};

// One primary sample of a tile. A tile's samples run in pixel order;
// packets take eight consecutive ones.
struct TileSample {
  glm::ivec2 pixel;
  int sample;
};

std::vector<TileSample> tileSamples(const Tile& tile, int spp) {
  std::vector<TileSample> samples;
  samples.reserve(size_t(tile.width() * tile.height() * spp));
  for (int y = tile.y0; y < tile.y1; ++y)
    for (int x = tile.x0; x < tile.x1; ++x)
      for (int s = 0; s < spp; ++s) samples.push_back({{x, y}, s});
  return samples;
}

// Where a tile's sample results go: colours summed per pixel (box filter
// in premultiplied space), Z and IDs from the sample nearest the pixel
// centre, deep samples per pixel.
class TileOutput {
 public:
  TileOutput(const Tile& tile, int centre, FlatImage* image, std::vector<std::vector<DeepSample>>* deep)
      : tile_(tile),
        centre_(centre),
        image_(*image),
        deep_(deep),
        sum_(size_t(tile.width() * tile.height()), glm::vec4(0.0f)) {}

  std::vector<DeepSample>* deepOf(const TileSample& s) const {
    return deep_ ? &(*deep_)[image_.index(s.pixel.x, s.pixel.y)] : nullptr;
  }

  void add(const TileSample& s, const SampleResult& r) {
    sum_[size_t((s.pixel.y - tile_.y0) * tile_.width() + (s.pixel.x - tile_.x0))] += r.color;
    if (s.sample == centre_) {
      const size_t i = image_.index(s.pixel.x, s.pixel.y);
      image_.depth[i] = r.front.depth;
      image_.instance[i] = r.front.instance;
      image_.triangle[i] = r.front.triangle;
    }
  }

  void writeColors(int spp) {
    for (int y = tile_.y0; y < tile_.y1; ++y)
      for (int x = tile_.x0; x < tile_.x1; ++x)
        image_.color[image_.index(x, y)] =
            sum_[size_t((y - tile_.y0) * tile_.width() + (x - tile_.x0))] / float(spp);
  }

 private:
  Tile tile_;
  int centre_;
  FlatImage& image_;
  std::vector<std::vector<DeepSample>>* deep_;
  std::vector<glm::vec4> sum_;
};

// Defined below, in the order the image needs them.
void renderTile(const CasterState& state, const Tile& tile, const std::vector<glm::dvec2>& positions,
                int centre, FlatImage* image, std::vector<std::vector<DeepSample>>* deep);
DeepImage assembleDeepImage(int width, int height, std::vector<std::vector<DeepSample>>& perPixel);
void tracePacket(const CasterState& state, const RayTreeContext& context, const TileSample* samples, size_t n,
                 const std::vector<glm::dvec2>& positions, std::array<HitGather, kPacket>& gathers,
                 std::vector<SurfaceCrossing>* crossings, TileOutput& out);
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
  std::vector<std::vector<DeepSample>> deep;
  if (options.keepSamples) deep.resize(size_t(camera.width) * size_t(camera.height));

  const int size = std::max(1, options.tileSize);
  const int tilesX = (camera.width + size - 1) / size, tilesY = (camera.height + size - 1) / size;
  tbb::parallel_for(tbb::blocked_range<int>(0, tilesX * tilesY), [&](const tbb::blocked_range<int>& range) {
    for (int t = range.begin(); t != range.end(); ++t) {
      const int x0 = (t % tilesX) * size, y0 = (t / tilesX) * size;
      const Tile tile{x0, y0, std::min(x0 + size, camera.width), std::min(y0 + size, camera.height)};
      renderTile(state, tile, positions, centre, &out.image, options.keepSamples ? &deep : nullptr);
    }
  });
  if (options.keepSamples) {
    out.hasSamples = true;
    out.samples = assembleDeepImage(camera.width, camera.height, deep);
  }
  return out;
}

bool usePackets(const CasterState& state) {
  return state.options.packets && (state.options.forcePackets || !state.analysis.transparency);
}

namespace {

void renderTile(const CasterState& state, const Tile& tile, const std::vector<glm::dvec2>& positions,
                int centre, FlatImage* image, std::vector<std::vector<DeepSample>>* deep) {
  const RayTreeContext context = untracedContext(state);
  const int spp = int(positions.size());
  std::array<HitGather, kPacket> gathers;
  for (HitGather& g : gathers) g.hits.reserve(16);
  std::vector<SurfaceCrossing> crossings;
  TileOutput out(tile, centre, image, deep);
  const std::vector<TileSample> samples = tileSamples(tile, spp);
  if (!usePackets(state)) {
    for (const TileSample& s : samples)
      out.add(s, tracePrimarySample(state, context, s.pixel, positions[size_t(s.sample)], uint32_t(s.sample),
                                    gathers[0], out.deepOf(s), &crossings));
  } else {
    for (size_t first = 0; first < samples.size(); first += kPacket)
      tracePacket(state, context, &samples[first], std::min(size_t(kPacket), samples.size() - first),
                  positions, gathers, &crossings, out);
  }
  out.writeColors(spp);
}

// The per-pixel deep samples as one DeepImage (offsets per pixel).
DeepImage assembleDeepImage(int width, int height, std::vector<std::vector<DeepSample>>& perPixel) {
  DeepImage image;
  image.width = width;
  image.height = height;
  image.offsets.assign(perPixel.size() + 1, 0);
  size_t total = 0;
  for (size_t i = 0; i < perPixel.size(); ++i) {
    image.offsets[i] = total;
    total += perPixel[i].size();
  }
  image.offsets[perPixel.size()] = total;
  image.samples.reserve(total);
  for (auto& d : perPixel) image.samples.insert(image.samples.end(), d.begin(), d.end());
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

// Up to eight consecutive samples of a tile in one coherent packet.
void tracePacket(const CasterState& state, const RayTreeContext& context, const TileSample* samples, size_t n,
                 const std::vector<glm::dvec2>& positions, std::array<HitGather, kPacket>& gathers,
                 std::vector<SurfaceCrossing>* crossings, TileOutput& out) {
  alignas(32) int valid[kPacket];
  alignas(32) RTCRayHit8 rh;
  clearPacket(rh, valid);
  for (size_t i = 0; i < n; ++i) {
    setupPrimary(state, gathers[i], samples[i].pixel, positions[size_t(samples[i].sample)]);
    setLane(rh, valid, i, gathers[i].ray);
  }
  context.count(RayKind::Primary, n);
  GatherContext gatherContext;
  rtcInitIntersectContext(&gatherContext.embree);
  gatherContext.embree.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  gatherContext.gathers = gathers.data();
  {
    FlushDenormalsScope ftz;
    rtcIntersect8(valid, state.embree->handle(), &gatherContext.embree, &rh);
  }
  for (size_t i = 0; i < n; ++i)
    out.add(samples[i], resolvePrimary(state, context, gathers[i], laneHit(rh, i),
                                       uint32_t(samples[i].sample), out.deepOf(samples[i]), crossings));
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
  g.ray = state.camera.primaryRay(g.imagePosition);
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
