// Internal to raytrace/: what the parts of the ray caster share. The
// contract is in ray_caster.h; the parts, in the order a ray meets them:
//
//   ray_caster.cpp          RayCaster: binding, the report of passes,
//                           counters, and the traced pixel (its ray tree as
//                           records and as trace events)
//   primary_visibility.cpp  primary rays: tiles in parallel, coherent packets
//                           or single rays, the flat and deep output
//   radiance.cpp            the recursive radiance integrator: a ray's
//                           surfaces composited front to back through the
//                           Shader, whose reflection, refraction and shadow
//                           rays come back here
//   transparency.cpp        transparency continuation: the traversals whose
//                           filter callbacks gather the surfaces a ray
//                           passes through, the crossing rule that keeps one
//                           hit per crossing, and a ray's front-to-back
//                           surface list
//
// This header reads in that order too: the shared state, the context one
// ray tree is traced in, then what each part offers the others.
#pragma once

#include <embree3/rtcore.h>
#include <pmmintrin.h>
#include <tbb/enumerable_thread_specific.h>
#include <xmmintrin.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <type_traits>
#include <vector>

#include "common/analysis.h"
#include "common/camera.h"
#include "common/cull.h"
#include "common/hit.h"
#include "common/render_output.h"
#include "common/scene.h"
#include "common/shading.h"
#include "common/shading_kernel.h"
#include "common/surface.h"
#include "raytrace/embree_scene.h"
#include "raytrace/ray_caster.h"

namespace rastray {

constexpr float kInf = std::numeric_limits<float>::infinity();

// Rays per shadow-ray packet: at most 14 of an RTCRay16's 16 lanes. Embree
// 3.13.5's packet traversal (BVHNIntersectorKHybrid::occluded, incoherent
// context) goes on as a packet only while more than 14 of 16 lanes are
// active (switchThresholdIncoherent) and otherwise traverses each active
// lane alone with the single-ray box and triangle tests; there a lane's
// answer is its own, whatever its lane and its mates. Packet-mode leaf
// tests round differently: 16 lanes would let a lane's mates decide a ray
// that starts on a neighbour's plane (tested:
// ShadowPackets.ALanesAnswerDependsNeitherOnItsLaneNorOnItsMates).
constexpr size_t kShadowPacket = 14;

// Rays traced, by RayKind.
using RayCounts = std::array<uint64_t, kRayKindCount>;

// --- what a ray carries ------------------------------------------------------

// A surface a ray passed through (or stopped at), as Embree reported it.
struct GatheredHit {
  float traversalT = kInf;  // Embree's float t: where its traversal found the hit
  uint32_t instance = kNoId, triangle = kNoId;
  float u = 0.0f, v = 0.0f;  // Embree's barycentrics
  // Shadow rays: Shader::shadowTransmittance of the surface, evaluated once
  // by the filter that let the ray through it (1 for radiance rays).
  glm::vec3 transmittance{1.0f};
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

// One surface of a ray's front-to-back list: a BLEND layer the ray
// continues behind, or the surface it stops at. It carries two depths:
// - traversalDepth, Embree's float t × depthPerT: what the ray caster's
//   own traversal found, reported as Z (the compare tool measures it);
// - refined.depth, the plane depth: planeT × depthPerT, with planeT the
//   ray's intersection with the triangle's plane in double (refineHit),
//   where the surface is shaded exactly as the rasterizer shades it.
struct SurfaceCrossing {
  SampleHit refined;  // refineHit(): clamped barycentrics, depth = the plane depth
  float traversalDepth = 0.0f;
  // The plane t in double (Embree's t when the plane cannot be
  // intersected): the list's order, then instance and triangle.
  double planeT = 0.0;
  bool blend = false;  // a BLEND layer: the ray continues behind it
};

// Scratch one thread reuses for the secondary and shadow rays it traces, so
// that once warm they allocate nothing: a stack of levels, one per ray in
// flight on the thread (a ray's surface list stays in use while the rays
// its surfaces spawn are traced). Held through RayScratch::Use.
class RayScratch {
 public:
  struct Level {
    HitGather gather;
    std::vector<SurfaceCrossing> crossings;
  };

  // The next free level, for one ray, released when the Use ends.
  class Use {
   public:
    explicit Use(RayScratch& scratch) : scratch_(scratch), level_(scratch.push()) {}
    ~Use() { --scratch_.top_; }
    Use(const Use&) = delete;
    Use& operator=(const Use&) = delete;
    Level& level() const { return level_; }

   private:
    RayScratch& scratch_;
    Level& level_;
  };

 private:
  Level& push() {
    // unique_ptr: growing the stack must not move the levels in use.
    if (top_ == levels_.size()) levels_.push_back(std::make_unique<Level>());
    return *levels_[top_++];
  }
  std::vector<std::unique_ptr<Level>> levels_;
  size_t top_ = 0;

