// RayCaster: binding, the image and its report of passes, the interfaces
// hybrid shading calls, counters, and the traced pixel. The work is in the
// parts ray_caster_parts.h lists.
#include "raytrace/ray_caster.h"

#include <cstdio>
#include <string>

#include "common/error.h"
#include "common/sampling.h"
#include "raytrace/ray_caster_parts.h"

namespace rastray {

namespace {

const char* kCounterNames[kRayKindCount] = {"rays.primary", "rays.shadow", "rays.reflection",
                                            "rays.refraction", "rays.transparency"};

// What render() did and left out, with the analysis's reasons.
void reportPasses(const CasterState& state, RenderOutput* out) {
  out->passesRun.push_back(
      "primary rays (" +
      (usePackets(state) ? std::to_string(state.options.packetWidth) + "-wide packets" : "single rays") +
      ")");
  const SceneAnalysis& a = state.analysis;
  auto pass = [&](bool needed, const std::string& name, Work work, const char* offBy = nullptr) {
    if (needed && offBy)
      out->passesLeftOut.push_back(name + ": " + offBy);
    else if (needed)
      out->passesRun.push_back(name);
    else
      for (const WorkDecision& d : a.decisions)
        if (d.work == work) out->passesLeftOut.push_back(name + ": " + d.reason);
  };
  const ShadingOptions& shading = state.options.shading;
  pass(a.shadows, "shadow rays", Work::Shadows, state.options.shadows ? nullptr : "--shadows none");
  pass(a.reflection, "reflection rays", Work::ReflectionRays,
       shading.reflection ? nullptr : "--no-reflection");
  pass(a.refraction, "refraction rays", Work::RefractionRays,
       shading.refraction ? nullptr : "--no-refraction");
  pass(a.transparency, "transparency continuation", Work::TransparencyPass);
  pass(a.alphaTest, "alpha test (filter callbacks)", Work::AlphaTest);
  if (state.cull != CullMode::None)
    out->passesRun.push_back(std::string(state.cull == CullMode::Back ? "back" : "front") +
                             "-face culling (filters on " + std::to_string(state.embree->filterGeometries()) +
                             " single-sided geometries)");
}

// The callbacks one traced pixel's Shader calls: its reflection, refraction
// and shadow rays go back into the integrator with this tree's context,
// so they are recorded; their counts are dropped.
class TracedRayTree : public SecondaryRayTracer, public LightVisibility {
 public:
  explicit TracedRayTree(const CasterState& state)
      : state_(state), shader_(*state.shader, state.options.shadows ? this : nullptr, this) {}

  // The Shader holds these callbacks as const objects; the counts and the
  // tree they record into are this object's own, used on one thread.
  RayTreeContext context() const { return {&shader_, &counts_, &recorder_, &scratch_}; }
  RayTreeRecorder& recorder() const { return recorder_; }

  glm::vec3 radiance(const SurfacePoint& from, const glm::dvec3& direction, RayKind kind, int depth,
                     float throughput) const override {
    return traceRadiance(state_, context(), from, direction, kind, depth, throughput);
  }
  glm::vec3 transmittance(const SurfacePoint& point, int /*lightIndex*/, const glm::dvec3& toLight,
                          double distance) const override {
    return traceTransmittance(state_, context(), point, toLight, distance);
  }
  void transmittances(int /*lightIndex*/, size_t n, const SurfacePoint* const* points,
                      const glm::dvec3* toLight, const double* distance, glm::vec3* out) const override {
    traceTransmittances(state_, context(), n, points, toLight, distance, out, state_.options.shadowPackets);
  }

