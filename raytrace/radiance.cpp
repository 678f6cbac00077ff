// The recursive radiance integrator. A ray's surfaces (transparency.cpp)
// are shaded front to back by the context's Shader and composited with
// premultiplied `over`; shading a mirror, glass or lit surface asks the
// Shader's SecondaryRayTracer and LightVisibility for more rays, which
// come back here (traceRadiance, traceTransmittance) with the same
// context, one depth further.
#include <cmath>
#include <limits>

#include "raytrace/ray_caster_parts.h"
#include "raytrace/ray_offset.h"

namespace rastray {

namespace {

// Defined below, each after the function that uses it.
glm::vec3 secondaryRayOrigin(const CasterState& state, const SurfacePoint& from, const glm::dvec3& direction);
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
  g.ray = secondaryRay(secondaryRayOrigin(state, from, dir), dir, std::numeric_limits<double>::infinity());
  g.hits.clear();
  collectCrossings(state, g, intersectClosest(state, g, /*coherent=*/false), &crossings);
  return glm::vec3(shadeRay(state, context, kind, depth, throughput, g, crossings, DeepTarget{}).color);
}

glm::vec3 traceTransmittance(const CasterState& state, const RayTreeContext& context,
                             const SurfacePoint& point, const glm::dvec3& toLight, double distance) {
  context.count(RayKind::Shadow);
  const glm::dvec3 dir = glm::normalize(toLight);
  const RayScratch::Use use(*context.scratch);
  HitGather& g = use.level().gather;
  g.mode = GatherMode::Shadow;
  g.primary = false;
  g.ray = secondaryRay(secondaryRayOrigin(state, point, dir), dir, distance);
  g.hits.clear();
  const bool blocked = traceOcclusion(state, g);
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

namespace {

// Where a secondary or shadow ray leaving `from` along `direction`
// starts (raytrace/ray_offset.h): the one place both kinds get it.
glm::vec3 secondaryRayOrigin(const CasterState& state, const SurfacePoint& from,
                             const glm::dvec3& direction) {
  const glm::dvec3 side = offsetSideNormal(from.geometricNormal, direction);
  if (state.options.offset == RayOffsetMethod::FloatUlps)
    return floatUlpsRayOrigin(glm::vec3(from.position), glm::vec3(side));
  const Scene& scene = state.scene;
  const glm::uvec3 t = scene.triangle(from.instance, from.triangle);
  const FloatTriangle triangle = {scene.positions[t.x], scene.positions[t.y], scene.positions[t.z]};
  return errorBoundRayOrigin(triangle, from.position, from.b1, from.b2, side);
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
