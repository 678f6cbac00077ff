// `rastray stability [--quick] [--report DIR]`: the numerical-stability
// study (app/studies/stability.h). Generates the stiff scene family, runs every
// selected case, prints one row per case × variant, saves the rows as CSV
// and JSON and writes the HTML report. Exit status: 0 when every asserted
// property holds, 1 when one fails (or a case could not run), 2 on bad
// input (SPEC §7).
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <regex>

#include <tbb/global_control.h>

#include "app/engine/render_options.h"
#include "app/studies/stability.h"
#include "app/studies/stability_report.h"
#include "cli/commands.h"
#include "common/error.h"
#include "common/image.h"
#include "common/interrupt.h"

namespace rastray {

namespace {

struct StabilityOptions {
  bool quick = false;
  std::string reportDir, scenesDir, writeScenesDir, caseRegex, jsonFile, csvFile;
  int threads = 0;
  std::vector<std::string> shadowBias;  // --shadow-bias C S: for every shadow-map variant
  std::string commandLine;              // for the report
};

// A folder for freshly generated scenes, removed when the run ends.
class TempDir {
 public:
  TempDir() {
    const auto base = std::filesystem::temp_directory_path();
    for (int n = 0;; ++n) {
      path_ = base / ("rastray-stability-" + std::to_string(getpid()) + "-" + std::to_string(n));
      if (std::filesystem::create_directory(path_)) break;
    }
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  std::string path() const { return path_.string(); }

 private:
  std::filesystem::path path_;
};

void writeCaseScene(const stability::Case& c, const std::string& dir) {
  const std::string path = (std::filesystem::path(dir) / (c.name + ".gltf")).string();
  try {
    c.build().write(path);
  } catch (const std::runtime_error& e) {
    throw InputError(path, "", std::string("cannot write the generated scene: ") + e.what());
  }
}

int runStability(const StabilityOptions& opt) {
  std::vector<stability::Case> cases = stability::allCases();

  if (!opt.writeScenesDir.empty()) {
    // The whole family and its README, whatever --case and --quick say:
    // scenes/stiff/ always holds every case.
    std::error_code ec;
    std::filesystem::create_directories(opt.writeScenesDir, ec);
    if (ec) throw InputError(opt.writeScenesDir, "", "cannot create the folder: " + ec.message());
    for (const stability::Case& c : cases) writeCaseScene(c, opt.writeScenesDir);
    writeTextFile((std::filesystem::path(opt.writeScenesDir) / "README.md").string(),
                  stability::sceneFamilyReadme(cases));
    std::printf("wrote %zu scenes and README.md to %s\n", cases.size(), opt.writeScenesDir.c_str());
    return 0;
  }

  std::regex pattern;
  try {
    pattern = std::regex(opt.caseRegex.empty() ? std::string(".") : opt.caseRegex, std::regex::ECMAScript);
  } catch (const std::regex_error& e) {
    throw InputError("command line", "--case", std::string("not a regular expression: ") + e.what());
  }
  std::vector<stability::Case> selected;
  for (stability::Case& c : cases)
    if ((!opt.quick || c.quick) && std::regex_search(c.name, pattern)) selected.push_back(std::move(c));
  if (selected.empty())
    throw InputError("command line",
                     !opt.caseRegex.empty() ? "--case"
                     : opt.quick            ? "--quick"
                                            : "stability",
                     "selects no case (see scenes/stiff/README.md for their names)");

  std::vector<std::string> shadowMapArgs;
  if (!opt.shadowBias.empty()) {
    shadowMapArgs = {"--shadow-bias", opt.shadowBias[0], opt.shadowBias[1]};
    // Its values checked by the option's own row before any case runs.
    renderSettingsFrom({"--renderer", "raster", "--shadow-bias", opt.shadowBias[0], opt.shadowBias[1]});
  }

  std::unique_ptr<TempDir> temp;
  std::string sceneDir = opt.scenesDir;
  if (sceneDir.empty()) {
    temp = std::make_unique<TempDir>();
    sceneDir = temp->path();
    for (const stability::Case& c : selected) writeCaseScene(c, sceneDir);
  } else {
    for (const stability::Case& c : selected) {
      const auto path = std::filesystem::path(sceneDir) / (c.name + ".gltf");
      if (!std::filesystem::is_regular_file(path))
        throw InputError(path.string(), "", "missing: regenerate the family with --write-scenes " + sceneDir);
    }
  }
  if (!opt.reportDir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(opt.reportDir, ec);
    if (ec) throw InputError(opt.reportDir, "", "cannot create the report folder: " + ec.message());
  }

  std::unique_ptr<tbb::global_control> threads;
  if (opt.threads > 0)
    threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                    size_t(opt.threads));
  const bool terminal = isatty(STDERR_FILENO);
  // Ctrl-C (common/interrupt.h): the case in progress stops; the tables
  // and the report index are written only for a whole run (the generated
  // scenes' temporary folder is removed on the way out).
  installInterruptHandlers();
  std::vector<stability::CaseResult> results;
  for (size_t i = 0; i < selected.size(); ++i) {
    const stability::Case& c = selected[i];
    stability::CaseContext ctx;
    ctx.sceneDir = sceneDir;
    ctx.reportDir = opt.reportDir;
    ctx.quick = opt.quick;
    ctx.threads = opt.threads;
    ctx.shadowMapArgs = shadowMapArgs;
    if (terminal)
      ctx.progress = [&, i](const std::string& line) {
        std::fprintf(stderr, "\r\033[K[%zu/%zu] %s: %s", i + 1, selected.size(), c.name.c_str(),
                     line.c_str());
      };
    stability::CaseResult result{c.name, c.group, c.parameters, c.quick, {}, {}};
    try {
      throwIfInterrupted();
      result.rows = c.run(ctx, (std::filesystem::path(sceneDir) / (c.name + ".gltf")).string());
    } catch (const Interrupted& e) {
      if (terminal) std::fprintf(stderr, "\r\033[K");
      throw e.withFinished(std::to_string(i) + " of " + std::to_string(selected.size()) +
                           " cases finished, no table or report index written; " + c.name + " not finished");
    } catch (const std::exception& e) {
      // A case that cannot run is a failed case, not a bad input: the
      // others still run and the report shows which one broke.
      result.error = e.what();
    }
    results.push_back(std::move(result));
  }
  if (terminal) std::fprintf(stderr, "\r\033[K");

