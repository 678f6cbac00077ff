// `rastray crossval SCENE... [--report DIR]`: every scene rendered by the
// rasterizer, the ray caster and hybrid under identical settings, compared
// sample by sample and layer by layer, one summary row per scene.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

#include <tbb/global_control.h>
#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "app/crossval.h"
#include "app/crossval_report.h"
#include "app/explain.h"
#include "app/render_setup.h"
#include "common/error.h"
#include "common/image.h"

namespace rastray {

namespace {

struct CrossvalOptions {
  std::vector<std::string> scenes;
  std::string reportDir;
  bool json = false;
  double minAgreement = 0.0;
  uint64_t maxGenuine = 0;
  double maxHybridError = 1e-5;
  RenderSettings settings;
};

nlohmann::json visibilityJson(const VisibilityReport& v) {
  nlohmann::json j;
  j["samples"] = {{"compared", v.samples.compared}, {"agreeing", v.samples.agreeing}};
  j["layers"] = {{"compared", v.layers.compared}, {"agreeing", v.layers.agreeing}};
  nlohmann::json classes = nlohmann::json::object();
  for (int c = 0; c < kMismatchClassCount; ++c)
    classes[toString(MismatchClass(c))] = v.layers.count(MismatchClass(c));
  j["mismatches"] = classes;
  j["cutOff"] = {{"layers", v.layers.cutOff},
                 {"samples", v.cutOff.samples},
                 {"meanColor", v.cutOff.meanColor},
                 {"maxColor", v.cutOff.maxColor},
                 {"maxAt", {v.cutOff.maxX, v.cutOff.maxY}}};
  j["depthError"] = {{"meanAbsolute", v.depth.meanAbsolute},
                     {"maxAbsolute", v.depth.maxAbsolute},
                     {"meanRelative", v.depth.meanRelative},
                     {"maxRelative", v.depth.maxRelative}};
  return j;
}

nlohmann::json colorJson(const ColorMetrics& m, const AgreeingColorStats& agree) {
  return {{"mean", m.meanError},
          {"rms", m.rmsError},
          {"psnr", std::isinf(m.psnr) ? nlohmann::json("inf") : nlohmann::json(m.psnr)},
          {"max", m.maxError},
          {"maxAt", {m.maxX, m.maxY}},
          {"yeeFailingPixels", m.yeeFailingPixels},
          {"maxWhereHitsAgree", agree.maxError},
          {"layersWhereHitsAgree", agree.layers}};
}

int runCrossval(CrossvalOptions& opt) {
  opt.settings.finish();
  std::unique_ptr<tbb::global_control> threads;
  if (opt.settings.threads > 0)
    threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                    size_t(opt.settings.threads));
  const bool terminal = isatty(STDERR_FILENO);
  std::vector<CrossvalResult> results;
  // Scenes are loaded one at a time: a bad file stops the run (exit 2)
  // before any report is written.
  for (size_t i = 0; i < opt.scenes.size(); ++i) {
    const Scene scene = loadSceneForRender(opt.scenes[i], opt.settings);
    auto progress = [&](const std::string& stage) {
      if (terminal)
        std::fprintf(stderr, "\r[%zu/%zu] %s: %-10s", i + 1, opt.scenes.size(), opt.scenes[i].c_str(),
                     stage.c_str());
    };
    results.push_back(crossvalidate(scene, opt.settings, progress));
  }
  if (terminal) std::fprintf(stderr, "\r%80s\r", "");

  std::vector<std::string> failures;
  for (const CrossvalResult& r : results) {
    const uint64_t rasterGenuine = r.rasterVsRay.layers.count(MismatchClass::Genuine),
                   hybridGenuine = r.hybridVsRay.layers.count(MismatchClass::Genuine);
    if (rasterGenuine > opt.maxGenuine || hybridGenuine > opt.maxGenuine)
      failures.push_back(r.scenePath + ": genuine mismatches: raster " + std::to_string(rasterGenuine) +
                         ", hybrid " + std::to_string(hybridGenuine) + " (max " +
                         std::to_string(opt.maxGenuine) + " each)");
    if (r.rasterVsRay.layers.agreement() < opt.minAgreement)
      failures.push_back(r.scenePath + ": agreement " + std::to_string(r.rasterVsRay.layers.agreement()) +
                         " below " + std::to_string(opt.minAgreement));
    if (r.hybridWhereAgree.maxError > opt.maxHybridError)
      failures.push_back(r.scenePath + ": hybrid differs from the ray caster by " +
                         std::to_string(r.hybridWhereAgree.maxError) + " where their hits agree (max " +
                         std::to_string(opt.maxHybridError) + ")");
  }

  if (!opt.reportDir.empty()) {
    // One explained example pixel per mismatch class, linked from the report.
    std::vector<std::vector<ReportExplanation>> explanations(results.size());
    for (size_t i = 0; i < results.size(); ++i) {
      const CrossvalResult& r = results[i];
      const std::string folder = opt.reportDir + "/" + std::filesystem::path(r.scenePath).stem().string();
      std::filesystem::create_directories(folder);
      const Scene scene = loadSceneForRender(r.scenePath, opt.settings);
      for (int c = 0; c < kMismatchClassCount; ++c) {
        const auto& example = r.rasterVsRay.examples[size_t(c)];
        if (!example) continue;
        if (terminal)
          std::fprintf(stderr, "\rexplaining %s: %-20s", r.scenePath.c_str(), toString(MismatchClass(c)));
        const std::string file = std::string("explain-") + toString(MismatchClass(c)) + ".txt";
        writeTextFile(folder + "/" + file,
                      explanationText(explainPixel(scene, opt.settings, example->x, example->y)));
        explanations[i].push_back({toString(MismatchClass(c)), file});
      }
    }
    if (terminal) std::fprintf(stderr, "\r%80s\r", "");
    writeCrossvalReport(opt.reportDir, results, opt.settings, explanations);
  }

