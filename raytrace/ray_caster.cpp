#include "raytrace/ray_caster.h"

#include <embree3/rtcore.h>
#include <pmmintrin.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <xmmintrin.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <limits>
#include <type_traits>

#include "common/error.h"
#include "common/optics.h"
#include "common/sampling.h"
#include "common/surface.h"
#include "raytrace/embree_scene.h"
#include "raytrace/ray_offset.h"

namespace rastray {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr int kPacket = 8;

const char* kCounterNames[kRayKindCount] = {"rays.primary", "rays.shadow", "rays.reflection",
                                            "rays.refraction", "rays.transparency"};

// Flush-to-zero and denormals-are-zero while Embree traverses (Embree's
// recommendation: denormals in traversal arithmetic are slow). Scoped to
// each traversal call and restored after it, so shading arithmetic runs
// in the caller's mode whether it is our tile task or the rasterizer's
// thread (hybrid): hybrid and ray-cast shading stay bit-identical.
class FlushDenormalsScope {
 public:
  FlushDenormalsScope() : saved_(_mm_getcsr()) {
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
  }
  ~FlushDenormalsScope() { _mm_setcsr(saved_); }
  FlushDenormalsScope(const FlushDenormalsScope&) = delete;
  FlushDenormalsScope& operator=(const FlushDenormalsScope&) = delete;

 private:
  unsigned saved_;
};

// A surface a ray passed through (or stopped at), as Embree reported it.
struct GatheredHit {
  float t = kInf;  // Embree's float t
  uint32_t instance = kNoId, triangle = kNoId;
  float u = 0.0f, v = 0.0f;
};

enum class GatherMode { Radiance, Shadow };

// Per-ray state the filter callbacks fill: every hit they reject so that
// traversal continues (BLEND layers; for shadow rays every surface that
// lets light through). Opaque hits are accepted and shrink tfar.
struct HitGather {
  GatherMode mode = GatherMode::Radiance;
  Ray ray;               // the traced ray, in double (for refinement)
  bool primary = false;  // MASK coverage uses the pixel footprint then
  glm::dvec2 imagePosition{0.0};
  std::vector<GatheredHit> hits;
};

// Embree's context extended with our per-call data: the documented way to
// hand filter callbacks per-query state. `embree` must stay the first
// member (the callback receives a pointer to it).
struct GatherContext {
  RTCIntersectContext embree;
  HitGather* gathers = nullptr;  // indexed by RTCRay::id
};
static_assert(std::is_standard_layout<GatherContext>::value, "GatherContext must be standard layout");
static_assert(offsetof(GatherContext, embree) == 0,
              "RTCIntersectContext must be GatherContext's first member");

// One traced ray of the current --debug-pixel trace (this thread only).
thread_local std::vector<RayRecord>* tTrace = nullptr;
thread_local int tTraceSample = 0;
thread_local int tTraceDepth = 0;  // depth of the surface being shaded (shadow rays)

RTCRayHit makeRayHit(const glm::vec3& origin, const glm::vec3& direction, float tnear, float tfar,
                     unsigned id) {
  RTCRayHit rh;
  rh.ray.org_x = origin.x;
  rh.ray.org_y = origin.y;
  rh.ray.org_z = origin.z;
  rh.ray.tnear = tnear;
  rh.ray.dir_x = direction.x;
  rh.ray.dir_y = direction.y;
  rh.ray.dir_z = direction.z;
  rh.ray.time = 0.0f;
  rh.ray.tfar = tfar;
  rh.ray.mask = 0xFFFFFFFFu;
  rh.ray.id = id;
  rh.ray.flags = 0;
  rh.hit.Ng_x = rh.hit.Ng_y = rh.hit.Ng_z = 0.0f;
  rh.hit.u = rh.hit.v = 0.0f;
  rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  return rh;
}

// The relation of two hits on one ray: how many crossings they are.
enum class Crossing { Two, KeepFirst, KeepSecond };

// Two reported hits are one crossing of one surface (SPEC §1, §3) when
// they are the same (instance, triangle), or when their triangles are
// adjacent across the ray: they share a vertex position p and, projected
// along the ray, lie on opposite sides of a line through p along one of
// their edges. Embree's watertight test may report both triangles of a
// shared edge (or several of a fan around a shared vertex), but a ray can
// meet both closed half-planes only on their common line, so such a pair
// is always one crossing, whatever t rounding says. Coincident duplicates
// (the same three positions) and folded pairs (same side) stay two layers.
//
// Which one is kept is decided like the rasterizer's top-left rule, by an
// exact-sign test evaluated once per pair: the side s of the ray's origin
// relative to the separating line, with the line's endpoints in canonical
// (lexicographic) order so the decision does not depend on which triangle
// is asked; the triangle on the ray's side wins, and on s == 0 (the ray
// exactly on the line) the one on the positive side. In double from the
// float vertex data; the projection is parallel to the ray direction.
class CrossingRule {
 public:
  CrossingRule(const Scene& scene, const glm::dvec3& origin, const glm::dvec3& direction)
      : scene_(scene), origin_(origin), direction_(direction) {}

