// `rastray explain SCENE X Y`: every sample of one pixel as each renderer
// saw it — the rasterizer's fragments, edge functions, fill-rule and depth
// decisions, and the ray caster's ray tree — plus the two hit lists side by
// side with the mismatch class of each disagreement.
#include "app/crossval/explain.h"

#include <algorithm>
#include <cstdio>

#include "app/crossval/crossval.h"
#include "common/error.h"
#include "common/sampling.h"
#include "common/trace.h"
#include "compare/classify.h"

namespace rastray {

namespace {

std::string hitText(const std::optional<DeepSample>& s) {
  if (!s) return "nothing";
  char buf[128];
  std::snprintf(buf, sizeof buf, "(%u, %u) Z %.9g", s->instance, s->triangle, double(s->depth));
  return buf;
}

// The entries of sample `index` at pixel p, front to back.
std::vector<const DeepSample*> layersOf(const DeepImage& image, size_t p, uint32_t index) {
  std::vector<const DeepSample*> out;
  for (uint64_t i = image.offsets[p]; i < image.offsets[p + 1]; ++i)
    if (image.samples[i].sample == index) out.push_back(&image.samples[i]);
  return out;
}

}  // namespace

PixelExplanation explainPixel(const Scene& scene, const RenderSettings& settings, int x, int y) {
  RenderSettings s = settings;
  s.debugPixel = glm::ivec2(x, y);
  // Each renderer records what it did at the pixel into its own log.
  TraceLog rasterLog, rayLog;
  s.raster.trace = {&rasterLog, {x, y}};
  s.ray.trace = {&rayLog, {x, y}};
  s.keepSamples = true;

  s.renderer = RendererKind::Raster;
  const RenderRun raster = renderScene(scene, s);
  s.renderer = RendererKind::Raytrace;
  const RenderRun ray = renderScene(scene, s);

  PixelExplanation e;
  e.scenePath = scene.path;
  e.x = x;
  e.y = y;
  e.width = raster.camera.width;
  e.height = raster.camera.height;
  e.spp = s.spp;
  e.camera = raster.camera.describe();
  e.renderOrigin = scene.origin;
  e.rasterEvents = rasterLog.events();
  e.rayEvents = rayLog.events();

  // Hits side by side, with the mismatch class of each disagreement.
  MismatchClassifier classifier(classifierSettings(scene, raster.camera, s.raster.depthFormat));
  const auto positions = samplePositions(s.spp);
  const size_t p = size_t(y) * size_t(raster.camera.width) + size_t(x);
  for (uint32_t i = 0; i < positions.size(); ++i) {
    ExplainedSample sample;
    sample.index = i;
    sample.position = glm::dvec2(x, y) + positions[i];
    const auto a = layersOf(raster.output.samples, p, i), b = layersOf(ray.output.samples, p, i);
    for (size_t k = 0; k < std::max({a.size(), b.size(), size_t(1)}); ++k) {
      ExplainedLayer layer;
      HitRecord ha, hb;
      if (k < a.size()) {
        layer.raster = *a[k];
        ha = {a[k]->instance, a[k]->triangle, a[k]->depth};
      }
      if (k < b.size()) {
        layer.raytrace = *b[k];
        hb = {b[k]->instance, b[k]->triangle, b[k]->depth};
      }
      layer.verdict = "agree";
      if (!ha.sameSurface(hb)) {
        layer.verdict = displayName(classifier.classify(sample.position, ha, hb, ImageSpaceEvidence{}));
        if (ha.isHit()) layer.rasterEdgeDistance = classifier.distanceToTriangleEdges(sample.position, ha);
        if (hb.isHit()) layer.raytraceEdgeDistance = classifier.distanceToTriangleEdges(sample.position, hb);
      }
      sample.layers.push_back(layer);
    }
    e.samples.push_back(sample);
  }
  return e;
}

std::string explanationText(const PixelExplanation& e) {
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line, "pixel (%d, %d) of %s, %dx%d, %d spp\ncamera %s\n\n", e.x, e.y,
                e.scenePath.c_str(), e.width, e.height, e.spp, e.camera.c_str());
  out += line;
  if (e.renderOrigin != glm::dvec3(0.0)) {
    // Traced ray origins below are in the rebased frame (--origin camera).
    std::snprintf(line, sizeof line,
                  "positions below are relative to the render origin (%.17g, %.17g, %.17g)\n\n",
                  e.renderOrigin.x, e.renderOrigin.y, e.renderOrigin.z);
    out += line;
  }
  out += "== hits per sample (instance, triangle) and view depth, front to back ==\n";
  for (const ExplainedSample& sample : e.samples) {
    std::snprintf(line, sizeof line, "sample %u at (%.4f, %.4f)\n", sample.index, sample.position.x,
                  sample.position.y);
    out += line;
    for (size_t k = 0; k < sample.layers.size(); ++k) {
      const ExplainedLayer& layer = sample.layers[k];
      std::snprintf(line, sizeof line, "  layer %zu: raster %-34s raytrace %-34s %s\n", k,
                    hitText(layer.raster).c_str(), hitText(layer.raytrace).c_str(), layer.verdict.c_str());
      out += line;
      if (layer.rasterEdgeDistance) {
        std::snprintf(line, sizeof line, "           distance to raster triangle's edges %.4g px\n",
                      *layer.rasterEdgeDistance);
        out += line;
      }
      if (layer.raytraceEdgeDistance) {
        std::snprintf(line, sizeof line, "           distance to raytrace triangle's edges %.4g px\n",
                      *layer.raytraceEdgeDistance);
        out += line;
      }
    }
  }
  out += "\n== rasterizer: coverage, fill rule, depth tests, layers ==\n" + traceText(e.rasterEvents);
  out += "\n== ray caster: ray tree ==\n" + rayTreeText(e.rayEvents, {e.x, e.y});
  return out;
}

