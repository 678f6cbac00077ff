// The pixel-order ray caster on Embree 3. Only raytrace/ includes Embree.
//
// It renders images on its own (render) and, for the hybrid renderer,
// serves the rasterizer's shading through the SecondaryRayTracer and
// LightVisibility interfaces of common/shading.h.
//
// Layout (ray_caster_parts.h is what the parts share):
//   ray_caster.cpp          this class: binding, the report of passes,
//                           counters, the traced pixel
//   primary_visibility.cpp  primary rays: tiles, packets, flat and deep output
//   radiance.cpp            the recursive radiance integrator: compositing a
//                           ray's surfaces, reflection, refraction and shadow rays
//   transparency.cpp        transparency continuation: filter callbacks, the
//                           crossing rule and merge, a ray's surface list
//   embree_scene.cpp        the Embree device and scene; ray_offset.cpp:
//                           where secondary rays start
//
// Contract
// - Primary rays: camera.primaryRay(pixel + sample position) over
//   [tNear, tFar] (the near and far planes, as the rasterizer clips), in
//   16×16-pixel tiles in parallel (TBB). Each hit is refined with
//   refineHit() before shading, exactly as the rasterizer does, so both
//   shade a shared (instance, triangle) from identical inputs. Two depths
//   per surface, named apart in the code: the traversal depth (Embree's
//   float t × depthPerT) and the plane depth (the double intersection with
//   the triangle's plane × depthPerT, where it is shaded). Z is the
//   traversal depth of the front-most surface, the ray caster's own
//   precision (the compare tool measures it); IDs are Embree's
//   (geomID, primID) = SPEC §1 (instance, triangle).
// - Transparency continuation: filter callbacks collect every BLEND hit
//   along the ray and reject it, so one traversal continues from the same t
//   with no epsilon; opaque (and refractive, and covered MASK) hits are
//   accepted and end it. The collected hits in front of the stopping one
//   are deduplicated (below), ordered by (plane t, instance, triangle)
//   and composited front to back with premultiplied `over` until the first
//   opaque surface or until the remaining transmittance 1 − α_acc is below
//   RayOptions::transparencyCutoff (1e-4). MASK hits with alpha < cutoff
//   are rejected and ignored. "rays.transparency" counts BLEND layers a ray
//   continued behind.
// - One crossing per surface (SPEC §1, §3): every triangle is its own
//   layer, coincident duplicates included. Two reported hits are merged
//   only when they are the same (instance, triangle), or when their
//   triangles share a vertex position and lie on opposite sides of an edge
//   through it seen along the ray (the ray went through their shared edge
//   or vertex); the kept one is decided by an exact side test, as the
//   rasterizer's top-left rule decides (CrossingRule in transparency.cpp).
//   Shadow rays follow the same rule, so a shared edge attenuates once.
// - Culling (constructor): single-sided triangles seen from the culled side
//   are rejected by a filter on those geometries, for every ray kind.
// - Cut-off (SPEC §6): when compositing stops with layers left, the last
//   deep sample of that sample gets DeepSample::cutOff.
// - Shadow rays (rtcOccluded16, up to 14 to a packet) run to the light
//   (distance, or +inf for directional lights); occlusion filters accept opaque hits (blocked)
//   and collect the rest, whose Shader::shadowTransmittance values multiply
//   (BLEND 1 − α, refractive transmission × C; SPEC §5). A blocked one
//   asks for its first hit (one rtcIntersect1): when that surface passes
//   through the lit point and the ray leaves it (a concave seam, ray_offset.h)
//   the origin moves off it too and the ray is traced again. RayOptions::
//   shadows false (--shadows none): no shadow rays, every light unoccluded,
//   the pass reported left out.
// - Secondary and shadow rays (radiance(), transmittance(): the only
//   secondary-ray origins, hybrid's included) start on the side they leave,
//   tnear 0, at the origin RayOptions::offset picks (raytrace/ray_offset.h):
//   ErrorBound (default) a float origin above the hit's float triangle by
//   at least Embree's error bound for that origin (checked, not estimated),
//   which scales with the triangle's size and shape, plus at most one float
//   spacing of one coordinate (0.0625 at 1e6) — so the ray cannot hit the
//   surface it leaves again, for every direction leaving the plane by more
//   than ~1e-5 (times the triangle's aspect ratio); FloatUlps the Ray
//   Tracing Gems ch. 6 offset of 256 ULPs of the hit point's own
//   coordinates (16 units at 1e6). On meshes with authored normals the
//   point is first lifted towards the smooth surface the normals describe
//   (RayOptions::terminator, ray_offset.h "The shadow terminator"). They
//   are shaded at the depth the Shader gives them; --max-depth and the
//   throughput cut-off come from ShadingOptions.
// - Deep samples (keepSamples): for every sample, every surface its primary
//   ray composited, front to back, each with its OWN unattenuated
//   premultiplied colour (what Shader::shade returns for it) and its
//   traversal depth, ending with the opaque one; compositing them with `over` per sample and box-
//   filtering the samples reproduces the flat pixel. Samples that hit
//   nothing have no entries.
// - Flat output: box filter of the samples' premultiplied colours; Z and
//   IDs of the front-most surface (transparent or opaque) of the sample
//   nearest the pixel centre (centreSampleIndex).
// - Counters: rays.primary, rays.shadow, rays.reflection, rays.refraction,
//   rays.transparency, always all five, per thread and summed.
// - Frames: the constructor builds the BVH once; bind() and render() may
//   follow any number of times (another camera, other options), each
//   render() giving exactly what a new caster would. Scratch buffers are
//   per thread and kept across frames: no heap allocation per ray or per
//   sample once warm (deep output: one buffer per tile, one flat image).
// - Timings: render() reports "raytrace.primary" (primary ray setup and
//   traversal, filter callbacks included) and "raytrace.shade" (surface
//   lists, refinement, shading with all secondary and shadow rays), which
//   add up to the wall time of the tile loop: each tile traces all its
//   primary rays, then shades them, and the loop's wall time is split in
//   proportion to the thread-seconds summed per phase (three clock reads
//   per tile); with keepSamples also "raytrace.deep_output" (assembly).
// - Tracing: traceDebugPixel() re-traces one pixel with single rays and
//   returns its ray tree (RayRecord, each ray before the rays its surfaces
//   spawned); render() with RayOptions::trace records that tree into the
//   sink as TraceStage::Ray events (rayTraceEvent). The trace context is
//   passed down the recursion (the traced pixel gets a Shader of its own
//   whose callbacks carry it): no globals, one pointer test per ray when
//   nothing is traced, and traced rays are not counted.
// - Never prints. Embree device errors are kept and raised as
//   std::runtime_error("embree: ...") by render(), traceDebugPixel() and
//   throwIfError().
#pragma once