  Crossing classify(const GatheredHit& first, const GatheredHit& second) const {
    if (first.instance == second.instance && first.triangle == second.triangle) return Crossing::KeepFirst;
    const std::array<glm::dvec3, 3> a = corners(first), b = corners(second);
    if (samePositionSet(a, b)) return Crossing::Two;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        if (a[i] != b[j]) continue;
        // p = a[i] = b[j]; the candidate lines run from p along the other
        // triangles' edges.
        const glm::dvec3& p = a[i];
        for (const glm::dvec3& x : {a[(i + 1) % 3], a[(i + 2) % 3], b[(j + 1) % 3], b[(j + 2) % 3]}) {
          if (x == p) continue;
          const Crossing c = separated(p, x, a, b);
          if (c != Crossing::Two) return c;
        }
      }
    return Crossing::Two;
  }

 private:
  std::array<glm::dvec3, 3> corners(const GatheredHit& h) const {
    const glm::uvec3 t = scene_.triangle(h.instance, h.triangle);
    return {glm::dvec3(scene_.positions[t.x]), glm::dvec3(scene_.positions[t.y]),
            glm::dvec3(scene_.positions[t.z])};
  }

  static bool samePositionSet(const std::array<glm::dvec3, 3>& a, const std::array<glm::dvec3, 3>& b) {
    for (const glm::dvec3& p : a)
      if (std::find(b.begin(), b.end(), p) == b.end()) return false;
    for (const glm::dvec3& p : b)
      if (std::find(a.begin(), a.end(), p) == a.end()) return false;
    return true;
  }

  static bool lexicographicLess(const glm::dvec3& u, const glm::dvec3& v) {
    if (u.x != v.x) return u.x < v.x;
    if (u.y != v.y) return u.y < v.y;
    return u.z < v.z;
  }

  // Sign of the side of q relative to the plane through the line (p, x)
  // that contains the ray direction: +1, -1 or 0.
  int side(const glm::dvec3& p, const glm::dvec3& x, const glm::dvec3& q) const {
    const double s = glm::dot(glm::cross(x - p, direction_), q - p);
    return (s > 0.0) - (s < 0.0);
  }

  // Whether the line (p, x) separates the triangles; then which one the
  // ray belongs to.
  Crossing separated(glm::dvec3 p, glm::dvec3 x, const std::array<glm::dvec3, 3>& a,
                     const std::array<glm::dvec3, 3>& b) const {
    if (lexicographicLess(x, p)) std::swap(p, x);
    auto sideOf = [&](const std::array<glm::dvec3, 3>& t) {
      int s = 0;
      for (const glm::dvec3& q : t) {
        if (q == p || q == x) continue;
        const int k = side(p, x, q);
        if (k == 0 || (s != 0 && k != s)) return 0;  // touches or straddles the line
        s = k;
      }
      return s;
    };
    const int sa = sideOf(a), sb = sideOf(b);
    if (sa == 0 || sb == 0 || sa == sb) return Crossing::Two;
    const double ray = glm::dot(glm::cross(x - p, direction_), origin_ - p);
    const int owner = ray > 0.0 ? 1 : ray < 0.0 ? -1 : 1;
    return owner == sa ? Crossing::KeepFirst : Crossing::KeepSecond;
  }

  const Scene& scene_;
  glm::dvec3 origin_, direction_;
};

// Sorts hits by (t, instance, triangle) and keeps one hit per crossing
// (CrossingRule).
void sortAndMergeCrossings(const Scene& scene, const Ray& ray, std::vector<GatheredHit>* hits) {
  std::sort(hits->begin(), hits->end(), [](const GatheredHit& a, const GatheredHit& b) {
    if (a.t != b.t) return a.t < b.t;
    if (a.instance != b.instance) return a.instance < b.instance;
    return a.triangle < b.triangle;
  });
  // Only hits whose triangles share a corner position can be one crossing
  // (CrossingRule), so each hit is tested against the earlier kept hits it
  // shares a corner with, found through the corners sorted by position:
  // O(n log n) for n unrelated layers (1,000 stacked quads: no pair tests
  // instead of 500,000). Equivalent to testing every earlier kept hit in
  // order, since all others are Crossing::Two.
  const size_t n = hits->size();
  struct Corner {
    glm::vec3 position;
    uint32_t hit;
  };
  std::vector<Corner> corners;
  corners.reserve(3 * n);
  for (size_t i = 0; i < n; ++i) {
    const glm::uvec3 t = scene.triangle((*hits)[i].instance, (*hits)[i].triangle);
    // + 0.0f turns −0 into +0: equal positions must sort together.
    for (uint32_t v : {t.x, t.y, t.z}) corners.push_back({scene.positions[v] + glm::vec3(0.0f), uint32_t(i)});
  }
  const auto positionLess = [](const glm::vec3& a, const glm::vec3& b) {
    if (a.x != b.x) return a.x < b.x;
    if (a.y != b.y) return a.y < b.y;
    return a.z < b.z;
  };
  std::sort(corners.begin(), corners.end(), [&](const Corner& a, const Corner& b) {
    if (a.position != b.position) return positionLess(a.position, b.position);
    return a.hit < b.hit;
  });
  // For each hit, its corners' runs of equal positions in `corners`.
  std::vector<std::array<std::pair<uint32_t, uint32_t>, 3>> runs(n);
  std::vector<uint8_t> runCount(n, 0);
  for (size_t begin = 0; begin < corners.size();) {
    size_t end = begin + 1;
    while (end < corners.size() && corners[end].position == corners[begin].position) ++end;
    if (end - begin > 1)
      for (size_t k = begin; k < end; ++k) {
        const uint32_t h = corners[k].hit;
        runs[h][runCount[h]++] = {uint32_t(begin), uint32_t(end)};
      }
    begin = end;
  }

  const CrossingRule rule(scene, ray.origin, ray.direction);
  std::vector<uint8_t> kept(n, 0);
  std::vector<uint32_t> candidates;
  for (size_t i = 0; i < n; ++i) {
    candidates.clear();
    for (uint8_t r = 0; r < runCount[i]; ++r)
      for (uint32_t k = runs[i][r].first; k < runs[i][r].second; ++k) {
        const uint32_t j = corners[k].hit;
        if (j < i && kept[j]) candidates.push_back(j);
      }
    std::sort(candidates.begin(), candidates.end());
    candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
    bool keep = true;
    for (uint32_t j : candidates) {
      const Crossing c = rule.classify((*hits)[j], (*hits)[i]);
      if (c == Crossing::KeepFirst) {
        keep = false;
        break;
      }
      if (c == Crossing::KeepSecond) kept[j] = 0;
    }
    kept[i] = keep;
  }
  size_t out = 0;
  for (size_t i = 0; i < n; ++i)
    if (kept[i]) (*hits)[out++] = (*hits)[i];
  hits->resize(out);
}