  if (opt.json) {
    nlohmann::json j = nlohmann::json::array();
    for (const CrossvalResult& r : results)
      j.push_back(
          {{"scene", r.scenePath},
           {"width", r.camera.width},
           {"height", r.camera.height},
           {"spp", opt.settings.spp},
           {"rasterVsRaytrace",
            {{"visibility", visibilityJson(r.rasterVsRay)},
             {"color", colorJson(r.rasterVsRayColor, r.rasterWhereAgree)}}},
           {"hybridVsRaytrace",
            {{"visibility", visibilityJson(r.hybridVsRay)},
             {"color", colorJson(r.hybridVsRayColor, r.hybridWhereAgree)}}},
           {"seconds",
            {{"raster", r.raster.seconds}, {"raytrace", r.raytrace.seconds}, {"hybrid", r.hybrid.seconds}}}});
    std::cout << nlohmann::json{{"schema", "rastray.crossval"},
                                {"version", 1},
                                {"scenes", j},
                                {"failures", failures}}
                     .dump(2)
              << "\n";
  } else {
    // The scene column is as wide as the longest file name.
    int nameWidth = 5;
    for (const CrossvalResult& r : results)
      nameWidth = std::max(nameWidth, int(std::filesystem::path(r.scenePath).filename().string().size()));
    std::printf("%-*s %9s %4s %9s %9s %9s %7s %7s %7s %7s %7s %7s %7s %9s %8s %7s %9s %8s %8s %8s\n",
                nameWidth, "scene", "size", "spp", "samples", "layers", "agree%", "edge", "shared", "ztie",
                "plane", "genuine", "cutoff", "hyb gen", "max relZ", "RMS", "PSNR", "hybrid d", "raster s",
                "ray s", "hybrid s");
    for (const CrossvalResult& r : results) {
      const VisibilityReport& v = r.rasterVsRay;
      char size[32];
      std::snprintf(size, sizeof size, "%dx%d", r.camera.width, r.camera.height);
      std::printf(
          "%-*s %9s %4d %9llu %9llu %9.4f %7llu %7llu %7llu %7llu %7llu %7llu %7llu %9.2e %8.2e %7.1f %9.2e "
          "%8.3f %8.3f %8.3f\n",
          nameWidth, std::filesystem::path(r.scenePath).filename().string().c_str(), size, opt.settings.spp,
          (unsigned long long)v.samples.compared, (unsigned long long)v.layers.compared,
          100.0 * v.layers.agreement(), (unsigned long long)v.layers.count(MismatchClass::SilhouetteEdge),
          (unsigned long long)v.layers.count(MismatchClass::SharedEdgeTie),
          (unsigned long long)v.layers.count(MismatchClass::DepthTie),
          (unsigned long long)v.layers.count(MismatchClass::NearFarPlane),
          (unsigned long long)v.layers.count(MismatchClass::Genuine), (unsigned long long)v.layers.cutOff,
          (unsigned long long)r.hybridVsRay.layers.count(MismatchClass::Genuine), v.depth.maxRelative,
          r.rasterVsRayColor.rmsError, std::isinf(r.rasterVsRayColor.psnr) ? 999.9 : r.rasterVsRayColor.psnr,
          r.hybridWhereAgree.maxError, r.raster.seconds, r.raytrace.seconds, r.hybrid.seconds);
    }
    if (!opt.reportDir.empty()) std::printf("\nreport: %s/index.html\n", opt.reportDir.c_str());
    for (const std::string& f : failures) std::printf("FAIL %s\n", f.c_str());
  }
  return failures.empty() ? 0 : 1;
}

}  // namespace

CommandRunner addCrossvalCommand(CLI::App& app) {
  auto opt = std::make_shared<CrossvalOptions>();
  CLI::App* cmd = app.add_subcommand(
      "crossval",
      "Render scenes with the rasterizer, the ray caster and hybrid, and compare every sample and layer");
  cmd->add_option("scenes", opt->scenes, "glTF 2.0 files")->required();
  cmd->add_option("--report", opt->reportDir,
                  "Write an HTML report (index.html and images) into this folder");
  cmd->add_flag("--json", opt->json, "Print the results as JSON");
  cmd->add_option("--min-agreement", opt->minAgreement,
                  "Fail (exit 1) below this fraction of agreeing layers")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--max-genuine", opt->maxGenuine,
                  "Fail (exit 1) above this many genuine mismatches per scene")
      ->capture_default_str();
  cmd->add_option("--max-hybrid-error", opt->maxHybridError,
                  "Fail (exit 1) when hybrid and ray-cast colours differ by more where their hits agree")
      ->capture_default_str();
  addRenderSettings(*cmd, opt->settings, /*withRenderer=*/false);
  return [opt, cmd]() -> int { return cmd->parsed() ? runCrossval(*opt) : -1; };
}

}  // namespace rastray