#include <glm/glm.hpp>
#include <memory>
#include <vector>

#include "common/analysis.h"
#include "common/camera.h"
#include "common/cull.h"
#include "common/interrupt.h"
#include "common/render_output.h"
#include "common/scene.h"
#include "common/shading.h"
#include "common/trace.h"

namespace rastray {

// Where secondary and shadow rays start (raytrace/ray_offset.h).
enum class RayOffsetMethod {
  ErrorBound,  // above the hit's triangle by Embree's error bound for the origin traced (after pbrt-v4)
  FloatUlps,   // a fixed count of float ULPs of the hit point's own coordinates (Ray Tracing Gems ch. 6)
};
const char* toString(RayOffsetMethod method);

// Where a secondary or shadow ray starts on a mesh with interpolated
// normals (raytrace/ray_offset.h, "The shadow terminator").
enum class ShadowTerminator {
  None,           // on the flat triangle: low-poly smooth meshes show their facets in the shadow edge
  ShadingNormal,  // lifted towards the vertices' tangent planes (Hanika 2021): a smooth terminator
};
const char* toString(ShadowTerminator terminator);

struct RayOptions {
  int spp = 1;
  RayOffsetMethod offset = RayOffsetMethod::ErrorBound;
  ShadowTerminator terminator = ShadowTerminator::ShadingNormal;
  // false (--shadows none): no shadow rays; every light reaches every
  // point unoccluded (V = 1 in common/shading.h), for primary and
  // secondary hits alike, and the report says the pass was left out.
  bool shadows = true;
  ShadingOptions shading;            // maxDepth, throughput cut-off, texture filter
  float transparencyCutoff = 1e-4f;  // stop compositing once remaining transmittance is below
  bool keepSamples = false;          // fill RenderOutput::samples (deep output, crossval)
  // Primary rays in coherent packets where that is faster: measured faster
  // without BLEND materials, slower with them (lanes diverge over the many
  // rejected layer hits), so scenes with BLEND trace single rays unless
  // forcePackets. false: always single rays (the scalar reference path).
  // Packets and single rays find the same hits except where a ray meets
  // two triangles at exactly the same t (a shared edge or corner), where
  // Embree keeps the first its traversal order finds.
  bool packets = true;
  bool forcePackets = false;
  // Shadow rays of one light from the shading kernel's lit lanes traced
  // 14 at a time (rtcOccluded16: LightVisibility::transmittances), in the
  // ray caster and in hybrid alike. Every occlusion query goes through
  // rtcOccluded16, a single ray as a packet of one, and a lane's answer
  // does not depend on its lane or its packet mates, so the pictures are
  // the same either way (--no-shadow-packets: one ray per packet).
  bool shadowPackets = true;
  // Rays per packet: 4, 8 or 16 (rtcIntersect4/8/16), each packet a compact
  // block of pixels (Morton order within the tile). 16 measured fastest on
  // this AVX-512 machine (the engine model, 1920×1080, 1 thread: primary
  // phase ≈ 73 ms against ≈ 83 ms for 8).
  int packetWidth = 16;
  int tileSize = 16;  // pixels per side of a parallel work item
  // render() records the ray tree of trace.pixel (TraceStage::Ray events,
  // one per ray: rayTraceEvent) into trace.sink after the image.
  TraceRequest trace;
  // Stops the render at its next tile when cancelled (common/interrupt.h);
  // nullptr: a signal alone stops it. Must outlive the render.
  const CancelToken* cancel = nullptr;
};

// One traced ray of a pixel's ray tree (RayCaster::traceDebugPixel), in
// tree order: each ray before the rays its surfaces spawned.
struct RayRecord {
  RayKind kind = RayKind::Primary;
  int depth = 0;   // primary 0, each bounce +1; shadow rays: the depth of the ray whose hit they light
  int sample = 0;  // sample index within the pixel
  glm::dvec3 origin{0.0};
  glm::dvec3 direction{0.0};
  double tNear = 0.0, tFar = 0.0;
  // The front-most surface the ray met (kNoId: none), its t (the plane t
  // in double; shadow rays: Embree's float t of the first surface passed
  // through), and how many surfaces it composited (transparent layers and
  // the opaque one; shadow rays: passed through, 0 when blocked).
  uint32_t instance = kNoId, triangle = kNoId;
  double t = 0.0;
  int layers = 0;
  // Primary and secondary rays: premultiplied RGBA they return (alpha 1
  // for secondary rays that hit something). Shadow rays: the per-channel
  // transmittance in rgb, alpha 1.
  glm::vec4 contribution{0.0f};
};

// A ray of the tree as a trace event (TraceStage::Ray): depth is the ray's
// (shadow rays: the lit surface's + 1), outcome "hit" or "miss" (shadow
// rays: "blocked", "unoccluded" or "through"), values kind, origin, dir,
// tnear, tfar, t and layers (hits), surfaces (shadow rays passing
// through), contribution or transmittance.
TraceEvent rayTraceEvent(const RayRecord& record);

class RayCaster : public SecondaryRayTracer, public LightVisibility {
 public:
  // Builds the Embree device and scene from the shared triangle store.
  // `scene` must outlive the caster; `analysis` is copied. `cull` drops
  // single-sided triangles seen from the culled side by every ray, primary
  // and secondary (SPEC §3), through a filter on those geometries only.
  RayCaster(const Scene& scene, const SceneAnalysis& analysis, CullMode cull = CullMode::None);
  ~RayCaster() override;
  RayCaster(const RayCaster&) = delete;
  RayCaster& operator=(const RayCaster&) = delete;