std::string fmt3(const glm::dvec3& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%.9g, %.9g, %.9g)", v.x, v.y, v.z);
  return buf;
}

}  // namespace

const char* toString(RayOffsetMethod method) {
  return method == RayOffsetMethod::ErrorBound ? "error-bound" : "float-ulps";
}

// ---------------------------------------------------------------------------

struct RayCaster::Impl {
  const Scene& scene;
  const SceneAnalysis analysis;  // a copy: callers often pass a temporary
  std::unique_ptr<EmbreeScene> embree;

  bool bound = false;
  Camera camera;
  RayOptions options;
  std::unique_ptr<Shader> shader;

  mutable tbb::enumerable_thread_specific<std::array<uint64_t, kRayKindCount>> counts{
      std::array<uint64_t, kRayKindCount>{}};

  const CullMode cull;

  Impl(const Scene& s, const SceneAnalysis& a, CullMode c) : scene(s), analysis(a), cull(c) {}

  void count(RayKind kind, uint64_t n = 1) const {
    if (tTrace) return;  // debug traces re-trace rays the render already counted
    counts.local()[size_t(kind)] += n;
  }

  // --- filter callbacks ----------------------------------------------------

  // The surface point of a hit along the gather's ray, refined in double.
  SurfacePoint pointOf(const HitGather& g, uint32_t instance, uint32_t triangle, float u, float v,
                       float t) const {
    SampleHit h;
    h.instance = instance;
    h.triangle = triangle;
    h.b1 = u;
    h.b2 = v;
    h.depth = float(double(t) * g.ray.depthPerT);
    return makeSurfacePoint(scene, refineHit(scene, g.ray, h));
  }

  // MASK coverage (SPEC §5): alpha >= cutoff covers.
  bool maskCovers(const HitGather& g, const SurfacePoint& p) const {
    const TextureFootprint fp =
        g.primary ? pixelFootprint(scene, camera, p, g.imagePosition) : TextureFootprint{};
    return shader->coverageAlpha(p, fp) >= p.material->alphaCutoff;
  }

  // Front-facing: the stored vertices run counter-clockwise seen along the
  // ray (normal cross(b − a, c − a) against the direction), in double.
  bool isFrontFacing(const GatheredHit& hit, const glm::dvec3& direction) const {
    const glm::uvec3 t = scene.triangle(hit.instance, hit.triangle);
    const glm::dvec3 a(scene.positions[t.x]), b(scene.positions[t.y]), c(scene.positions[t.z]);
    return glm::dot(glm::cross(b - a, c - a), direction) < 0.0;
  }

  // Accept (true) or reject (false, traversal continues) one hit.
  bool filterHit(HitGather& g, const GatheredHit& hit) const {
    const Material& m = scene.materialOf(hit.instance);
    if (cull != CullMode::None && isCulled(cull, m, isFrontFacing(hit, g.ray.direction))) return false;
    if (m.alphaMode == AlphaMode::Mask) {
      const SurfacePoint p = pointOf(g, hit.instance, hit.triangle, hit.u, hit.v, hit.t);
      if (!maskCovers(g, p)) return false;  // not there: ignored
      if (g.mode == GatherMode::Radiance) return true;
    }
    if (g.mode == GatherMode::Radiance) {
      if (m.alphaMode != AlphaMode::Blend) return true;  // opaque or refractive: a stopping hit
      g.hits.push_back(hit);
      return false;
    }
    // Shadow rays: gather everything that lets light through.
    const SurfacePoint p = pointOf(g, hit.instance, hit.triangle, hit.u, hit.v, hit.t);
    const glm::vec3 st = shader->shadowTransmittance(p);
    if (st == glm::vec3(0.0f)) return true;  // blocks: ends the occlusion query
    g.hits.push_back(hit);
    return false;
  }

