// The recursive radiance integrator. A ray's surfaces (transparency.cpp)
// are shaded front to back by the context's Shader and composited with
// premultiplied `over`; shading a mirror, glass or lit surface asks the
// Shader's SecondaryRayTracer and LightVisibility for more rays, which
// come back here (traceRadiance, traceTransmittance) with the same
// context, one depth further.
#include <algorithm>
#include <cmath>
#include <limits>

#include "raytrace/ray_caster_parts.h"
#include "raytrace/ray_offset.h"

namespace rastray {

namespace {

// Defined below, each after the function that uses it.
struct OriginInputs {
  FloatTriangle triangle;
  glm::dvec3 side, lift;
};
OriginInputs originInputs(const CasterState& state, const SurfacePoint& from, const glm::dvec3& direction);
glm::vec3 secondaryRayOrigin(const CasterState& state, const SurfacePoint& from, const glm::dvec3& direction,
                             glm::dvec3* sideOut = nullptr);
FloatTriangle floatTriangle(const Scene& scene, uint32_t instance, uint32_t triangle);
bool leaveSeam(const CasterState& state, const SurfacePoint& from, const glm::dvec3& direction,
               const GatheredHit& first, glm::vec3* origin, FloatTriangle* planes, glm::dvec3* sides,
               size_t* count);
Ray secondaryRay(const glm::vec3& origin, const glm::dvec3& direction, double tFar);
Composited composite(const CasterState& state, const RayTreeContext& context, int depth, float throughput,
                     const HitGather& g, const std::vector<SurfaceCrossing>& crossings, DeepTarget deep);

}  // namespace

// --- secondary and shadow rays -------------------------------------------------------

glm::vec3 traceRadiance(const CasterState& state, const RayTreeContext& context, const SurfacePoint& from,
                        const glm::dvec3& direction, RayKind kind, int depth, float throughput) {
  const ShadingOptions& shading = state.options.shading;
  if (depth > shading.maxDepth || !(throughput >= shading.minThroughput)) return glm::vec3(0.0f);
  context.count(kind);
  const glm::dvec3 dir = glm::normalize(direction);
  // This ray's surface list stays in use while their own rays are traced
  // (the next level of the scratch).
  const RayScratch::Use use(*context.scratch);
  HitGather& g = use.level().gather;
  std::vector<SurfaceCrossing>& crossings = use.level().crossings;
  g.mode = GatherMode::Radiance;
  g.primary = false;
  constexpr double kNoEnd = std::numeric_limits<double>::infinity();
  glm::dvec3 side;
  glm::vec3 origin = secondaryRayOrigin(state, from, dir, &side);
  g.ray = secondaryRay(origin, dir, kNoEnd);
  g.hits.clear();
  GatheredHit first = intersectClosest(state, g, /*coherent=*/false);
  // A seam neighbour the ray leaves is not what it sees (ray_offset.h,
  // "Concave seams"): off its plane too, and again.
  FloatTriangle planes[4] = {floatTriangle(state.scene, from.instance, from.triangle)};
  glm::dvec3 sides[4] = {side};
  size_t count = 1;
  while (count < 4 && leaveSeam(state, from, dir, first, &origin, planes, sides, &count)) {
    g.ray = secondaryRay(origin, dir, kNoEnd);
    g.hits.clear();
    first = intersectClosest(state, g, /*coherent=*/false);
  }
  collectCrossings(state, g, first, &crossings);
  return glm::vec3(shadeRay(state, context, kind, depth, throughput, g, crossings, DeepTarget{}).color);
}

namespace {

// g set up for a shadow ray's first query from `origin` along unit `dir`.
void startShadowGather(const glm::vec3& origin, const glm::dvec3& dir, double distance, HitGather& g) {
  g.mode = GatherMode::Shadow;
  g.primary = false;
  g.ray = secondaryRay(origin, dir, distance);
  g.hits.clear();
}

// A shadow ray's first query from `point` towards unit `dir`: g set up
// for it (startShadowGather from the offset origin); returns the origin,
// and its offset side in *side.
glm::vec3 startShadowRay(const CasterState& state, const SurfacePoint& point, const glm::dvec3& dir,
                         double distance, HitGather& g, glm::dvec3* side) {
  const glm::vec3 origin = secondaryRayOrigin(state, point, dir, side);
  startShadowGather(origin, dir, distance, g);
  return origin;
}

// The rest of traceTransmittance once its first occlusion query has
// answered `blocked` (g as traceOcclusion left it).
glm::vec3 finishTransmittance(const CasterState& state, const RayTreeContext& context,
                              const SurfacePoint& point, const glm::dvec3& dir, double distance,
                              glm::vec3 origin, const glm::dvec3& side, HitGather& g, bool blocked) {
  // Blocked: by a seam neighbour the ray leaves (ray_offset.h, "Concave
  // seams")? The first hit says; then off its plane too, and again.
  FloatTriangle planes[4] = {floatTriangle(state.scene, point.instance, point.triangle)};
  glm::dvec3 sides[4] = {side};
  size_t count = 1;
  while (blocked && count < 4) {
    g.mode = GatherMode::Radiance;
    g.hits.clear();
    const GatheredHit first = intersectClosest(state, g, /*coherent=*/false);
    g.mode = GatherMode::Shadow;
    g.hits.clear();
    if (!leaveSeam(state, point, dir, first, &origin, planes, sides, &count)) break;
    g.ray = secondaryRay(origin, dir, distance);
    blocked = traceOcclusion(state, g);
  }
  glm::vec3 result(blocked ? 0.0f : 1.0f);
  // Each surface's transmittance was evaluated by the filter that let the
  // ray through it (GatheredHit::transmittance): not again here.
  if (!blocked)
    for (const GatheredHit& h : g.hits) result *= h.transmittance;
  if (context.recorder) {
    const GatheredHit* front = g.hits.empty() ? nullptr : &g.hits.front();
    const size_t record = context.recorder->begin(
        RayKind::Shadow, context.recorder->shadingDepth(), g.ray, front ? front->instance : kNoId,
        front ? front->triangle : kNoId, front ? double(front->traversalT) : 0.0);
    context.recorder->finish(record, blocked ? 0 : int(g.hits.size()), glm::vec4(result, 1.0f));
  }
  return result;
}

}  // namespace

glm::vec3 traceTransmittance(const CasterState& state, const RayTreeContext& context,
                             const SurfacePoint& point, const glm::dvec3& toLight, double distance) {
  context.count(RayKind::Shadow);
  const glm::dvec3 dir = glm::normalize(toLight);
  const RayScratch::Use use(*context.scratch);
  HitGather& g = use.level().gather;
  glm::dvec3 side;
  const glm::vec3 origin = startShadowRay(state, point, dir, distance, g, &side);
  const bool blocked = traceOcclusion(state, g);
  return finishTransmittance(state, context, point, dir, distance, origin, side, g, blocked);
}

void traceTransmittances(const CasterState& state, const RayTreeContext& context, size_t n,
                         const SurfacePoint* const* points, const glm::dvec3* toLight, const double* distance,
                         glm::vec3* out, bool packets, const int* lanes) {
  if (!lanes && (context.recorder || !packets)) {
    for (size_t k = 0; k < n; ++k)
      out[k] = traceTransmittance(state, context, *points[k], toLight[k], distance[k]);
    return;
  }
  HitGather* gathers = context.scratch->packet.data();
  glm::dvec3 dirs[kShadowPacket], sides[kShadowPacket];
  glm::vec3 origins[kShadowPacket];
  bool blocked[kShadowPacket];
  for (size_t first = 0; first < n; first += kShadowPacket) {
    const size_t m = std::min(kShadowPacket, n - first);
    // The lanes' origins together (errorBoundRayOrigins: the certification
    // in double SIMD lanes), then each lane's gather as startShadowRay sets it.
    FloatTriangle triangles[kShadowPacket];
    glm::dvec3 positions[kShadowPacket], lifts[kShadowPacket];
    float b1[kShadowPacket], b2[kShadowPacket];
    for (size_t k = 0; k < m; ++k) {
      context.count(RayKind::Shadow);
      const SurfacePoint& p = *points[first + k];
      dirs[k] = glm::normalize(toLight[first + k]);
      const OriginInputs in = originInputs(state, p, dirs[k]);
      triangles[k] = in.triangle;
      sides[k] = in.side;
      lifts[k] = in.lift;
      positions[k] = p.position;
      b1[k] = p.b1;
      b2[k] = p.b2;
    }
    if (state.options.offset == RayOffsetMethod::FloatUlps)
      for (size_t k = 0; k < m; ++k)
        origins[k] = floatUlpsRayOrigin(glm::vec3(positions[k] + lifts[k]), glm::vec3(sides[k]));
    else
      errorBoundRayOrigins(m, triangles, positions, b1, b2, sides, lifts, origins);
    for (size_t k = 0; k < m; ++k) startShadowGather(origins[k], dirs[k], distance[first + k], gathers[k]);
    traceOcclusionPacket(state, gathers, m, blocked, lanes);
    for (size_t k = 0; k < m; ++k)
      out[first + k] = finishTransmittance(state, context, *points[first + k], dirs[k], distance[first + k],
                                           origins[k], sides[k], gathers[k], blocked[k]);
  }
}

namespace {

// Where a secondary or shadow ray leaving `from` along `direction`
// starts (raytrace/ray_offset.h): the one place both kinds get it, hybrid's
// included.
glm::vec3 secondaryRayOrigin(const CasterState& state, const SurfacePoint& from, const glm::dvec3& direction,
                             glm::dvec3* sideOut) {
  const OriginInputs in = originInputs(state, from, direction);
  if (sideOut) *sideOut = in.side;
  if (state.options.offset == RayOffsetMethod::FloatUlps)
    return floatUlpsRayOrigin(glm::vec3(from.position + in.lift), glm::vec3(in.side));
  return errorBoundRayOrigin(in.triangle, from.position, from.b1, from.b2, in.side, in.lift);
}

// What the offset of a ray leaving `from` along `direction` starts from:
// its triangle, the side it leaves on and the terminator lift.
OriginInputs originInputs(const CasterState& state, const SurfacePoint& from, const glm::dvec3& direction) {
  glm::dvec3 side = offsetSideNormal(from.geometricNormal, direction);
  const Scene& scene = state.scene;
  const glm::uvec3 t = scene.triangle(from.instance, from.triangle);
  const FloatTriangle triangle = {scene.positions[t.x], scene.positions[t.y], scene.positions[t.z]};
  glm::dvec3 lift(0.0);
  if (state.options.terminator == ShadowTerminator::ShadingNormal &&
      scene.instances[from.instance].normals == NormalSource::Authored) {
    // Lifted towards the tangent planes on the side of the shading normals
    // the ray leaves; the origin then sits on that side of the plane.
    const double s = glm::dot(from.shadingNormal, direction) >= 0.0 ? 1.0 : -1.0;
    const glm::dvec3 liftSide = s * from.geometricNormal;
    lift = terminatorLift(triangle, {scene.normals[t.x], scene.normals[t.y], scene.normals[t.z]},
                          from.position, from.b1, from.b2, s);
    if (!(glm::dot(lift, liftSide) > 0.0)) {
      lift = glm::dvec3(0.0);
    } else if (glm::dot(liftSide, side) < 0.0) {
      // The terminator: the ray leaves through the other face of the flat
      // triangle. From above it, the ray must not come back through it.
      if (liftedRayCrossesItsTriangle(triangle, from.position, lift, direction))
        lift = glm::dvec3(0.0);
      else
        side = liftSide;
    }
  }
  return {triangle, side, lift};
}

FloatTriangle floatTriangle(const Scene& scene, uint32_t instance, uint32_t triangle) {
  const glm::uvec3 t = scene.triangle(instance, triangle);
  return {scene.positions[t.x], scene.positions[t.y], scene.positions[t.z]};
}

// Whether `first`, the first surface a ray from `from` along `direction`
// met, is a seam neighbour the ray leaves (ray_offset.h, "Concave seams"):
// its plane passes through the point within the point's error, and the
// ray goes to the side of it where the point's own surface lies. If so,
// adds its plane to planes/sides (count < 4 on entry) and moves *origin
// off all of them.
bool leaveSeam(const CasterState& state, const SurfacePoint& from, const glm::dvec3& direction,
               const GatheredHit& first, glm::vec3* origin, FloatTriangle* planes, glm::dvec3* sides,
               size_t* count) {
  if (first.instance == kNoId) return false;
  const FloatTriangle other = floatTriangle(state.scene, first.instance, first.triangle);
  for (size_t i = 0; i < *count; ++i)
    if (planes[i] == other) return false;  // its own surface, or one already left: a real hit
  if (!(planeDistance(other, from.position) <= seamTolerance(planes[0], from.position, *origin)))
    return false;
  const glm::dvec3 side = seamSide(planes[0], other, direction);
  if (!(glm::dot(side, direction) > 0.0)) return false;  // towards the neighbour's far side: blocked
  planes[*count] = other;
  sides[*count] = side;
  ++*count;
  const glm::vec3 moved = offsetOffPlanes(planes, sides, *count, *origin);
  if (moved == *origin) return false;
  *origin = moved;
  return true;
}

// A secondary or shadow ray from `origin` (float, as Embree traces it).
Ray secondaryRay(const glm::vec3& origin, const glm::dvec3& direction, double tFar) {
  Ray ray;
  ray.origin = glm::dvec3(origin);
  ray.direction = direction;
  ray.tNear = 0.0;
  ray.tFar = tFar;
  ray.depthPerT = 1.0;
  return ray;
}

}  // namespace

// --- shading a ray's surfaces ----------------------------------------------------

Composited shadeRay(const CasterState& state, const RayTreeContext& context, RayKind kind, int depth,
                    float throughput, const HitGather& g, const std::vector<SurfaceCrossing>& crossings,
                    DeepTarget deep) {
  if (!context.recorder) return composite(state, context, depth, throughput, g, crossings, deep);
  const SurfaceCrossing* front = crossings.empty() ? nullptr : &crossings.front();
  const size_t record =
      context.recorder->begin(kind, depth, g.ray, front ? front->refined.instance : kNoId,
                              front ? front->refined.triangle : kNoId, front ? front->planeT : 0.0);
  const Composited result = composite(state, context, depth, throughput, g, crossings, deep);
  context.recorder->finish(record, result.layers, result.color);
  return result;
}

namespace {

// Front-to-back compositing of a ray's surfaces with premultiplied `over`
// (SPEC §4): acc = acc + (1 − acc.a)·layer. Stops after the opaque
// surface or once the remaining transmittance 1 − acc.a is below
// options.transparencyCutoff. `deep` receives each surface's own
// unattenuated premultiplied colour.
Composited composite(const CasterState& state, const RayTreeContext& context, int depth, float throughput,
                     const HitGather& g, const std::vector<SurfaceCrossing>& crossings, DeepTarget deep) {
  Composited acc;
  for (const SurfaceCrossing& crossing : crossings) {
    const float remaining = 1.0f - acc.color.a;
    if (remaining < state.options.transparencyCutoff) {
      // Stopped with surfaces left: the deep output says so (SPEC §6).
      if (deep.samples && !deep.samples->empty()) deep.samples->back().cutOff = true;
      break;
    }
    glm::vec4 c;
    {
      const ShadingDepthScope shading(context.recorder, depth);
      if (g.primary) {
        // A primary surface: through the shading kernel, as the rasterizer
        // (hybrid) shades the same refined hit.
        ShadeHit hit;
        hit.instance = crossing.refined.instance;
        hit.triangle = crossing.refined.triangle;
        hit.b1 = crossing.refined.b1;
        hit.b2 = crossing.refined.b2;
        hit.direction = g.ray.direction;
        hit.footprintPosition = g.imagePosition;
        hit.throughput = throughput * remaining;
        shadePrimaryHits(*context.shader, &hit, 1, &c, shadingPath(state));
      } else {
        const SurfacePoint p = makeSurfacePoint(state.scene, crossing.refined);
        c = context.shader->shade(p, g.ray.direction, TextureFootprint{}, depth, throughput * remaining);
      }
    }
    acc.color += remaining * c;
    ++acc.layers;
    if (deep.samples) {
      DeepSample s;
      s.color = c;
      s.depth = crossing.traversalDepth;
      s.instance = crossing.refined.instance;
      s.triangle = crossing.refined.triangle;
      s.sample = deep.sampleIndex;
      deep.samples->push_back(s);
    }
    if (!crossing.blend) break;
    context.count(RayKind::Transparency);  // the ray continues behind this surface
  }
  return acc;
}

}  // namespace

}  // namespace rastray