  // Binds a camera and options: required before render() and before the
  // interfaces below are used (hybrid rendering). May be called again
  // between frames; the BVH is kept.
  void bind(const Camera& camera, const RayOptions& options);

  // One frame of the bound camera; repeatable (identical output each time).
  RenderOutput render();

  // SecondaryRayTracer / LightVisibility (thread-safe; count rays by kind).
  glm::vec3 radiance(const SurfacePoint& from, const glm::dvec3& direction, RayKind kind, int depth,
                     float throughput) const override;
  glm::vec3 transmittance(const SurfacePoint& point, int lightIndex, const glm::dvec3& toLight,
                          double distance) const override;
  void transmittances(int lightIndex, size_t n, const SurfacePoint* const* points, const glm::dvec3* toLight,
                      const double* distance, glm::vec3* out) const override;
  // transmittances() of n ≤ 14 rays in one packet, ray k in lane lanes[k]
  // (distinct, 0…15), the other lanes empty: for the test that a lane's
  // answer depends neither on its lane nor on its packet mates.
  void transmittancesInLanes(size_t n, const SurfacePoint* const* points, const glm::dvec3* toLight,
                             const double* distance, const int* lanes, glm::vec3* out) const;

  // Rays traced since the last bind(), render() or resetCounters(), by
  // kind (SPEC §8: zero for what the scene does not need). render()'s
  // output counts its own frame's rays; a hybrid frame loop calls
  // resetCounters() before each frame.
  CounterSet counters() const;
  void resetCounters();

  // Throws the first Embree error since the last check (render() and
  // traceDebugPixel() check on their own; hybrid rendering calls this after
  // the rasterizer is done with the interfaces above).
  void throwIfError() const;

  // The ray tree of one pixel (all its samples), traced with single rays
  // exactly as render() traces them; does not touch the counters.
  std::vector<RayRecord> traceDebugPixel(glm::ivec2 pixel) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rastray