  static void filter(const RTCFilterFunctionNArguments* args) {
    const auto* self = static_cast<const Impl*>(args->geometryUserPtr);
    // The context is the first member of our GatherContext (see there).
    const auto* context = reinterpret_cast<const GatherContext*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
      if (args->valid[i] != -1) continue;
      HitGather& g = context->gathers[RTCRayN_id(args->ray, args->N, i)];
      GatheredHit hit;
      hit.t = RTCRayN_tfar(args->ray, args->N, i);  // Embree sets tfar to the hit distance
      hit.instance = RTCHitN_geomID(args->hit, args->N, i);
      hit.triangle = RTCHitN_primID(args->hit, args->N, i);
      hit.u = RTCHitN_u(args->hit, args->N, i);
      hit.v = RTCHitN_v(args->hit, args->N, i);
      if (!self->filterHit(g, hit)) args->valid[i] = 0;
    }
  }

  // --- tracing ---------------------------------------------------------------

  // The surfaces along a traced ray, front to back: the gathered
  // transparent layers in front of the stopping hit, deduplicated, then
  // the stopping hit. Sorted by the refined (double) t, then instance and
  // triangle, and cut after the first non-BLEND surface.
  struct Layer {
    SampleHit hit;  // refined for shading: depth = t · depthPerT in double
    // The view depth Embree's float traversal found (its t × depthPerT):
    // the Z output reports this, the ray caster's own precision, so the
    // compare tool measures it instead of two copies of one refinement.
    float traversalDepth = 0.0f;
    double t = 0.0;
    bool blend = false;
  };

  void collectLayers(HitGather& g, const GatheredHit& closest, std::vector<Layer>* layers) const {
    layers->clear();
    if (closest.instance != kNoId) {
      // Layers Embree reported before it found a closer stopping hit lie
      // behind it.
      g.hits.erase(
          std::remove_if(g.hits.begin(), g.hits.end(), [&](const GatheredHit& h) { return h.t > closest.t; }),
          g.hits.end());
      g.hits.push_back(closest);
    }
    if (g.hits.size() > 1) sortAndMergeCrossings(scene, g.ray, &g.hits);
    for (const GatheredHit& h : g.hits) {
      Layer layer;
      SampleHit raw;
      raw.instance = h.instance;
      raw.triangle = h.triangle;
      raw.b1 = h.u;
      raw.b2 = h.v;
      raw.depth = float(double(h.t) * g.ray.depthPerT);
      layer.t = h.t;
      double t;
      glm::dvec2 b;
      if (intersectTrianglePlane(scene, h.instance, h.triangle, g.ray, &t, &b)) layer.t = t;
      layer.hit = refineHit(scene, g.ray, raw);
      layer.traversalDepth = raw.depth;
      layer.blend = scene.materialOf(h.instance).alphaMode == AlphaMode::Blend;
      layers->push_back(layer);
    }
    std::sort(layers->begin(), layers->end(), [](const Layer& a, const Layer& b) {
      if (a.t != b.t) return a.t < b.t;
      if (a.hit.instance != b.hit.instance) return a.hit.instance < b.hit.instance;
      return a.hit.triangle < b.hit.triangle;
    });
    for (size_t i = 0; i < layers->size(); ++i)
      if (!(*layers)[i].blend) {
        layers->resize(i + 1);
        break;
      }
  }

  // Traces one ray (single-ray path) and gathers its layers.
  // One single-ray traversal of g.ray (filters gather BLEND hits into g);
  // returns the closest accepted hit (instance kNoId when none).
  GatheredHit intersectSingle(HitGather& g, bool coherent) const {
    const glm::vec3 origin(g.ray.origin), direction(g.ray.direction);
    RTCRayHit rh = makeRayHit(origin, direction, float(g.ray.tNear), float(g.ray.tFar), 0);
    GatherContext context;
    rtcInitIntersectContext(&context.embree);
    context.embree.flags =
        coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    context.gathers = &g;
    {
      FlushDenormalsScope ftz;
      rtcIntersect1(embree->handle(), &context.embree, &rh);
    }
    GatheredHit closest;
    if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
      closest.t = rh.ray.tfar;
      closest.instance = rh.hit.geomID;
      closest.triangle = rh.hit.primID;
      closest.u = rh.hit.u;
      closest.v = rh.hit.v;
    }
    return closest;
  }

  void traceRadiance(HitGather& g, bool coherent, std::vector<Layer>* layers) const {
    const GatheredHit closest = intersectSingle(g, coherent);
    collectLayers(g, closest, layers);
  }

  // Front-to-back compositing of a ray's layers with premultiplied `over`
  // (SPEC §4): acc = acc + (1 − acc.a)·layer. Stops after the opaque
  // layer or once the remaining transmittance 1 − acc.a is below
  // options.transparencyCutoff. `deep` receives each layer's own
  // unattenuated premultiplied colour.
  glm::vec4 composite(const HitGather& g, const std::vector<Layer>& layers, int depth, float throughput,
                      std::vector<DeepSample>* deep, uint32_t sampleIndex, int* used) const {
    glm::vec4 acc(0.0f);
    int n = 0;
    for (const Layer& layer : layers) {
      const float remaining = 1.0f - acc.a;
      if (remaining < options.transparencyCutoff) {
        // Stopped with layers left: the deep output says so (SPEC §6).
        if (deep && !deep->empty()) deep->back().cutOff = true;
        break;
      }
      const SurfacePoint p = makeSurfacePoint(scene, layer.hit);
      const TextureFootprint fp =
          g.primary ? pixelFootprint(scene, camera, p, g.imagePosition) : TextureFootprint{};
      if (tTrace) tTraceDepth = depth;
      const glm::vec4 c = shader->shade(p, g.ray.direction, fp, depth, throughput * remaining);
      acc += remaining * c;
      ++n;
      if (deep) {
        DeepSample s;
        s.color = c;
        s.depth = layer.traversalDepth;
        s.instance = layer.hit.instance;
        s.triangle = layer.hit.triangle;
        s.sample = sampleIndex;
        deep->push_back(s);
      }
      if (!layer.blend) break;
      count(RayKind::Transparency);  // the ray continues behind this layer
    }
    if (used) *used = n;
    return acc;
  }

  // --- primary rays ------------------------------------------------------------

  struct SampleResult {
    glm::vec4 color{0.0f};
    SampleHit front;  // the front-most surface (transparent or opaque)
  };

  SampleResult resolvePrimary(HitGather& g, const GatheredHit& closest, uint32_t sampleIndex,
                              std::vector<DeepSample>* deep, std::vector<Layer>* layers) const {
    collectLayers(g, closest, layers);
    SampleResult r;
    if (!layers->empty()) {
      r.front = layers->front().hit;
      r.front.depth = layers->front().traversalDepth;
    }
    int used = 0;
    r.color = composite(g, *layers, 0, 1.0f, deep, sampleIndex, &used);
    if (tTrace) {
      RayRecord rec;
      rec.kind = RayKind::Primary;
      rec.sample = tTraceSample;
      rec.origin = g.ray.origin;
      rec.direction = g.ray.direction;
      rec.tNear = g.ray.tNear;
      rec.tFar = g.ray.tFar;
      if (!layers->empty()) {
        rec.instance = r.front.instance;
        rec.triangle = r.front.triangle;
        rec.t = layers->front().t;
      }
      rec.layers = used;
      rec.contribution = r.color;
      // Secondary rays were recorded while shading; the primary goes first.
      tTrace->insert(tTrace->begin() + traceStart, rec);
    }
    return r;
  }
  mutable size_t traceStart = 0;  // only used by the (serial) debug trace

  void setupPrimary(HitGather& g, glm::ivec2 pixel, const glm::dvec2& position) const {
    g.mode = GatherMode::Radiance;
    g.primary = true;
    g.imagePosition = glm::dvec2(pixel) + position;
    g.ray = camera.primaryRay(g.imagePosition);
    g.hits.clear();
  }

  SampleResult tracePrimarySingle(glm::ivec2 pixel, const glm::dvec2& position, uint32_t sampleIndex,
                                  HitGather& g, std::vector<DeepSample>* deep,
                                  std::vector<Layer>* layers) const {
    setupPrimary(g, pixel, position);
    count(RayKind::Primary);
    if (tTrace) traceStart = tTrace->size();
    const GatheredHit closest = intersectSingle(g, /*coherent=*/true);
    return resolvePrimary(g, closest, sampleIndex, deep, layers);
  }

  // --- secondary rays ------------------------------------------------------------

  // Where a secondary or shadow ray leaving `from` along `direction`
  // starts (raytrace/ray_offset.h): the one place both kinds get it.
  glm::vec3 rayOrigin(const SurfacePoint& from, const glm::dvec3& direction) const {
    const glm::dvec3 side = offsetSideNormal(from.geometricNormal, direction);
    if (options.offset == RayOffsetMethod::FloatUlps)
      return floatUlpsRayOrigin(glm::vec3(from.position), glm::vec3(side));
    const glm::uvec3 t = scene.triangle(from.instance, from.triangle);
    const FloatTriangle triangle = {scene.positions[t.x], scene.positions[t.y], scene.positions[t.z]};
    return errorBoundRayOrigin(triangle, from.position, from.b1, from.b2, side);
  }

  glm::vec3 radiance(const SurfacePoint& from, const glm::dvec3& direction, RayKind kind, int depth,
                     float throughput) const {
    if (depth > options.shading.maxDepth || !(throughput >= options.shading.minThroughput))
      return glm::vec3(0.0f);
    count(kind);
    HitGather g;
    g.mode = GatherMode::Radiance;
    g.primary = false;
    const glm::dvec3 dir = glm::normalize(direction);
    const glm::vec3 origin = rayOrigin(from, dir);
    g.ray.origin = glm::dvec3(origin);
    g.ray.direction = dir;
    g.ray.tNear = 0.0;
    g.ray.tFar = std::numeric_limits<double>::infinity();
    g.ray.depthPerT = 1.0;
    std::vector<Layer> layers;
    traceRadiance(g, false, &layers);
    size_t recordIndex = 0;
    if (tTrace) {
      RayRecord rec;
      rec.kind = kind;
      rec.depth = depth;
      rec.sample = tTraceSample;
      rec.origin = g.ray.origin;
      rec.direction = dir;
      rec.tNear = 0.0;
      rec.tFar = g.ray.tFar;
      if (!layers.empty()) {
        rec.instance = layers.front().hit.instance;
        rec.triangle = layers.front().hit.triangle;
        rec.t = layers.front().t;
      }
      recordIndex = tTrace->size();
      tTrace->push_back(rec);
    }
    int used = 0;
    const glm::vec4 c = composite(g, layers, depth, throughput, nullptr, 0, &used);
    if (tTrace) {
      (*tTrace)[recordIndex].layers = used;
      (*tTrace)[recordIndex].contribution = c;
    }
    return glm::vec3(c);
  }

  glm::vec3 transmittance(const SurfacePoint& point, const glm::dvec3& toLight, double distance) const {
    count(RayKind::Shadow);
    const glm::dvec3 dir = glm::normalize(toLight);
    const glm::vec3 origin = rayOrigin(point, dir);
    HitGather g;
    g.mode = GatherMode::Shadow;
    g.primary = false;
    g.ray.origin = glm::dvec3(origin);
    g.ray.direction = dir;
    g.ray.tNear = 0.0;
    g.ray.tFar = distance;
    g.ray.depthPerT = 1.0;
    RTCRayHit rh = makeRayHit(origin, glm::vec3(dir), 0.0f, float(distance), 0);
    GatherContext context;
    rtcInitIntersectContext(&context.embree);
    context.gathers = &g;
    {
      FlushDenormalsScope ftz;
      rtcOccluded1(embree->handle(), &context.embree, &rh.ray);
    }
    glm::vec3 result(1.0f);
    const bool blocked = rh.ray.tfar == -kInf;
    if (blocked) {
      result = glm::vec3(0.0f);
    } else if (!g.hits.empty()) {
      sortAndMergeCrossings(scene, g.ray, &g.hits);
      for (const GatheredHit& h : g.hits)
        result *= shader->shadowTransmittance(pointOf(g, h.instance, h.triangle, h.u, h.v, h.t));
    }
    if (tTrace) {
      RayRecord rec;
      rec.kind = RayKind::Shadow;
      rec.depth = tTraceDepth;  // the shaded surface's depth
      rec.sample = tTraceSample;
      rec.origin = g.ray.origin;
      rec.direction = dir;
      rec.tFar = distance;
      rec.layers = blocked ? 0 : int(g.hits.size());
      if (!g.hits.empty()) {
        rec.instance = g.hits.front().instance;
        rec.triangle = g.hits.front().triangle;
        rec.t = g.hits.front().t;
      }
      rec.contribution = glm::vec4(result, 1.0f);
      tTrace->push_back(rec);
    }
    return result;
  }

  // --- the image -------------------------------------------------------------------

  bool usePackets() const { return options.packets && (options.forcePackets || !analysis.transparency); }

  RenderOutput render() const;
  void renderTile(int x0, int y0, int x1, int y1, const std::vector<glm::dvec2>& positions, int centre,
                  RenderOutput* out, std::vector<std::vector<DeepSample>>* deep) const;
};

