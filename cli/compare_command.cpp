// `rastray compare A.exr B.exr`: where two SPEC §6 EXR files (from rastray
// or any other renderer) disagree about visibility, why, and how far their
// colours differ. Exit status 1 when a threshold is violated (SPEC §7), so
// the command can gate a test suite. Files may hold any subset of the SPEC
// §6 channels; without colour the colour metrics are skipped, and the
// colour options (--fail-rms, --heatmap) exit 2.
#include <cstdio>
#include <iostream>
#include <memory>

#include "app/engine/cli_options.h"
#include "cli/commands.h"
#include "cli/render_options_cli.h"
#include "common/error.h"
#include "common/memory_budget.h"
#include "compare/compare_files.h"
#include "compare/maps.h"

namespace rastray {

namespace {

struct CompareCommandOptions {
  std::string a, b, scene;
  int spp = 0;
  std::string depthFormat = toString(DepthFormat::FloatReversed);
  double edgeDistance = kDefaultEdgeDistance;
  CameraOptions camera;  // from renderCli, once the command line is parsed
  RenderOptionsCli renderCli;
  double minAgreement = 0.0, failRms = 0.0;
  uint64_t maxGenuine = 0;
  CLI::Option *minAgreementOption = nullptr, *maxGenuineOption = nullptr, *failRmsOption = nullptr;
  bool json = false;
  std::string heatmap, mismatchMap, depthMap;
  std::string maxMemory;  // empty: MemoryBudget::machineDefault()
};

// Colour options asked of files without colour (a visibility export) are
// bad usage, exit 2: --fail-rms would otherwise pass (or fail) a check it
// never made, and --heatmap would draw a picture of nothing.
void requireColorFor(const CompareResult& result, const CompareCommandOptions& opt) {
  if (result.colorSkipped.empty()) return;
  const char* option = opt.failRmsOption->count() ? "--fail-rms"
                       : !opt.heatmap.empty()     ? "--heatmap"
                                                  : nullptr;
  if (option)
    throw InputError("command line", option, "cannot apply: colour skipped (" + result.colorSkipped + ")");
}

int runCompare(CompareCommandOptions& opt) {
  const RenderSettings settings = opt.renderCli.settings(/*allRenderers=*/false);
  opt.camera = settings.camera;
  // Camera options other than the planes only make sense with the scene's
  // camera; silently ignoring them would misstate the classification.
  if (opt.scene.empty()) {
    const CameraOverrides o = opt.camera.overrides();
    const char* needsScene = o.eye                ? "--eye"
                             : o.target           ? "--target"
                             : o.up               ? "--up"
                             : o.yfovDegrees      ? "--yfov"
                             : settings.pose.time ? "--time"
                                                  : nullptr;
    if (needsScene) throw InputError("command line", needsScene, "needs --scene");
  }
  CompareInputs in;
  in.pathA = opt.a;
  in.pathB = opt.b;
  in.scenePath = opt.scene;
  in.camera = opt.camera.overrides();
  in.pose = settings.pose;
  in.spp = opt.spp;
  in.depthFormat = *parseDepthFormat(opt.depthFormat);  // CLI11 checked the spelling
  in.edgeDistance = opt.edgeDistance;
  // Both files are in memory at once: each may take half the budget
  // (estimated from its header before decoding, common/image.h).
  const MemoryBudget budget =
      opt.maxMemory.empty() ? MemoryBudget::machineDefault() : MemoryBudget::parse(opt.maxMemory);
  in.maxImageBytes = budget.bytes / 2;
  const CompareResult result = compareFiles(in);
  if (opt.renderCli.given("--size") &&
      (result.visibility.width != opt.camera.width() || result.visibility.height != opt.camera.height()))
    throw InputError("command line", "--size",
                     std::to_string(opt.camera.width()) + "x" + std::to_string(opt.camera.height()) +
                         " is not the files' size, " + std::to_string(result.visibility.width) + "x" +
                         std::to_string(result.visibility.height));

  Thresholds t;
  if (opt.minAgreementOption->count()) t.minAgreement = opt.minAgreement;
  if (opt.maxGenuineOption->count()) t.maxGenuine = opt.maxGenuine;
  if (opt.failRmsOption->count()) t.failRms = opt.failRms;
  requireColorFor(result, opt);
  const std::vector<std::string> violations = thresholdViolations(result, t);

  if (!opt.heatmap.empty()) writeDifferenceHeatMap(opt.heatmap, result.colorA, result.colorB);
  if (!opt.mismatchMap.empty()) writeMismatchMap(opt.mismatchMap, result.visibility);
  if (!opt.depthMap.empty()) writeDepthDifferenceMap(opt.depthMap, result.visibility);

  if (opt.json)
    std::cout << toJson(result, t, violations).dump(2) << "\n";
  else
    std::cout << formatTable(result, t, violations);
  std::cout.flush();
  for (const std::string& v : violations) std::fprintf(stderr, "rastray compare: %s\n", v.c_str());
  return violations.empty() ? 0 : 1;
}

}  // namespace

CommandRunner addCompareCommand(CLI::App& app) {
  auto opt = std::make_shared<CompareCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "compare",
      "Compare two EXR files (SPEC 6): visibility per sample with classified mismatches, depth and colour");
  cmd->add_option("a", opt->a, "First EXR file (flat or deep)")->required();
  cmd->add_option("b", opt->b, "Second EXR file, the same kind and size")->required();
  cmd->add_option("--scene", opt->scene,
                  "The glTF scene both files show: classify edges geometrically (else image-space only)");
  cmd->add_option("--spp", opt->spp, "Samples per pixel the files were rendered with (needed with --scene)")
      ->check(CLI::PositiveNumber);
  // The camera options the files were rendered with; --size is the files'
  // own, and when given must be theirs.
  opt->renderCli.add(*cmd, /*withRenderer=*/false, RenderOptionsCli::Rows::Camera);
  cmd->add_option(
         "--depth-format", opt->depthFormat,
         "Depth buffer whose resolution decides a depth tie: float-reversed (default), float, unorm24, "
         "unorm16")
      ->check(CLI::IsMember({"float-reversed", "float", "unorm24", "unorm16"}));
  cmd->add_option("--edge-distance", opt->edgeDistance,
                  "Pixels from an edge within which a mismatch is an edge effect (default 1/16)")
      ->check(CLI::NonNegativeNumber);
  opt->minAgreementOption =
      cmd->add_option("--min-agreement", opt->minAgreement,
                      "Fail (exit 1) when the agreeing fraction of pixels (deep: layers) is below this")
          ->check(CLI::Range(0.0, 1.0));
  opt->maxGenuineOption = cmd->add_option("--max-genuine", opt->maxGenuine,
                                          "Fail (exit 1) when more pixels (deep: layers) than this mismatch "
                                          "genuinely");
  opt->failRmsOption =
      cmd->add_option("--fail-rms", opt->failRms, "Fail (exit 1) when the colour RMS error exceeds this")
          ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--json", opt->json, "Print a JSON report instead of a table");
  cmd->add_option("--heatmap", opt->heatmap, "Write the colour-difference heat map (PNG)");
  cmd->add_option("--mismatch-map", opt->mismatchMap,
                  "Write the visibility-mismatch map coloured by class (PNG)");
  cmd->add_option("--depth-map", opt->depthMap, "Write the |dZ| heat map of agreeing hits (PNG)");
  cmd->add_option(
      "--max-memory", opt->maxMemory,
      "Refuse (exit 2) a file whose header says reading it needs more than half of this: bytes or "
      "K, M, G, T (default: 80% of physical memory)");
  return [opt, cmd]() -> int { return cmd->parsed() ? runCompare(*opt) : -1; };
}

}  // namespace rastray