  const nlohmann::json json = stability::tableJson(results, opt.quick);
  const std::string csv = stability::tableCsv(results);
  if (!opt.jsonFile.empty()) writeTextFile(opt.jsonFile, json.dump(2) + "\n");
  if (!opt.csvFile.empty()) writeTextFile(opt.csvFile, csv);
  if (!opt.reportDir.empty()) {
    writeTextFile((std::filesystem::path(opt.reportDir) / "stability.json").string(), json.dump(2) + "\n");
    writeTextFile((std::filesystem::path(opt.reportDir) / "stability.csv").string(), csv);
    stability::writeStabilityReport(opt.reportDir, results, opt.commandLine);
  }

  std::printf("%s", stability::formatTable(results).c_str());
  const std::vector<std::string> failed = stability::failures(results);
  if (!opt.reportDir.empty()) std::printf("\nreport: %s/index.html\n", opt.reportDir.c_str());
  for (const std::string& f : failed) std::printf("FAIL %s\n", f.c_str());
  return failed.empty() ? 0 : 1;
}

}  // namespace

CommandRunner addStabilityCommand(CLI::App& app) {
  auto opt = std::make_shared<StabilityOptions>();
  CLI::App* cmd = app.add_subcommand("stability",
                                     "Render the generated stiff and extreme scenes (scenes/stiff/) with "
                                     "each renderer and variant, measure, "
                                     "and check each case's property");
  cmd->add_flag("--quick", opt->quick, "Only the representative subset (under a minute on 2 cores, for CI)");
  cmd->add_option("--report", opt->reportDir,
                  "Write an HTML report (index.html, images, CSV, JSON) into this folder");
  cmd->add_option(
      "--scenes", opt->scenesDir,
      "Read the case scenes from this folder (e.g. scenes/stiff) instead of generating them afresh");
  cmd->add_option("--write-scenes", opt->writeScenesDir,
                  "Write every case's scene and README.md into this folder (e.g. scenes/stiff), then stop");
  cmd->add_option("--case", opt->caseRegex, "Run only the cases whose name matches this regular expression");
  cmd->add_option("--threads", opt->threads, "Worker threads (0: all cores)")->check(CLI::Range(0, 1024));
  cmd->add_option("--shadow-bias", opt->shadowBias,
                  "Constant and slope-scaled bias for every variant that draws shadow maps (as render "
                  "--shadow-bias; default: the render default), to sweep them over the cases")
      ->expected(2);
  cmd->add_option("--json", opt->jsonFile, "Save the rows as JSON to this file");
  cmd->add_option("--csv", opt->csvFile, "Save the rows as CSV to this file");
  cmd->get_option("--write-scenes")
      ->excludes("--scenes")
      ->excludes("--report")
      ->excludes("--quick")
      ->excludes("--case")
      ->excludes("--shadow-bias");
  return [opt, cmd]() -> int {
    if (!cmd->parsed()) return -1;
    opt->commandLine = "rastray stability";
    for (const CLI::Option* o : cmd->get_options())
      if (o->count() > 0 && o->get_name() != "--help") {
        opt->commandLine += " " + o->get_name();
        for (const std::string& v : o->results())
          if (o->get_expected_min() > 0) opt->commandLine += " " + v;
      }
    return runStability(*opt);
  };
}

}  // namespace rastray