void RayCaster::Impl::renderTile(int x0, int y0, int x1, int y1, const std::vector<glm::dvec2>& positions,
                                 int centre, RenderOutput* out,
                                 std::vector<std::vector<DeepSample>>* deep) const {
  const int spp = int(positions.size());
  FlatImage& image = out->image;
  std::array<HitGather, kPacket> gathers;
  std::vector<Layer> layers;
  std::vector<DeepSample> scratch;
  for (HitGather& g : gathers) g.hits.reserve(16);

  // The (pixel, sample) pairs of the tile, in pixel order; packets take
  // eight consecutive ones.
  struct Item {
    glm::ivec2 pixel;
    int sample;
  };
  std::vector<Item> items;
  items.reserve(size_t((x1 - x0) * (y1 - y0) * spp));
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x)
      for (int s = 0; s < spp; ++s) items.push_back({{x, y}, s});

  std::vector<glm::vec4> sum(size_t((x1 - x0) * (y1 - y0)), glm::vec4(0.0f));
  auto accumulate = [&](const Item& item, const SampleResult& r) {
    sum[size_t((item.pixel.y - y0) * (x1 - x0) + (item.pixel.x - x0))] += r.color;
    if (item.sample == centre) {
      const size_t i = image.index(item.pixel.x, item.pixel.y);
      image.depth[i] = r.front.depth;
      image.instance[i] = r.front.instance;
      image.triangle[i] = r.front.triangle;
    }
  };
  auto deepOut = [&](const Item& item) -> std::vector<DeepSample>* {
    return deep ? &(*deep)[image.index(item.pixel.x, item.pixel.y)] : nullptr;
  };

  if (!usePackets()) {
    for (const Item& item : items) {
      const SampleResult r = tracePrimarySingle(item.pixel, positions[size_t(item.sample)],
                                                uint32_t(item.sample), gathers[0], deepOut(item), &layers);
      accumulate(item, r);
    }
  } else {
    for (size_t first = 0; first < items.size(); first += kPacket) {
      const size_t n = std::min(size_t(kPacket), items.size() - first);
      alignas(32) int valid[kPacket];
      alignas(32) RTCRayHit8 rh;
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
      for (size_t i = 0; i < n; ++i) {
        const Item& item = items[first + i];
        HitGather& g = gathers[i];
        setupPrimary(g, item.pixel, positions[size_t(item.sample)]);
        const glm::vec3 o(g.ray.origin), d(g.ray.direction);
        valid[i] = -1;
        rh.ray.org_x[i] = o.x;
        rh.ray.org_y[i] = o.y;
        rh.ray.org_z[i] = o.z;
        rh.ray.dir_x[i] = d.x;
        rh.ray.dir_y[i] = d.y;
        rh.ray.dir_z[i] = d.z;
        rh.ray.tnear[i] = float(g.ray.tNear);
        rh.ray.tfar[i] = float(g.ray.tFar);
      }
      count(RayKind::Primary, n);
      GatherContext context;
      rtcInitIntersectContext(&context.embree);
      context.embree.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
      context.gathers = gathers.data();
      {
        FlushDenormalsScope ftz;
        rtcIntersect8(valid, embree->handle(), &context.embree, &rh);
      }
      for (size_t i = 0; i < n; ++i) {
        const Item& item = items[first + i];
        GatheredHit closest;
        if (rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID) {
          closest.t = rh.ray.tfar[i];
          closest.instance = rh.hit.geomID[i];
          closest.triangle = rh.hit.primID[i];
          closest.u = rh.hit.u[i];
          closest.v = rh.hit.v[i];
        }
        accumulate(item, resolvePrimary(gathers[i], closest, uint32_t(item.sample), deepOut(item), &layers));
      }
    }
  }

  // Box filter in premultiplied space.
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x)
      image.color[image.index(x, y)] = sum[size_t((y - y0) * (x1 - x0) + (x - x0))] / float(spp);
}