 private:
  const CasterState& state_;
  Shader shader_;
  mutable RayCounts counts_{};
  mutable RayTreeRecorder recorder_;
  mutable RayScratch scratch_;
};

std::string contributionText(const glm::vec4& c) {
  char buf[128];
  std::snprintf(buf, sizeof buf, "(%.6g, %.6g, %.6g, %.6g)", double(c.r), double(c.g), double(c.b),
                double(c.a));
  return buf;
}

}  // namespace

const char* toString(RayOffsetMethod method) {
  return method == RayOffsetMethod::ErrorBound ? "error-bound" : "float-ulps";
}

const char* toString(ShadowTerminator terminator) {
  return terminator == ShadowTerminator::None ? "none" : "shading-normal";
}

// --- RayTreeRecorder: the one place a RayRecord is written ----------------------

size_t RayTreeRecorder::begin(RayKind kind, int depth, const Ray& ray, uint32_t instance, uint32_t triangle,
                              double t) {
  RayRecord r;
  r.kind = kind;
  r.depth = depth;
  r.sample = sample_;
  r.origin = ray.origin;
  r.direction = ray.direction;
  r.tNear = ray.tNear;
  r.tFar = ray.tFar;
  r.instance = instance;
  r.triangle = triangle;
  r.t = t;
  records_.push_back(r);
  return records_.size() - 1;
}

void RayTreeRecorder::finish(size_t record, int layers, const glm::vec4& contribution) {
  records_[record].layers = layers;
  records_[record].contribution = contribution;
}

TraceEvent rayTraceEvent(const RayRecord& r) {
  TraceEvent e;
  e.stage = TraceStage::Ray;
  e.sample = r.sample;
  e.instance = r.instance;
  e.triangle = r.triangle;
  // Shadow rays hang below the surface they light (its ray's depth + 1).
  e.depth = r.kind == RayKind::Shadow ? r.depth + 1 : r.depth;
  e.add("kind", toString(r.kind))
      .add("origin", traceVector(r.origin))
      .add("dir", traceVector(r.direction))
      .add("tnear", traceNumber(r.tNear))
      .add("tfar", traceNumber(r.tFar));
  if (r.kind == RayKind::Shadow) {
    const bool blocked = r.contribution == glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
    e.outcome = blocked ? "blocked" : r.layers == 0 ? "unoccluded" : "through";
    if (!blocked && r.layers > 0) e.add("surfaces", std::to_string(r.layers));
    e.add("transmittance", contributionText(r.contribution));
  } else {
    e.outcome = r.instance == kNoId ? "miss" : "hit";
    if (r.instance != kNoId) e.add("t", traceNumber(r.t)).add("layers", std::to_string(r.layers));
    e.add("contribution", contributionText(r.contribution));
  }
  return e;
}

// --- RayCaster ---------------------------------------------------------------------

struct RayCaster::Impl : CasterState {
  using CasterState::CasterState;
};

RayCaster::RayCaster(const Scene& scene, const SceneAnalysis& analysis, CullMode cull)
    : impl_(std::make_unique<Impl>(scene, analysis, cull)) {
  CasterState& state = *impl_;
  state.embree = std::make_unique<EmbreeScene>(scene, analysis, cull, &gatherFilter, &gatherFilter, &state);
}

RayCaster::~RayCaster() = default;

void RayCaster::bind(const Camera& camera, const RayOptions& options) {
  if (!isSupportedSampleCount(options.spp))
    throw InputError(
        "command line", "--spp",
        "unsupported sample count " + std::to_string(options.spp) + " (use " + supportedSampleCounts() + ")");
  if (options.shading.maxDepth < 0) throw InputError("command line", "--max-depth", "must be >= 0");
  RASTRAY_CHECK(options.packetWidth == 4 || options.packetWidth == 8 || options.packetWidth == 16,
                "RayOptions::packetWidth must be 4, 8 or 16");
  CasterState& state = *impl_;
  state.camera = camera;
  state.primaryRays.emplace(state.camera);
  state.options = options;
  // Without shadows the Shader gets no visibility callback: every light unoccluded.
  state.shader = std::make_unique<Shader>(state.scene, state.analysis, state.camera, options.shading,
                                          options.shadows ? this : nullptr, this);
  resetCounters();  // each thread's scratch is kept (warm) across binds
  state.bound = true;
}

RenderOutput RayCaster::render() {
  const CasterState& state = *impl_;
  RASTRAY_CHECK(state.bound, "RayCaster::render before bind");
  resetCounters();  // the output counts this frame's rays only
  RenderOutput out = renderPrimaryVisibility(state);
  state.embree->throwIfError();
  out.counters = counters();
  reportPasses(state, &out);
  const TraceRequest& trace = state.options.trace;
  if (trace) {
    const glm::ivec2 p = trace.pixel;
    if (p.x < 0 || p.y < 0 || p.x >= state.camera.width || p.y >= state.camera.height)
      throw InputError("trace request", "pixel",
                       "(" + std::to_string(p.x) + ", " + std::to_string(p.y) + ") lies outside the " +
                           std::to_string(state.camera.width) + "x" + std::to_string(state.camera.height) +
                           " image");
    for (const RayRecord& r : traceDebugPixel(p)) trace.sink->record(rayTraceEvent(r));
  }
  return out;
}

glm::vec3 RayCaster::radiance(const SurfacePoint& from, const glm::dvec3& direction, RayKind kind, int depth,
                              float throughput) const {
  RASTRAY_CHECK(impl_->bound, "RayCaster::radiance before bind");
  return traceRadiance(*impl_, untracedContext(*impl_), from, direction, kind, depth, throughput);
}

glm::vec3 RayCaster::transmittance(const SurfacePoint& point, int /*lightIndex*/, const glm::dvec3& toLight,
                                   double distance) const {
  RASTRAY_CHECK(impl_->bound, "RayCaster::transmittance before bind");
  return traceTransmittance(*impl_, untracedContext(*impl_), point, toLight, distance);
}

void RayCaster::transmittances(int /*lightIndex*/, size_t n, const SurfacePoint* const* points,
                               const glm::dvec3* toLight, const double* distance, glm::vec3* out) const {
  RASTRAY_CHECK(impl_->bound, "RayCaster::transmittances before bind");
  traceTransmittances(*impl_, untracedContext(*impl_), n, points, toLight, distance, out,
                      impl_->options.shadowPackets);
}

void RayCaster::transmittancesInLanes(size_t n, const SurfacePoint* const* points, const glm::dvec3* toLight,
                                      const double* distance, const int* lanes, glm::vec3* out) const {
  RASTRAY_CHECK(impl_->bound, "RayCaster::transmittancesInLanes before bind");
  RASTRAY_CHECK(n <= kShadowPacket, "one packet holds at most 14 rays, not " + std::to_string(n));
  for (size_t k = 0; k < n; ++k)
    RASTRAY_CHECK(lanes[k] >= 0 && lanes[k] < 16, "lane " + std::to_string(lanes[k]));
  traceTransmittances(*impl_, untracedContext(*impl_), n, points, toLight, distance, out, true, lanes);
}

void RayCaster::resetCounters() {
  for (ThreadRays& local : impl_->threads) local.counts = RayCounts{};
}

void RayCaster::throwIfError() const { impl_->embree->throwIfError(); }

CounterSet RayCaster::counters() const {
  RayCounts total{};
  for (const ThreadRays& local : impl_->threads)
    for (int k = 0; k < kRayKindCount; ++k) total[size_t(k)] += local.counts[size_t(k)];
  CounterSet set;
  for (int k = 0; k < kRayKindCount; ++k) set.set(kCounterNames[k], total[size_t(k)]);
  return set;
}

std::vector<RayRecord> RayCaster::traceDebugPixel(glm::ivec2 pixel) const {
  const CasterState& state = *impl_;
  RASTRAY_CHECK(state.bound, "RayCaster::traceDebugPixel before bind");
  TracedRayTree tree(state);
  const RayTreeContext context = tree.context();
  const std::vector<glm::dvec2> positions = samplePositions(state.options.spp);
  HitGather g;
  std::vector<SurfaceCrossing> crossings;
  for (size_t s = 0; s < positions.size(); ++s) {
    tree.recorder().beginSample(int(s));
    tracePrimarySample(state, context, pixel, positions[s], uint32_t(s), g, nullptr, &crossings);
  }
  state.embree->throwIfError();
  return tree.recorder().takeRecords();
}

}  // namespace rastray
