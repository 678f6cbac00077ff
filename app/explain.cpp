// `rastray explain SCENE X Y`: every sample of one pixel as each renderer
// saw it — the rasterizer's fragments, edge functions, fill-rule and depth
// decisions, and the ray caster's ray tree — plus the two hit lists side by
// side with the mismatch class of each disagreement.
#include "app/explain.h"

#include <cstdio>
#include <memory>

#include "app/commands.h"
#include "app/crossval.h"
#include "common/error.h"
#include "common/sampling.h"
#include "common/trace.h"
#include "compare/classify.h"

namespace rastray {

namespace {

std::string hitText(const DeepSample* s) {
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

std::string explainPixel(const Scene& scene, const RenderSettings& settings, int x, int y) {
  RenderSettings s = settings;
  s.debugPixel = glm::ivec2(x, y);
  // Each renderer records what it did at the pixel into its own log.
  TraceLog rasterLog, rayLog;
  s.raster.trace = {&rasterLog, {x, y}};
  s.ray.trace = {&rayLog, {x, y}};
  s.keepSamples = true;

  std::string out;
  char line[512];
  s.renderer = RendererKind::Raster;
  const RenderRun raster = renderScene(scene, s);
  s.renderer = RendererKind::Raytrace;
  const RenderRun ray = renderScene(scene, s);
  const std::string rasterTrace = rasterLog.text(), rayTrace = rayTreeText(rayLog.events(), {x, y});

  std::snprintf(line, sizeof line, "pixel (%d, %d) of %s, %dx%d, %d spp\ncamera %s\n\n", x, y,
                scene.path.c_str(), raster.camera.width, raster.camera.height, s.spp,
                raster.camera.describe().c_str());
  out += line;
  if (scene.origin != glm::dvec3(0.0)) {
    // Traced ray origins below are in the rebased frame (--origin camera).
    std::snprintf(line, sizeof line,
                  "positions below are relative to the render origin (%.17g, %.17g, %.17g)\n\n",
                  scene.origin.x, scene.origin.y, scene.origin.z);
    out += line;
  }

  // Hits side by side, with the mismatch class of each disagreement.
  ClassifierSettings cs;
  cs.depthFormat = storedDepthFormat(s.raster.depthFormat);
  cs.planes = {true, raster.camera.projection, raster.camera.znear, raster.camera.zfar};
  cs.scene = &scene;
  cs.camera = &raster.camera;
  MismatchClassifier classifier(cs);
  const auto positions = samplePositions(s.spp);
  const size_t p = size_t(y) * size_t(raster.camera.width) + size_t(x);
  out += "== hits per sample (instance, triangle) and view depth, front to back ==\n";
  for (uint32_t i = 0; i < positions.size(); ++i) {
    const glm::dvec2 pos = glm::dvec2(x, y) + positions[i];
    std::snprintf(line, sizeof line, "sample %u at (%.4f, %.4f)\n", i, pos.x, pos.y);
    out += line;
    const auto a = layersOf(raster.output.samples, p, i), b = layersOf(ray.output.samples, p, i);
    for (size_t k = 0; k < std::max({a.size(), b.size(), size_t(1)}); ++k) {
      const DeepSample* la = k < a.size() ? a[k] : nullptr;
      const DeepSample* lb = k < b.size() ? b[k] : nullptr;
      HitRecord ha, hb;
      if (la) ha = {la->instance, la->triangle, la->depth};
      if (lb) hb = {lb->instance, lb->triangle, lb->depth};
      std::string verdict = "agree";
      if (!ha.sameSurface(hb)) verdict = displayName(classifier.classify(pos, ha, hb, ImageSpaceEvidence{}));
      std::snprintf(line, sizeof line, "  layer %zu: raster %-34s raytrace %-34s %s\n", k,
                    hitText(la).c_str(), hitText(lb).c_str(), verdict.c_str());
      out += line;
      if (!ha.sameSurface(hb)) {
        if (ha.isHit()) {
          std::snprintf(line, sizeof line, "           distance to raster triangle's edges %.4g px\n",
                        classifier.distanceToTriangleEdges(pos, ha));
          out += line;
        }
        if (hb.isHit()) {
          std::snprintf(line, sizeof line, "           distance to raytrace triangle's edges %.4g px\n",
                        classifier.distanceToTriangleEdges(pos, hb));
          out += line;
        }
      }
    }
  }
  out += "\n== rasterizer: coverage, fill rule, depth tests, layers ==\n" + rasterTrace;
  out += "\n== ray caster: ray tree ==\n" + rayTrace;
  return out;
}

namespace {

struct ExplainOptions {
  std::string scenePath;
  int x = 0, y = 0;
  RenderSettings settings;
};

int runExplain(ExplainOptions& opt) {
  opt.settings.finish();
  const Scene scene = loadSceneForRender(opt.scenePath, opt.settings);
  if (opt.x < 0 || opt.y < 0 || opt.x >= opt.settings.camera.width() || opt.y >= opt.settings.camera.height())
    throw InputError(
        "command line", "X Y",
        "pixel (" + std::to_string(opt.x) + ", " + std::to_string(opt.y) + ") lies outside the image");
  std::fputs(explainPixel(scene, opt.settings, opt.x, opt.y).c_str(), stdout);
  return 0;
}

}  // namespace

CommandRunner addExplainCommand(CLI::App& app) {
  auto opt = std::make_shared<ExplainOptions>();
  CLI::App* cmd = app.add_subcommand(
      "explain",
      "Show every sample of one pixel as the rasterizer and the ray caster saw it, and why they differ");
  cmd->add_option("scene", opt->scenePath, "glTF 2.0 file")->required();
  cmd->add_option("x", opt->x, "Pixel column (0 = left)")->required();
  cmd->add_option("y", opt->y, "Pixel row (0 = top)")->required();
  addRenderSettings(*cmd, opt->settings, /*withRenderer=*/false);
  return [opt, cmd]() -> int { return cmd->parsed() ? runExplain(*opt) : -1; };
}

}  // namespace rastray