RenderOutput RayCaster::Impl::render() const {
  RenderOutput out;
  out.image = FlatImage(camera.width, camera.height);
  const std::vector<glm::dvec2> positions = samplePositions(options.spp);
  const int centre = centreSampleIndex(options.spp);
  std::vector<std::vector<DeepSample>> deep;
  if (options.keepSamples) deep.resize(size_t(camera.width) * size_t(camera.height));

  const int tile = std::max(1, options.tileSize);
  const int tilesX = (camera.width + tile - 1) / tile, tilesY = (camera.height + tile - 1) / tile;
  tbb::parallel_for(tbb::blocked_range<int>(0, tilesX * tilesY), [&](const tbb::blocked_range<int>& range) {
    for (int t = range.begin(); t != range.end(); ++t) {
      const int x0 = (t % tilesX) * tile, y0 = (t / tilesX) * tile;
      renderTile(x0, y0, std::min(x0 + tile, camera.width), std::min(y0 + tile, camera.height), positions,
                 centre, &out, options.keepSamples ? &deep : nullptr);
    }
  });
  embree->throwIfError();

  if (options.keepSamples) {
    out.hasSamples = true;
    out.samples.width = camera.width;
    out.samples.height = camera.height;
    out.samples.offsets.assign(deep.size() + 1, 0);
    size_t total = 0;
    for (size_t i = 0; i < deep.size(); ++i) {
      out.samples.offsets[i] = total;
      total += deep[i].size();
    }
    out.samples.offsets[deep.size()] = total;
    out.samples.samples.reserve(total);
    for (auto& d : deep) out.samples.samples.insert(out.samples.samples.end(), d.begin(), d.end());
  }
  return out;
}