 public:
  // One gather per lane of a shadow-ray packet (traceTransmittances). A
  // batch of shadow rays spawns no batch of its own (its lanes' seam
  // loops trace single rays), so one set serves the thread.
  std::array<HitGather, kShadowPacket> packet;
};

// What each thread tracing rays keeps: its counts since bind() and its
// scratch (kept across renders).
struct ThreadRays {
  RayCounts counts{};
  RayScratch scratch;
};

// --- state -------------------------------------------------------------------

// The caster's state: built by the constructor, completed by bind(), then
// only read by the parts (the per-thread counts and scratch excepted).
struct CasterState {
  CasterState(const Scene& s, const SceneAnalysis& a, CullMode c) : scene(s), analysis(a), cull(c) {}

  const Scene& scene;
  const SceneAnalysis analysis;  // a copy: callers often pass a temporary
  const CullMode cull;
  // The filter callbacks receive this state as their geometry user pointer.
  std::unique_ptr<EmbreeScene> embree;

  // Set by RayCaster::bind.
  bool bound = false;
  Camera camera;
  std::optional<PrimaryRays> primaryRays;  // of `camera`
  RayOptions options;
  std::unique_ptr<Shader> shader;  // calls back into the RayCaster: untraced rays
  mutable tbb::enumerable_thread_specific<ThreadRays> threads;
};

// The shading kernel's path for this caster's primary hits: the kernel
// unless the reference is asked for (ShadingOptions::referenceShading).
inline ShadingPath shadingPath(const CasterState& state) {
  return state.options.shading.referenceShading ? ShadingPath::Reference : ShadingPath::Kernel;
}

// --- the context one ray tree is traced in ------------------------------------

// The ray tree of one traced pixel as it is recorded
// (RayCaster::traceDebugPixel): one recorder per call, used on one thread.
// The one place a RayRecord is written.
class RayTreeRecorder {
 public:
  // The primary sample whose tree is being traced.
  void beginSample(int sample) { sample_ = sample; }

  // Records a ray; call it before the surfaces the ray met are shaded, so
  // the rays they spawn follow it in the tree. (instance, triangle, t): the
  // front-most surface it met (kNoId: none). Returns the record's index
  // for finish().
  size_t begin(RayKind kind, int depth, const Ray& ray, uint32_t instance, uint32_t triangle, double t);
  // What the ray returned: the surfaces it composited (shadow rays: passed
  // through) and its contribution (shadow rays: transmittance, alpha 1).
  void finish(size_t record, int layers, const glm::vec4& contribution);

  // The depth of the surface being shaded, which its shadow rays take:
  // LightVisibility does not pass it, so compositing sets it around each
  // Shader::shade call (ShadingDepthScope).
  int shadingDepth() const { return shadingDepth_; }

  std::vector<RayRecord> takeRecords() { return std::move(records_); }

 private:
  friend class ShadingDepthScope;
  std::vector<RayRecord> records_;
  int sample_ = 0;
  int shadingDepth_ = 0;
};

// Sets the recorder's shading depth for one Shader::shade call and restores
// the enclosing surface's afterwards; does nothing without a recorder.
class ShadingDepthScope {
 public:
  ShadingDepthScope(RayTreeRecorder* recorder, int depth)
      : recorder_(recorder), saved_(recorder ? recorder->shadingDepth_ : 0) {
    if (recorder_) recorder_->shadingDepth_ = depth;
  }
  ~ShadingDepthScope() {
    if (recorder_) recorder_->shadingDepth_ = saved_;
  }
  ShadingDepthScope(const ShadingDepthScope&) = delete;
  ShadingDepthScope& operator=(const ShadingDepthScope&) = delete;

 private:
  RayTreeRecorder* recorder_;
  int saved_;
};

// What one ray tree is traced with, passed down the recursion: the Shader
// whose reflection, refraction and shadow rays come back into the
// integrator with this same context, the counts its rays add to, and the
// recorder (null unless this tree is being traced). Untraced trees use the
// caster's Shader and this thread's counts; a traced pixel has a Shader of
// its own calling back into its recorder, and counts that are dropped
// (its rays were counted when the image was rendered).
struct RayTreeContext {
  const Shader* shader = nullptr;
  RayCounts* counts = nullptr;
  RayTreeRecorder* recorder = nullptr;
  RayScratch* scratch = nullptr;  // the calling thread's (or the traced pixel's own)