nlohmann::ordered_json explanationJson(const PixelExplanation& e) {
  using json = nlohmann::ordered_json;
  auto hit = [](const std::optional<DeepSample>& s) -> json {
    if (!s) return nullptr;
    return {{"instance", s->instance}, {"triangle", s->triangle}, {"depth", s->depth}};
  };
  auto events = [](const std::vector<TraceEvent>& list) {
    json out = json::array();
    for (const TraceEvent& ev : list) {
      json values = json::object();
      for (const auto& [name, value] : ev.values) {
        // Names are unique within an event; a repeated one keeps both values.
        std::string key = name;
        for (int n = 2; values.contains(key); ++n) key = name + "#" + std::to_string(n);
        values[key] = value;
      }
      out.push_back({{"stage", toString(ev.stage)},
                     {"sample", ev.sample >= 0 ? json(ev.sample) : json(nullptr)},
                     {"instance", ev.instance != kNoId ? json(ev.instance) : json(nullptr)},
                     {"triangle", ev.triangle != kNoId ? json(ev.triangle) : json(nullptr)},
                     {"depth", ev.depth},
                     {"outcome", ev.outcome},
                     {"values", values}});
    }
    return out;
  };
  json samples = json::array();
  for (const ExplainedSample& sample : e.samples) {
    json layers = json::array();
    for (const ExplainedLayer& layer : sample.layers) {
      json l = {{"raster", hit(layer.raster)}, {"raytrace", hit(layer.raytrace)}, {"verdict", layer.verdict}};
      if (layer.rasterEdgeDistance) l["rasterEdgeDistance"] = *layer.rasterEdgeDistance;
      if (layer.raytraceEdgeDistance) l["raytraceEdgeDistance"] = *layer.raytraceEdgeDistance;
      layers.push_back(l);
    }
    samples.push_back(
        {{"sample", sample.index}, {"position", {sample.position.x, sample.position.y}}, {"layers", layers}});
  }
  return {{"schema", "rastray.explain"},
          {"version", 1},
          {"scene", e.scenePath},
          {"pixel", {e.x, e.y}},
          {"size", {e.width, e.height}},
          {"spp", e.spp},
          {"camera", e.camera},
          {"renderOrigin", {e.renderOrigin.x, e.renderOrigin.y, e.renderOrigin.z}},
          {"samples", samples},
          {"raster", {{"events", events(e.rasterEvents)}}},
          {"raytrace", {{"events", events(e.rayEvents)}}}};
}

}  // namespace rastray