// ---------------------------------------------------------------------------

RayCaster::RayCaster(const Scene& scene, const SceneAnalysis& analysis, CullMode cull)
    : impl_(std::make_unique<Impl>(scene, analysis, cull)) {
  impl_->embree =
      std::make_unique<EmbreeScene>(scene, analysis, cull, &Impl::filter, &Impl::filter, impl_.get());
}

RayCaster::~RayCaster() = default;

void RayCaster::bind(const Camera& camera, const RayOptions& options) {
  if (!isSupportedSampleCount(options.spp))
    throw InputError(
        "command line", "--spp",
        "unsupported sample count " + std::to_string(options.spp) + " (use " + supportedSampleCounts() + ")");
  if (options.shading.maxDepth < 0) throw InputError("command line", "--max-depth", "must be >= 0");
  Impl& m = *impl_;
  m.camera = camera;
  m.options = options;
  m.shader = std::make_unique<Shader>(m.scene, m.analysis, m.camera, options.shading, this, this);
  m.counts.clear();
  m.bound = true;
}

RenderOutput RayCaster::render() {
  RASTRAY_CHECK(impl_->bound, "RayCaster::render before bind");
  RenderOutput out = impl_->render();
  out.counters = counters();
  out.passesRun.push_back("primary rays (" +
                          std::string(impl_->usePackets() ? "8-wide packets" : "single rays") + ")");
  const SceneAnalysis& a = impl_->analysis;
  auto pass = [&](bool needed, const std::string& name, Work work) {
    if (needed)
      out.passesRun.push_back(name);
    else
      for (const WorkDecision& d : a.decisions)
        if (d.work == work) out.passesLeftOut.push_back(name + ": " + d.reason);
  };
  pass(a.shadows, "shadow rays", Work::Shadows);
  pass(a.reflection, "reflection rays", Work::ReflectionRays);
  pass(a.refraction, "refraction rays", Work::RefractionRays);
  pass(a.transparency, "transparency continuation", Work::TransparencyPass);
  pass(a.alphaTest, "alpha test (filter callbacks)", Work::AlphaTest);
  if (impl_->cull != CullMode::None)
    out.passesRun.push_back(std::string(impl_->cull == CullMode::Back ? "back" : "front") +
                            "-face culling (filters on " + std::to_string(impl_->embree->filterGeometries()) +
                            " single-sided geometries)");
  if (impl_->options.debugPixel) {
    const glm::ivec2 p = *impl_->options.debugPixel;
    if (p.x >= 0 && p.y >= 0 && p.x < impl_->camera.width && p.y < impl_->camera.height)
      printRayTree(traceDebugPixel(p), p);
    else
      std::fprintf(stderr, "debug pixel (%d, %d) lies outside the %dx%d image\n", p.x, p.y,
                   impl_->camera.width, impl_->camera.height);
  }
  return out;
}

