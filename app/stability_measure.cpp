#include "app/stability_measure.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <CLI/CLI.hpp>

#include "common/error.h"
#include "compare/classify.h"
#include "compare/maps.h"

namespace rastray::stability {

RenderSettings renderSettingsFrom(const std::vector<std::string>& args, bool allRenderers) {
  CLI::App app;
  RenderSettings settings;
  addRenderSettings(app, settings, /*withRenderer=*/!allRenderers);
  settings.allRenderers = allRenderers;
  std::vector<std::string> reversed(args.rbegin(), args.rend());  // CLI11 takes them last first
  app.parse(reversed);
  settings.finish();
  settings.cliOptions.clear();  // they point into `app`
  return settings;
}

Rendered renderVariant(const CaseContext& ctx, const std::string& scenePath,
                       const std::vector<std::string>& args, bool deep, const std::string& label) {
  Rendered r;
  r.settings = renderSettingsFrom(args);
  r.settings.keepSamples = deep;
  r.scene = loadSceneForRender(scenePath, r.settings);
  r.run = renderScene(r.scene, r.settings);
  if (ctx.progress) {
    char line[256];
    std::snprintf(line, sizeof line, "%s: %.3f s",
                  label.empty() ? toString(r.settings.renderer) : label.c_str(), r.run.seconds);
    ctx.progress(line);
  }
  return r;
}

namespace {

bool finite4(const glm::vec4& c) {
  return std::isfinite(c.r) && std::isfinite(c.g) && std::isfinite(c.b) && std::isfinite(c.a);
}

// A depth is wrong when NaN or −inf anywhere, or +inf on a hit.
bool badDepth(float depth, bool hit) {
  return std::isnan(depth) || depth == -INFINITY || (hit && std::isinf(depth));
}

}  // namespace

uint64_t countNanInf(const RenderOutput& output) {
  uint64_t bad = 0;
  const FlatImage& image = output.image;
  for (size_t i = 0; i < image.color.size(); ++i) {
    if (!finite4(image.color[i])) ++bad;
    if (i < image.depth.size() &&
        badDepth(image.depth[i], i < image.instance.size() && image.instance[i] != kNoId))
      ++bad;
  }
  if (output.hasSamples)
    for (const DeepSample& s : output.samples.samples) {
      if (!finite4(s.color)) ++bad;
      if (badDepth(s.depth, s.instance != kNoId)) ++bad;
    }
  return bad;
}

VisibilityReport visibilityAgainst(const Rendered& a, const Rendered& reference) {
  if (!a.run.output.hasSamples || !reference.run.output.hasSamples)
    throw std::logic_error("visibilityAgainst: both renders need their samples (renderVariant deep = true)");
  ClassifierSettings classifier;
  const auto rasterizes = [](const Rendered& r) { return r.settings.renderer != RendererKind::Raytrace; };
  if (rasterizes(a))
    classifier.depthFormat = storedDepthFormat(a.settings.raster.depthFormat);
  else if (rasterizes(reference))
    classifier.depthFormat = storedDepthFormat(reference.settings.raster.depthFormat);
  const Camera& camera = reference.camera();
  classifier.planes = {true, camera.projection, camera.znear, camera.zfar};
  classifier.scene = &reference.scene;
  classifier.camera = &camera;
  return compareVisibility(a.run.output.samples, reference.run.output.samples, reference.settings.spp,
                           classifier, FrameNames{toString(a.settings.renderer), "reference"});
}

double agreementOf(const VisibilityReport& v) { return v.layers.agreement(); }
int64_t genuineOf(const VisibilityReport& v) { return int64_t(v.layers.count(MismatchClass::Genuine)); }

CrossvalResult crossvalidateVariant(const CaseContext& ctx, const std::string& scenePath,
                                    const std::vector<std::string>& args) {
  const RenderSettings settings = renderSettingsFrom(args, /*allRenderers=*/true);
  const Scene scene = loadSceneForRender(scenePath, settings);
  return crossvalidate(scene, settings, ctx.progress);
}

std::vector<float> pixelDifference(const FlatImage& a, const FlatImage& b) {
  if (a.width != b.width || a.height != b.height)
    throw std::logic_error("pixelDifference: images of different sizes");
  std::vector<float> d(a.color.size());
  for (size_t i = 0; i < d.size(); ++i) {
    const glm::vec4 e = glm::abs(a.color[i] - b.color[i]);
    // NaN compares false in max: make it count as maximally different.
    const float m = std::max(std::max(e.r, e.g), std::max(e.b, e.a));
    d[i] = finite4(e) ? m : INFINITY;
  }
  return d;
}

double fractionOff(const FlatImage& a, const FlatImage& b, double threshold) {
  const std::vector<float> d = pixelDifference(a, b);
  if (d.empty()) return 0.0;
  const auto off = std::count_if(d.begin(), d.end(), [&](float v) { return v > threshold; });
  return double(off) / double(d.size());
}

void addImage(Row& row, const ReportImage& image) {
  if (!image.first.empty()) row.images.push_back(image);
}

namespace {

// <reportDir>/<caseName>/<file>, the folder created; "" without a report.
std::string reportPath(const CaseContext& ctx, const std::string& caseName, const std::string& file) {
  if (ctx.reportDir.empty()) return "";
  std::filesystem::create_directories(std::filesystem::path(ctx.reportDir) / caseName);
  return (std::filesystem::path(ctx.reportDir) / caseName / file).string();
}

std::string barCaption(const std::string& caption, const ColorBar& bar) {
  char range[160];
  std::snprintf(range, sizeof range, " (%s: dark 0 .. bright %.3g)", bar.quantity.c_str(), bar.hi);
  return caption + range;
}

}  // namespace

ReportImage writeRenderImage(const CaseContext& ctx, const std::string& caseName, const std::string& file,
                             const FlatImage& image, const std::string& caption) {
  const std::string path = reportPath(ctx, caseName, file);
  if (path.empty()) return {};
  writePng(path, image);
  return {caseName + "/" + file, caption};
}

ReportImage writeDifferenceImage(const CaseContext& ctx, const std::string& caseName, const std::string& file,
                                 const FlatImage& a, const FlatImage& b, const std::string& caption) {
  const std::string path = reportPath(ctx, caseName, file);
  if (path.empty()) return {};
  const ColorBar bar = writeDifferenceHeatMap(path, a, b);
  return {caseName + "/" + file, barCaption(caption, bar)};
}

ReportImage writeMismatchImage(const CaseContext& ctx, const std::string& caseName, const std::string& file,
                               const VisibilityReport& visibility, const std::string& caption) {
  const std::string path = reportPath(ctx, caseName, file);
  if (path.empty()) return {};
  writeMismatchMap(path, visibility);
  return {caseName + "/" + file, caption};
}

ReportImage writeValueImage(const CaseContext& ctx, const std::string& caseName, const std::string& file,
                            int width, int height, const std::vector<float>& values,
                            const std::string& quantity, const std::string& caption) {
  const std::string path = reportPath(ctx, caseName, file);
  if (path.empty()) return {};
  const ColorBar bar = writeHeatMap(path, width, height, values, quantity);
  return {caseName + "/" + file, barCaption(caption, bar)};
}

std::string powerOfTen(double value) {
  const int exponent = int(std::lround(std::log10(std::fabs(value))));
  return std::string(value < 0 ? "-" : "") + "1e" + std::to_string(exponent);
}

}  // namespace rastray::stability
