// Transparency continuation: one traversal per ray sees every surface
// along it. Filter callbacks reject (and gather) the hits traversal must
// continue behind and accept the ones that end it; the gathered hits are
// reduced to one per crossing (CrossingRule) and become the ray's
// front-to-back surface list, which the integrator composites.
#include <algorithm>
#include <array>
#include <string>
#include <utility>

#include "raytrace/ray_caster_parts.h"

namespace rastray {

namespace {

// Defined below, each after the function that uses it.
bool acceptHit(const CasterState& state, HitGather& g, GatheredHit& hit);
bool maskCovers(const CasterState& state, const HitGather& g, const SurfacePoint& p);
bool isFrontFacing(const Scene& scene, const GatheredHit& hit, const glm::dvec3& direction);
RTCRayHit makeRayHit(const glm::vec3& origin, const glm::vec3& direction, float tnear, float tfar,
                     unsigned id);
void appendSurfaceCrossing(const Scene& scene, const Ray& ray, const GatheredHit& h,
                           std::vector<SurfaceCrossing>* crossings);
// At the end: the detail of when two hits are one crossing.
void sortAndMergeCrossings(const Scene& scene, const Ray& ray, std::vector<GatheredHit>* hits);

}  // namespace

// --- filters ------------------------------------------------------------------

void gatherFilter(const RTCFilterFunctionNArguments* args) {
  const auto* state = static_cast<const CasterState*>(args->geometryUserPtr);
  // The context is the first member of our GatherContext (see there).
  const auto* context = reinterpret_cast<const GatherContext*>(args->context);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    HitGather& g = context->gathers[RTCRayN_id(args->ray, args->N, i)];
    GatheredHit hit;
    hit.traversalT = RTCRayN_tfar(args->ray, args->N, i);  // Embree sets tfar to the hit distance
    hit.instance = RTCHitN_geomID(args->hit, args->N, i);
    hit.triangle = RTCHitN_primID(args->hit, args->N, i);
    hit.u = RTCHitN_u(args->hit, args->N, i);
    hit.v = RTCHitN_v(args->hit, args->N, i);
    if (!acceptHit(*state, g, hit)) args->valid[i] = 0;
  }
}

namespace {

// Accept (true) or reject (false, traversal continues) one hit; a shadow
// ray's hit it lets through keeps its transmittance.
bool acceptHit(const CasterState& state, HitGather& g, GatheredHit& hit) {
  const Scene& scene = state.scene;
  const Material& m = scene.materialOf(hit.instance);
  if (state.cull != CullMode::None && isCulled(state.cull, m, isFrontFacing(scene, hit, g.ray.direction)))
    return false;
  if (m.alphaMode == AlphaMode::Mask) {
    if (!maskCovers(state, g, surfacePointOf(scene, g.ray, hit))) return false;  // not there: ignored
    if (g.mode == GatherMode::Radiance) return true;
  }
  if (g.mode == GatherMode::Radiance) {
    if (m.alphaMode != AlphaMode::Blend) return true;  // opaque or refractive: a stopping hit
    g.hits.push_back(hit);
    return false;
  }
  // Shadow rays: gather everything that lets light through.
  hit.transmittance = state.shader->shadowTransmittance(surfacePointOf(scene, g.ray, hit));
  if (hit.transmittance == glm::vec3(0.0f)) return true;  // blocks: ends the occlusion query
  g.hits.push_back(hit);
  return false;
}

// MASK coverage (SPEC §5): alpha >= cutoff covers.
bool maskCovers(const CasterState& state, const HitGather& g, const SurfacePoint& p) {
  const TextureFootprint fp =
      g.primary ? pixelFootprint(state.scene, state.camera, p, g.imagePosition) : TextureFootprint{};
  return state.shader->coverageAlpha(p, fp) >= p.material->alphaCutoff;
}

// Front-facing: the stored vertices run counter-clockwise seen along the
// ray (normal cross(b − a, c − a) against the direction), in double.
bool isFrontFacing(const Scene& scene, const GatheredHit& hit, const glm::dvec3& direction) {
  const glm::uvec3 t = scene.triangle(hit.instance, hit.triangle);
  const glm::dvec3 a(scene.positions[t.x]), b(scene.positions[t.y]), c(scene.positions[t.z]);
  return glm::dot(glm::cross(b - a, c - a), direction) < 0.0;
}

}  // namespace

SurfacePoint surfacePointOf(const Scene& scene, const Ray& ray, const GatheredHit& hit) {
  SampleHit h;
  h.instance = hit.instance;
  h.triangle = hit.triangle;
  h.b1 = hit.u;
  h.b2 = hit.v;
  h.depth = float(double(hit.traversalT) * ray.depthPerT);
  return surfacePointOnRay(scene, ray, h);
}

// --- traversals -----------------------------------------------------------------