glm::vec3 RayCaster::radiance(const SurfacePoint& from, const glm::dvec3& direction, RayKind kind, int depth,
                              float throughput) const {
  RASTRAY_CHECK(impl_->bound, "RayCaster::radiance before bind");
  return impl_->radiance(from, direction, kind, depth, throughput);
}

glm::vec3 RayCaster::transmittance(const SurfacePoint& point, int /*lightIndex*/, const glm::dvec3& toLight,
                                   double distance) const {
  RASTRAY_CHECK(impl_->bound, "RayCaster::transmittance before bind");
  return impl_->transmittance(point, toLight, distance);
}

CounterSet RayCaster::counters() const {
  std::array<uint64_t, kRayKindCount> total{};
  for (const auto& local : impl_->counts)
    for (int k = 0; k < kRayKindCount; ++k) total[size_t(k)] += local[size_t(k)];
  CounterSet set;
  for (int k = 0; k < kRayKindCount; ++k) set.set(kCounterNames[k], total[size_t(k)]);
  return set;
}

std::vector<RayRecord> RayCaster::traceDebugPixel(glm::ivec2 pixel) const {
  RASTRAY_CHECK(impl_->bound, "RayCaster::traceDebugPixel before bind");
  std::vector<RayRecord> records;
  const std::vector<glm::dvec2> positions = samplePositions(impl_->options.spp);
  HitGather g;
  std::vector<Impl::Layer> layers;
  tTrace = &records;
  try {
    for (size_t s = 0; s < positions.size(); ++s) {
      tTraceSample = int(s);
      impl_->tracePrimarySingle(pixel, positions[s], uint32_t(s), g, nullptr, &layers);
    }
  } catch (...) {
    tTrace = nullptr;
    throw;
  }
  tTrace = nullptr;
  return records;
}

void RayCaster::printRayTree(const std::vector<RayRecord>& records, glm::ivec2 pixel) {
  std::fprintf(stderr, "ray tree of pixel (%d, %d): %zu rays\n", pixel.x, pixel.y, records.size());
  for (const RayRecord& r : records) {
    // Shadow rays hang below the surface they light (its ray's depth + 1).
    const int indent = r.kind == RayKind::Shadow ? r.depth + 1 : r.depth;
    std::string pad(size_t(2 * indent + 2), ' ');
    std::string what;
    if (r.kind == RayKind::Shadow) {
      what = r.contribution == glm::vec4(0.0f, 0.0f, 0.0f, 1.0f) ? "blocked"
             : r.layers == 0                                     ? "unoccluded"
                             : "through " + std::to_string(r.layers) + " surface(s), first instance " +
                                   std::to_string(r.instance) + " triangle " + std::to_string(r.triangle);
    } else if (r.instance == kNoId) {
      what = "miss";
    } else {
      char tbuf[64];
      std::snprintf(tbuf, sizeof tbuf, " t %.9g", r.t);
      what = "hit instance " + std::to_string(r.instance) + " triangle " + std::to_string(r.triangle) + tbuf +
             ", " + std::to_string(r.layers) + " layer(s)";
    }
    std::fprintf(stderr,
                 "%ssample %d %s%s origin %s dir %s tnear %.9g tfar %.9g: %s, %s (%.6g, %.6g, %.6g, %.6g)\n",
                 pad.c_str(), r.sample, toString(r.kind),
                 (" depth " + std::to_string(r.kind == RayKind::Shadow ? r.depth + 1 : r.depth)).c_str(),
                 fmt3(r.origin).c_str(), fmt3(r.direction).c_str(), r.tNear, r.tFar, what.c_str(),
                 r.kind == RayKind::Shadow ? "transmittance" : "contribution", r.contribution.r,
                 r.contribution.g, r.contribution.b, r.contribution.a);
  }
}

}  // namespace rastray
