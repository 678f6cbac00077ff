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
#include <optional>

#include <tbb/global_control.h>
#include <nlohmann/json.hpp>

#include "app/crossval/crossval.h"
#include "app/crossval/crossval_record.h"
#include "app/crossval/crossval_report.h"
#include "app/crossval/explain.h"
#include "app/engine/render_setup.h"
#include "cli/commands.h"
#include "cli/render_options_cli.h"
#include "common/error.h"
#include "common/image.h"
#include "common/interrupt.h"

namespace rastray {

namespace {

struct CrossvalOptions {
  std::vector<std::string> scenes;
  std::string reportDir;
  bool json = false;
  bool resume = false;
  double minAgreement = 0.0;
  uint64_t maxGenuine = 0;
  double maxHybridError = 1e-5;
  RenderSettings settings;  // from renderCli, once the command line is parsed
  RenderOptionsCli renderCli;
};

// The failure lines of one scene under the thresholds.
void addFailures(const CrossvalOptions& opt, const CrossvalSummary& r, std::vector<std::string>& failures) {
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

// The scene's folder in the report: one explained example pixel per
// mismatch class, its page, and last its record (app/crossval/crossval_record.h),
// so a record means a complete folder.
void writeSceneReport(const CrossvalOptions& opt, const CrossvalRunRecord& run, const Scene& scene,
                      const CrossvalResult& r, const CrossvalSummary& summary, bool terminal) {
  const std::string folder = opt.reportDir + "/" + std::filesystem::path(r.scenePath).stem().string();
  std::filesystem::create_directories(folder);
  std::vector<ReportExplanation> explanations;
  for (int c = 0; c < kMismatchClassCount; ++c) {
    const auto& example = r.rasterVsRay.examples[size_t(c)];
    if (!example) continue;
    throwIfInterrupted();
    if (terminal)
      std::fprintf(stderr, "\rexplaining %s: %-20s", r.scenePath.c_str(), toString(MismatchClass(c)));
    const std::string file = std::string("explain-") + toString(MismatchClass(c)) + ".txt";
    writeTextFile(folder + "/" + file,
                  explanationText(explainPixel(scene, opt.settings, example->x, example->y)));
    explanations.push_back({toString(MismatchClass(c)), file});
  }
  throwIfInterrupted();
  writeCrossvalScenePage(opt.reportDir, r, explanations);
  writeSceneRecord(opt.reportDir, run, summary);
}

// With --resume: the run record in the report folder and the scenes
// already finished under it (`done`; nullopt: not finished); nullopt when
// the folder has no run record. Refuses (exit 2) a folder made with other
// render options. Writes nothing.
std::optional<CrossvalRunRecord> resumedRun(const CrossvalOptions& opt,
                                            std::vector<std::optional<CrossvalSummary>>& done) {
  const std::vector<std::string> options = crossvalResultOptions(opt.settings);
  std::optional<CrossvalRunRecord> old = readRunRecord(opt.reportDir);
  if (!old) return std::nullopt;
  if (old->options != options)
    throw InputError(crossvalRunPath(opt.reportDir), "options",
                     "the folder holds a crossval made with " + describeOptions(old->options) +
                         ", this one has " + describeOptions(options) +
                         ": --resume needs the same render options (or leave out --resume to start over)");
  size_t finished = 0;
  for (size_t i = 0; i < opt.scenes.size(); ++i) {
    std::string why;
    done[i] = readSceneRecord(opt.reportDir, *old, opt.scenes[i], &why);
    if (done[i])
      ++finished;
    else if (!why.empty())
      std::fprintf(stderr, "resume: %s: running it again\n", why.c_str());
  }
  std::fprintf(stderr, "resume: %zu of %zu scenes already done in %s, %zu to run\n", finished,
               opt.scenes.size(), opt.reportDir.c_str(), opt.scenes.size() - finished);
  return old;
}

// A new run in the report folder: its record, before the first scene.
CrossvalRunRecord startRun(const CrossvalOptions& opt) {
  const CrossvalRunRecord run = newCrossvalRun(crossvalResultOptions(opt.settings));
  std::error_code ec;
  std::filesystem::create_directories(opt.reportDir, ec);
  if (ec) throw InputError(opt.reportDir, "", "cannot create the report folder: " + ec.message());
  writeRunRecord(opt.reportDir, run);
  return run;
}

// What an interrupted run finished: "1 of 3 scenes finished (reports in
// DIR/a; --resume runs the rest); b.gltf, c.gltf not finished".
std::string finishedAccount(const CrossvalOptions& opt,
                            const std::vector<std::optional<CrossvalSummary>>& done) {
  std::string finished, unfinished;
  size_t count = 0;
  for (size_t i = 0; i < opt.scenes.size(); ++i) {
    if (done[i]) {
      ++count;
      finished += (finished.empty() ? "" : ", ") + opt.reportDir + "/" +
                  std::filesystem::path(opt.scenes[i]).stem().string();
    } else {
      unfinished += (unfinished.empty() ? "" : ", ") + opt.scenes[i];
    }
  }
  std::string s = std::to_string(count) + " of " + std::to_string(opt.scenes.size()) + " scenes finished";
  if (opt.reportDir.empty())
    s += " (no --report: nothing written)";
  else if (count > 0)
    s += " (reports in " + finished + "; --resume runs the rest)";
  return s + "; " + unfinished + " not finished";
}

int runCrossval(CrossvalOptions& opt) {
  opt.settings = opt.renderCli.settings(/*allRenderers=*/true);
  if (opt.resume && opt.reportDir.empty())
    throw InputError("command line", "--resume", "needs --report DIR: the folder of the run to finish");
  std::unique_ptr<tbb::global_control> threads;
  if (opt.settings.threads > 0)
    threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                    size_t(opt.settings.threads));
  const bool terminal = isatty(STDERR_FILENO);
  // Ctrl-C (common/interrupt.h): every finished scene's report folder is
  // whole; the one in progress is left out and named.
  installInterruptHandlers();
  std::vector<std::optional<CrossvalSummary>> done(opt.scenes.size());
  std::optional<CrossvalRunRecord> run;
  if (opt.resume) run = resumedRun(opt, done);
  try {
    // A bad file stops the run (exit 2) before anything is written: every
    // scene to run but the first, which is loaded first below, is loaded
    // once beforehand (one at a time, so only one is in memory).
    bool first = true;
    for (size_t i = 0; i < opt.scenes.size(); ++i) {
      if (done[i]) continue;
      throwIfInterrupted();
      if (!first) loadSceneForRender(opt.scenes[i], opt.settings);
      first = false;
    }
    for (size_t i = 0; i < opt.scenes.size(); ++i) {
      if (done[i]) continue;
      throwIfInterrupted();
      const Scene scene = loadSceneForRender(opt.scenes[i], opt.settings);
      if (!opt.reportDir.empty() && !run) run = startRun(opt);
      auto progress = [&](const std::string& stage) {
        if (terminal)
          std::fprintf(stderr, "\r[%zu/%zu] %s: %-10s", i + 1, opt.scenes.size(), opt.scenes[i].c_str(),
                       stage.c_str());
      };
      const CrossvalResult result = crossvalidate(scene, opt.settings, progress);
      const CrossvalSummary summary = summarize(result, opt.settings.spp);
      if (!opt.reportDir.empty()) writeSceneReport(opt, *run, scene, result, summary, terminal);
      done[i] = summary;
    }
  } catch (const Interrupted& e) {
    if (terminal) std::fprintf(stderr, "\r%80s\r", "");
    throw e.withFinished(finishedAccount(opt, done));
  }
  if (terminal) std::fprintf(stderr, "\r%80s\r", "");

  std::vector<CrossvalSummary> results;
  std::vector<std::string> failures;
  for (const std::optional<CrossvalSummary>& r : done) {
    results.push_back(*r);
    addFailures(opt, *r, failures);
  }
  if (!opt.reportDir.empty()) writeCrossvalIndex(opt.reportDir, results, opt.settings);

  if (opt.json) {
    nlohmann::json j = nlohmann::json::array();
    for (const CrossvalSummary& r : results) j.push_back(summaryJson(r));
    std::cout << nlohmann::json{{"schema", "rastray.crossval"},
                                {"version", 1},
                                {"scenes", j},
                                {"failures", failures}}
                     .dump(2)
              << "\n";
  } else {
    // The scene column is as wide as the longest file name.
    int nameWidth = 5;
    for (const CrossvalSummary& r : results)
      nameWidth = std::max(nameWidth, int(std::filesystem::path(r.scenePath).filename().string().size()));
    std::printf("%-*s %9s %4s %9s %9s %9s %7s %7s %7s %7s %7s %7s %7s %9s %8s %7s %9s %8s %8s %8s\n",
                nameWidth, "scene", "size", "spp", "samples", "layers", "agree%", "edge", "shared", "ztie",
                "plane", "genuine", "cutoff", "hyb gen", "max relZ", "RMS", "PSNR", "hybrid d", "raster s",
                "ray s", "hybrid s");
    for (const CrossvalSummary& r : results) {
      const VisibilityReport& v = r.rasterVsRay;
      char size[32];
      std::snprintf(size, sizeof size, "%dx%d", r.width, r.height);
      std::printf(
          "%-*s %9s %4d %9llu %9llu %9.4f %7llu %7llu %7llu %7llu %7llu %7llu %7llu %9.2e %8.2e %7.1f %9.2e "
          "%8.3f %8.3f %8.3f\n",
          nameWidth, std::filesystem::path(r.scenePath).filename().string().c_str(), size, r.spp,
          (unsigned long long)v.samples.compared, (unsigned long long)v.layers.compared,
          100.0 * v.layers.agreement(), (unsigned long long)v.layers.count(MismatchClass::SilhouetteEdge),
          (unsigned long long)v.layers.count(MismatchClass::SharedEdgeTie),
          (unsigned long long)v.layers.count(MismatchClass::DepthTie),
          (unsigned long long)v.layers.count(MismatchClass::NearFarPlane),
          (unsigned long long)v.layers.count(MismatchClass::Genuine), (unsigned long long)v.layers.cutOff,
          (unsigned long long)r.hybridVsRay.layers.count(MismatchClass::Genuine), v.depth.maxRelative,
          r.rasterVsRayColor.rmsError, std::isinf(r.rasterVsRayColor.psnr) ? 999.9 : r.rasterVsRayColor.psnr,
          r.hybridWhereAgree.maxError, r.rasterSeconds, r.raytraceSeconds, r.hybridSeconds);
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
  cmd->add_flag(
      "--resume", opt->resume,
      "With --report: skip the scenes an interrupted run with the same render options finished there");
  cmd->add_option("--min-agreement", opt->minAgreement,
                  "Fail (exit 1) below this fraction of agreeing layers")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--max-genuine", opt->maxGenuine,
                  "Fail (exit 1) above this many genuine mismatches per scene")
      ->capture_default_str();
  cmd->add_option("--max-hybrid-error", opt->maxHybridError,
                  "Fail (exit 1) when hybrid and ray-cast colours differ by more where their hits agree")
      ->capture_default_str();
  opt->renderCli.add(*cmd, /*withRenderer=*/false);
  return [opt, cmd]() -> int { return cmd->parsed() ? runCrossval(*opt) : -1; };
}

}  // namespace rastray