  void count(RayKind kind, uint64_t n = 1) const { (*counts)[size_t(kind)] += n; }
};

// The context of untraced rays on the calling thread.
inline RayTreeContext untracedContext(const CasterState& state) {
  ThreadRays& local = state.threads.local();
  return {state.shader.get(), &local.counts, nullptr, &local.scratch};
}

// --- transparency continuation (transparency.cpp) ------------------------------

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

// The Embree filter callback of every geometry that needs one, for every
// ray kind (geometryUserPtr: the CasterState): accepts or rejects each hit
// (culling, MASK coverage, BLEND layers, shadow transmittance) and gathers
// the rejected ones that matter.
void gatherFilter(const RTCFilterFunctionNArguments* args);

// One single-ray traversal of g.ray (g.mode Radiance): filters gather the
// BLEND hits into g; returns the closest accepted hit (instance kNoId when
// none).
GatheredHit intersectClosest(const CasterState& state, HitGather& g, bool coherent);

// One occlusion traversal of g.ray (g.mode Shadow): true when an opaque
// surface blocks it; otherwise g.hits holds the surfaces it passes
// through, one hit per crossing, ordered by (traversal t, instance,
// triangle). A packet of one (traceOcclusionPacket): every occlusion query
// takes the same Embree path.
bool traceOcclusion(const CasterState& state, HitGather& g);

// traceOcclusion for n ≤ kShadowPacket rays at once, gathers[k].ray the
// kth (its ray id k) in lane lanes[k] (nullptr: lane k) of one
// rtcOccluded16 packet, the other lanes empty: blocked[k] and
// gathers[k].hits as traceOcclusion(state, gathers[k]) leaves them, bit
// for bit (kShadowPacket says why).
void traceOcclusionPacket(const CasterState& state, HitGather* gathers, size_t n, bool* blocked,
                          const int* lanes = nullptr);

// The surfaces along a traced ray, front to back: the gathered BLEND hits
// in front of `closest` (the stopping hit, or none), one per crossing, then
// the stopping one; ordered by (plane t, instance, triangle) and cut after
// the first non-BLEND surface. Consumes g.hits.
void collectCrossings(const CasterState& state, HitGather& g, const GatheredHit& closest,
                      std::vector<SurfaceCrossing>* crossings);

// The shading point of a gathered hit along a ray, refined in double.
SurfacePoint surfacePointOf(const Scene& scene, const Ray& ray, const GatheredHit& hit);

// --- the radiance integrator (radiance.cpp) -----------------------------------

// Where a primary ray's compositing puts its deep samples (null: nowhere).
struct DeepTarget {
  std::vector<DeepSample>* samples = nullptr;
  uint32_t sampleIndex = 0;
};

struct Composited {
  glm::vec4 color{0.0f};  // premultiplied
  int layers = 0;         // surfaces composited
};

// Shades a ray's surfaces front to back and composites them (SPEC §4),
// recording the ray in the context's tree first when there is one.
// `depth` is the ray's depth (primary 0), `throughput` its weight.
Composited shadeRay(const CasterState& state, const RayTreeContext& context, RayKind kind, int depth,
                    float throughput, const HitGather& g, const std::vector<SurfaceCrossing>& crossings,
                    DeepTarget deep);

// SecondaryRayTracer::radiance and LightVisibility::transmittance for the
// context's tree (ray_caster.h's contract).
glm::vec3 traceRadiance(const CasterState& state, const RayTreeContext& context, const SurfacePoint& from,
                        const glm::dvec3& direction, RayKind kind, int depth, float throughput);
glm::vec3 traceTransmittance(const CasterState& state, const RayTreeContext& context,
                             const SurfacePoint& point, const glm::dvec3& toLight, double distance);
// LightVisibility::transmittances: traceTransmittance of each point, the
// first occlusion query of up to kShadowPacket of them in one packet
// (traceOcclusionPacket), the rest of each (a seam's retries) as
// traceTransmittance continues: the same result bits as one by one. A
// recorded tree (context.recorder) or `packets` false traces them one by
// one; `lanes` (n ≤ kShadowPacket, RayCaster::transmittancesInLanes) puts
// ray k in lane lanes[k] of one packet.
void traceTransmittances(const CasterState& state, const RayTreeContext& context, size_t n,
                         const SurfacePoint* const* points, const glm::dvec3* toLight, const double* distance,
                         glm::vec3* out, bool packets = true, const int* lanes = nullptr);

// --- primary visibility (primary_visibility.cpp) ------------------------------

// Whether primary rays go in packets (RayOptions::packets, packetWidth).
bool usePackets(const CasterState& state);

// The image: every sample's primary ray tree, filtered into the flat
// output, and the deep output when options.keepSamples.
RenderOutput renderPrimaryVisibility(const CasterState& state);

struct SampleResult {
  glm::vec4 color{0.0f};  // premultiplied
  // The front-most surface (transparent or opaque) with its traversal
  // depth: the sample's Z and IDs.
  SampleHit front;
};

// One sample's primary ray traced as a single ray, and its tree shaded in
// `context`; g and crossings are the caller's scratch.
SampleResult tracePrimarySample(const CasterState& state, const RayTreeContext& context, glm::ivec2 pixel,
                                const glm::dvec2& position, uint32_t sampleIndex, HitGather& g,
                                std::vector<DeepSample>* deep, std::vector<SurfaceCrossing>* crossings);

}  // namespace rastray