GatheredHit intersectClosest(const CasterState& state, HitGather& g, bool coherent) {
  const glm::vec3 origin(g.ray.origin), direction(g.ray.direction);
  RTCRayHit rh = makeRayHit(origin, direction, float(g.ray.tNear), float(g.ray.tFar), 0);
  GatherContext context;
  rtcInitIntersectContext(&context.embree);
  context.embree.flags =
      coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
  context.gathers = &g;
  {
    FlushDenormalsScope ftz;
    rtcIntersect1(state.embree->handle(), &context.embree, &rh);
  }
  GatheredHit closest;
  if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
    closest.traversalT = rh.ray.tfar;
    closest.instance = rh.hit.geomID;
    closest.triangle = rh.hit.primID;
    closest.u = rh.hit.u;
    closest.v = rh.hit.v;
  }
  return closest;
}

bool traceOcclusion(const CasterState& state, HitGather& g) {
  bool blocked = false;
  traceOcclusionPacket(state, &g, 1, &blocked);
  return blocked;
}

void traceOcclusionPacket(const CasterState& state, HitGather* gathers, size_t n, bool* blocked,
                          const int* lanes) {
  static_assert(kShadowPacket <= 14, "Embree traverses a packet of 16 lane by lane only up to 14 lanes");
  RASTRAY_CHECK(n <= kShadowPacket, "a shadow packet of " + std::to_string(n) + " rays");
  alignas(64) int valid[16];
  alignas(64) RTCRay16 ray;
  int laneOf[kShadowPacket];
  for (size_t i = 0; i < n; ++i) laneOf[i] = lanes ? lanes[i] : int(i);
  for (size_t l = 0; l < 16; ++l) {
    // Lanes without a ray: invalid, and a harmless ray should Embree read them.
    valid[l] = 0;
    ray.org_x[l] = ray.org_y[l] = ray.org_z[l] = 0.0f;
    ray.tnear[l] = 0.0f;
    ray.dir_x[l] = ray.dir_y[l] = 0.0f;
    ray.dir_z[l] = -1.0f;
    ray.time[l] = 0.0f;
    ray.tfar[l] = -kInf;
    ray.mask[l] = 0xFFFFFFFFu;
    ray.id[l] = 0;
    ray.flags[l] = 0;
  }
  for (size_t i = 0; i < n; ++i) {
    // The float ray of makeRayHit's fields, in its lane; its id indexes gathers.
    const size_t l = size_t(laneOf[i]);
    const glm::vec3 o(gathers[i].ray.origin), d(gathers[i].ray.direction);
    valid[l] = -1;
    ray.org_x[l] = o.x;
    ray.org_y[l] = o.y;
    ray.org_z[l] = o.z;
    ray.tnear[l] = float(gathers[i].ray.tNear);
    ray.dir_x[l] = d.x;
    ray.dir_y[l] = d.y;
    ray.dir_z[l] = d.z;
    ray.tfar[l] = float(gathers[i].ray.tFar);
    ray.id[l] = unsigned(i);
  }
  GatherContext context;
  rtcInitIntersectContext(&context.embree);
  // Incoherent (the default flag): with the coherent flag Embree traverses
  // the packet as a frustum and lanes test leaves their own boxes missed,
  // which changes a lane's answer with its mates.
  context.gathers = gathers;
  {
    FlushDenormalsScope ftz;
    rtcOccluded16(valid, state.embree->handle(), &context.embree, &ray);
  }
  for (size_t i = 0; i < n; ++i) {
    blocked[i] = ray.tfar[laneOf[i]] == -kInf;
    if (!blocked[i] && !gathers[i].hits.empty())
      sortAndMergeCrossings(state.scene, gathers[i].ray, &gathers[i].hits);
  }
}

namespace {

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

}  // namespace

// --- the surface list ------------------------------------------------------------

void collectCrossings(const CasterState& state, HitGather& g, const GatheredHit& closest,
                      std::vector<SurfaceCrossing>* crossings) {
  crossings->clear();
  if (g.hits.empty()) {
    // Nothing gathered (every opaque scene): the list is the stopping hit
    // alone, as the general path below would make it.
    if (closest.instance != kNoId) appendSurfaceCrossing(state.scene, g.ray, closest, crossings);
    return;
  }
  if (closest.instance != kNoId) {
    // Layers Embree reported before it found a closer stopping hit lie
    // behind it.
    g.hits.erase(std::remove_if(g.hits.begin(), g.hits.end(),
                                [&](const GatheredHit& h) { return h.traversalT > closest.traversalT; }),
                 g.hits.end());
    g.hits.push_back(closest);
  }
  if (g.hits.size() > 1) sortAndMergeCrossings(state.scene, g.ray, &g.hits);
  for (const GatheredHit& h : g.hits) appendSurfaceCrossing(state.scene, g.ray, h, crossings);
  std::sort(crossings->begin(), crossings->end(), [](const SurfaceCrossing& a, const SurfaceCrossing& b) {
    if (a.planeT != b.planeT) return a.planeT < b.planeT;
    if (a.refined.instance != b.refined.instance) return a.refined.instance < b.refined.instance;
    return a.refined.triangle < b.refined.triangle;
  });
  for (size_t i = 0; i < crossings->size(); ++i)
    if (!(*crossings)[i].blend) {
      crossings->resize(i + 1);
      break;
    }
}

namespace {

// A gathered hit appended to the ray's surface list, refined in double.
void appendSurfaceCrossing(const Scene& scene, const Ray& ray, const GatheredHit& h,
                           std::vector<SurfaceCrossing>* crossings) {
  // Filled in place in the list: a crossing (or its SampleHit) built apart
  // and copied in was read back in wider pieces than it was written (a
  // store-forwarding stall per hit).
  SurfaceCrossing& crossing = crossings->emplace_back();
  SampleHit& hit = crossing.refined;
  hit.instance = h.instance;
  hit.triangle = h.triangle;
  hit.b1 = h.u;
  hit.b2 = h.v;
  hit.depth = float(double(h.traversalT) * ray.depthPerT);
  crossing.traversalDepth = hit.depth;
  crossing.planeT = h.traversalT;
  double t;
  glm::dvec2 b;
  // One plane intersection for both: refineHitAt is refineHit from it.
  if (intersectTrianglePlane(scene, h.instance, h.triangle, ray, &t, &b)) {
    crossing.planeT = t;
    hit = refineHitAt(ray, hit, t, b);
  }
  crossing.blend = scene.materialOf(h.instance).alphaMode == AlphaMode::Blend;
}

// --- one hit per crossing ----------------------------------------------------------

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

// The hits (by index) that share a corner position with one another: for
// each hit, the runs of equal positions its corners fall in, over all
// corners sorted by position. Only such hits can be one crossing.
class SharedCorners {
 public:
  SharedCorners(const Scene& scene, const std::vector<GatheredHit>& hits)
      : runs_(hits.size()), runCount_(hits.size(), 0) {
    corners_.reserve(3 * hits.size());
    for (size_t i = 0; i < hits.size(); ++i) {
      const glm::uvec3 t = scene.triangle(hits[i].instance, hits[i].triangle);
      // + 0.0f turns −0 into +0: equal positions must sort together.
      for (uint32_t v : {t.x, t.y, t.z})
        corners_.push_back({scene.positions[v] + glm::vec3(0.0f), uint32_t(i)});
    }
    std::sort(corners_.begin(), corners_.end(), [](const Corner& a, const Corner& b) {
      if (a.position != b.position) return positionLess(a.position, b.position);
      return a.hit < b.hit;
    });
    for (size_t begin = 0; begin < corners_.size();) {
      size_t end = begin + 1;
      while (end < corners_.size() && corners_[end].position == corners_[begin].position) ++end;
      if (end - begin > 1)
        for (size_t k = begin; k < end; ++k) {
          const uint32_t h = corners_[k].hit;
          runs_[h][runCount_[h]++] = {uint32_t(begin), uint32_t(end)};
        }
      begin = end;
    }
  }

  // The hits before `i` that share a corner with it and pass `keep`, once
  // each, in increasing order.
  template <class Keep>
  void earlierNeighbours(uint32_t i, Keep keep, std::vector<uint32_t>* out) const {
    out->clear();
    for (uint8_t r = 0; r < runCount_[i]; ++r)
      for (uint32_t k = runs_[i][r].first; k < runs_[i][r].second; ++k) {
        const uint32_t j = corners_[k].hit;
        if (j < i && keep(j)) out->push_back(j);
      }
    std::sort(out->begin(), out->end());
    out->erase(std::unique(out->begin(), out->end()), out->end());
  }

 private:
  struct Corner {
    glm::vec3 position;
    uint32_t hit;
  };
  static bool positionLess(const glm::vec3& a, const glm::vec3& b) {
    if (a.x != b.x) return a.x < b.x;
    if (a.y != b.y) return a.y < b.y;
    return a.z < b.z;
  }

  std::vector<Corner> corners_;
  // Per hit, at most three runs (one per corner), as [begin, end) in corners_.
  std::vector<std::array<std::pair<uint32_t, uint32_t>, 3>> runs_;
  std::vector<uint8_t> runCount_;
};

// Sorts hits by (traversal t, instance, triangle) and keeps one hit per
// crossing (CrossingRule). Each hit is tested only against the earlier
// kept hits it shares a corner with (SharedCorners): O(n log n) for n
// unrelated layers (1,000 stacked quads: no pair tests instead of
// 500,000). Equivalent to testing every earlier kept hit in order, since
// all others are Crossing::Two.
void sortAndMergeCrossings(const Scene& scene, const Ray& ray, std::vector<GatheredHit>* hits) {
  std::sort(hits->begin(), hits->end(), [](const GatheredHit& a, const GatheredHit& b) {
    if (a.traversalT != b.traversalT) return a.traversalT < b.traversalT;
    if (a.instance != b.instance) return a.instance < b.instance;
    return a.triangle < b.triangle;
  });
  const size_t n = hits->size();
  const SharedCorners shared(scene, *hits);
  const CrossingRule rule(scene, ray.origin, ray.direction);
  std::vector<uint8_t> kept(n, 0);
  std::vector<uint32_t> candidates;
  for (uint32_t i = 0; i < n; ++i) {
    shared.earlierNeighbours(
        i, [&](uint32_t j) { return kept[j] != 0; }, &candidates);
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

}  // namespace

}  // namespace rastray
