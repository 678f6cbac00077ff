// `rastray sweep SCENE... --vary NAME=V1,V2,... --report DIR`: what each
// render setting costs in time and buys in accuracy (app/studies/sweep.h), and
// `rastray sweep --merge DIR... --report OUT`, which joins the shards of one
// sweep. Exit status: 0 done; 2 bad usage or input (SPEC §7), before any
// cell renders.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <set>

#include <tbb/global_control.h>

#include "app/engine/memory_estimate.h"
#include "app/studies/sweep.h"
#include "app/studies/sweep_crossover.h"
#include "app/studies/sweep_report.h"
#include "app/studies/sweep_table.h"
#include "cli/commands.h"
#include "cli/render_options_cli.h"
#include "common/error.h"
#include "common/image.h"
#include "common/interrupt.h"

namespace rastray {

namespace {

struct SweepOptions {
  std::vector<std::string> scenes, vary, merge;
  std::string reference = "auto", reportDir, shard;
  int repeat = 3;
  bool resume = false;
  bool crossover = false, quick = false;  // the crossover study (app/studies/sweep_crossover.h)
  RenderOptionsCli renderCli;             // the render options given plainly, back as text
  CLI::App* cmd = nullptr;
};

// The render options given plainly, back in `rastray render` syntax.
std::vector<std::string> plainRenderArgs(const SweepOptions& opt) { return opt.renderCli.args(); }

std::string file(const std::string& dir, const char* name) {
  return (std::filesystem::path(dir) / name).string();
}

void writeTables(const std::string& dir, const sweep::SweepMeta& meta,
                 const std::vector<sweep::CellResult>& rows) {
  writeTextFile(file(dir, "sweep.csv"), sweep::toCsv(meta.spec.vary, rows));
  writeTextFile(file(dir, "sweep.json"), sweep::toJson(meta, rows).dump(1) + "\n");
}

std::string duration(double seconds) {
  char buf[32];
  if (seconds < 120)
    std::snprintf(buf, sizeof buf, "%.0f s", seconds);
  else
    std::snprintf(buf, sizeof buf, "%.0f min", seconds / 60.0);
  return buf;
}

void createFolder(const std::string& dir);

int runMerge(const SweepOptions& opt) {
  if (!opt.scenes.empty() || !opt.vary.empty() || !opt.shard.empty() || opt.resume)
    throw InputError("command line", "--merge",
                     "takes shard folders only (no scenes, --vary, --shard, --resume)");
  sweep::SweepMeta meta;
  std::map<size_t, sweep::CellResult> byIndex;
  std::string first;
  for (const std::string& dir : opt.merge) {
    sweep::SweepMeta m;
    std::vector<sweep::CellResult> rows;
    const std::string path = file(dir, "sweep.json");
    sweep::readJson(path, m, rows);
    if (first.empty()) {
      meta = m;
      first = path;
    } else if (m.fingerprint != meta.fingerprint) {
      throw InputError(path, "fingerprint",
                       m.fingerprint + " is another sweep than " + first + " (" + meta.fingerprint + ")");
    }
    for (sweep::CellResult& r : rows) byIndex.emplace(r.index, std::move(r));
  }
  std::vector<sweep::CellResult> rows;
  for (auto& [index, r] : byIndex) rows.push_back(std::move(r));
  meta.shard = "merged";
  std::string missing;
  for (size_t i = 0, next = 0; i < meta.cells; ++i) {
    if (next < rows.size() && rows[next].index == i)
      ++next;
    else
      missing += (missing.empty() ? "" : ", ") + std::to_string(i);
  }
  createFolder(opt.reportDir);
  writeTables(opt.reportDir, meta, rows);
  sweep::writeSweepReport(opt.reportDir, meta, rows);
  std::printf("%s", sweep::formatTable(meta.spec.vary, rows).c_str());
  if (!missing.empty())
    std::fprintf(stderr, "merged %zu of %zu cells; missing cells: %s\n", rows.size(), meta.cells,
                 missing.c_str());
  return 0;
}

void createFolder(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw InputError(dir, "", "cannot create the report folder: " + ec.message());
}

int runSweep(const SweepOptions& opt) {
  if (!opt.merge.empty()) return runMerge(opt);

  sweep::SweepSpec spec;
  spec.scenes = opt.scenes;
  for (const std::string& v : opt.vary) spec.vary.push_back(sweep::parseVary(v));
  spec.plainArgs = plainRenderArgs(opt);
  spec.reference = opt.reference;
  spec.repeat = opt.repeat;
  const std::vector<sweep::Cell> cells = sweep::planCells(spec);
  const sweep::Shard shard = opt.shard.empty() ? sweep::Shard{} : sweep::parseShard(opt.shard);

  sweep::SweepMeta meta;
  meta.spec = spec;
  meta.fingerprint = sweep::fingerprint(spec);
  meta.cells = cells.size();
  meta.shard = opt.shard.empty() ? "all" : opt.shard;

  // The reference and every scene are checked before the first cell runs.
  sweep::ReferenceSource references(spec.reference);
  if (spec.reference == "auto") {
    meta.reference = "auto: " + std::string("the ray caster with");
    for (const std::string& a : sweep::autoReferenceArgs()) meta.reference += " " + a;
    meta.reference += ", at each cell's --size, camera options, --cull and pose (--time, --animation)";
  } else {
    if (spec.scenes.size() > 1)
      throw InputError("command line", "--reference",
                       "an EXR reference shows one scene; give one scene (or --reference auto)");
    const sweep::Reference& r = references.referenceFor(cells.front());
    meta.reference = r.description;
    if (!r.inexact.empty())
      std::fprintf(stderr, "rastray sweep: warning: %s: %s\n", spec.reference.c_str(), r.inexact.c_str());
    for (const sweep::Cell& c : cells)
      if (c.settings.camera.width() != r.color.width || c.settings.camera.height() != r.color.height)
        throw InputError(spec.reference, "",
                         std::to_string(r.color.width) + "x" + std::to_string(r.color.height) +
                             ", but cell " + std::to_string(c.index) + " renders " +
                             std::to_string(c.settings.camera.width()) + "x" +
                             std::to_string(c.settings.camera.height()) + " (--size)");
  }
  // Every scene loads, and every cell fits --max-memory, before the first
  // cell runs: a sweep is not refused hours in.
  for (const std::string& path : spec.scenes) {
    const Scene scene =
        loadScene(path, cells.empty() ? MemoryBudget::machineDefault() : cells.front().settings.memory);
    for (const sweep::Cell& c : cells)
      if (c.scene == path)
        checkMemory(estimateRenderMemory(scene, c.settings), c.settings.memory, path,
                    "cell " + std::to_string(c.index),
                    describeRenderWork(c.settings, toString(c.settings.renderer)));
  }
  createFolder(opt.reportDir);

  std::vector<sweep::CellResult> rows;
  std::set<size_t> done;
  const std::string csv = file(opt.reportDir, "sweep.csv"), json = file(opt.reportDir, "sweep.json");
  if (opt.resume && std::filesystem::exists(csv)) {
    if (std::filesystem::exists(json)) {
      sweep::SweepMeta old;
      std::vector<sweep::CellResult> ignored;
      sweep::readJson(json, old, ignored);
      if (old.fingerprint != meta.fingerprint)
        throw InputError(json, "fingerprint",
                         "the folder holds another sweep (" + old.fingerprint + ", this one is " +
                             meta.fingerprint +
                             "): resume needs the same scenes, --vary list, options and reference");
    }
    rows = sweep::readCsv(csv, spec.vary);
    for (const sweep::CellResult& r : rows) done.insert(r.index);
  }

  std::vector<const sweep::Cell*> todo;
  for (const sweep::Cell& c : cells)
    if (shard.contains(c.index) && !done.count(c.index)) todo.push_back(&c);
  if (opt.resume && !done.empty())
    std::fprintf(stderr, "resume: %zu cells already in %s, %zu to run\n", done.size(), csv.c_str(),
                 todo.size());

  const bool terminal = isatty(STDERR_FILENO);
  const auto start = std::chrono::steady_clock::now();
  // Ctrl-C (common/interrupt.h): the cell in progress is dropped; the
  // finished ones are in sweep.csv (written after each), for --resume.
  installInterruptHandlers();
  size_t finished = 0;
  try {
    for (size_t i = 0; i < todo.size(); ++i) {
      throwIfInterrupted();
      if (terminal) {
        const double elapsed =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        const std::string eta =
            i == 0 ? "" : ", ETA " + duration(elapsed / double(i) * double(todo.size() - i));
        std::string label = std::filesystem::path(todo[i]->scene).filename().string();
        for (size_t v = 0; v < spec.vary.size(); ++v)
          label += ", " + spec.vary[v].name + " " + todo[i]->values[v];
        std::fprintf(stderr, "\r\033[K[%zu/%zu done%s] cell %zu: %s", i, todo.size(), eta.c_str(),
                     todo[i]->index, label.c_str());
      }
      rows.push_back(sweep::measureCell(*todo[i], spec.repeat, references));
      std::sort(rows.begin(), rows.end(),
                [](const sweep::CellResult& a, const sweep::CellResult& b) { return a.index < b.index; });
      // After every cell: an interrupted run keeps what it measured (--resume).
      writeTables(opt.reportDir, meta, rows);
      ++finished;
    }
  } catch (const Interrupted& e) {
    if (terminal) std::fprintf(stderr, "\r\033[K");
    std::string account = std::to_string(done.size() + finished) + " of " +
                          std::to_string(done.size() + todo.size()) + " cells finished";
    if (done.size() + finished > 0) account += " (in " + csv + "; --resume runs the rest)";
    const sweep::Cell& c = *todo[finished];
    account +=
        "; cell " + std::to_string(c.index) + " (" + std::filesystem::path(c.scene).filename().string();
    for (size_t v = 0; v < spec.vary.size(); ++v) account += ", " + spec.vary[v].name + " " + c.values[v];
    account += ") not finished";
    throw e.withFinished(account);
  }
  if (terminal) std::fprintf(stderr, "\r\033[K");
  writeTables(opt.reportDir, meta, rows);
  sweep::writeSweepReport(opt.reportDir, meta, rows);
  std::printf("%s", sweep::formatTable(spec.vary, rows).c_str());
  return 0;
}

// `rastray sweep --crossover [--report DIR] [--quick] [--threads N] [--resume]`: the
// study renders its own generated scenes, so it takes no scene, --vary or
// other render option.
int runCrossoverStudy(const SweepOptions& opt) {
  if (!opt.scenes.empty() || !opt.vary.empty() || !opt.merge.empty() || !opt.shard.empty() ||
      opt.cmd->get_option("--reference")->count() || opt.cmd->get_option("--repeat")->count())
    throw InputError("command line", "--crossover",
                     "renders its own generated scenes: no SCENE, --vary, --reference, --repeat, --shard "
                     "or --merge");
  for (const std::string& arg : plainRenderArgs(opt))
    if (arg.rfind("--", 0) == 0 && arg != "--threads")
      throw InputError("command line", "--crossover",
                       "takes no render option but --threads (" + arg + " given)");
  crossover::CrossoverOptions o;
  o.reportDir = opt.reportDir;
  o.quick = opt.quick;
  o.threads = opt.renderCli.settings(/*allRenderers=*/false).threads;
  o.resume = opt.resume;
  return crossover::runCrossover(o);
}

}  // namespace

CommandRunner addSweepCommand(CLI::App& app) {
  auto opt = std::make_shared<SweepOptions>();
  CLI::App* cmd = app.add_subcommand(
      "sweep",
      "Render every combination of --vary settings, time it, measure its error against a reference, and "
      "write a table and log-log plots of error against time");
  opt->cmd = cmd;
  cmd->add_option("scenes", opt->scenes, "glTF scenes")->check(CLI::ExistingFile);
  cmd->add_option("--vary", opt->vary,
                  "NAME=V1,V2,...: a render option and its values (repeatable; every combination is a cell; "
                  "several numbers joined by x or :, flags on/off)")
      ->allow_extra_args(false);  // one NAME=... per --vary: a scene after it stays a scene
  cmd->add_option("--reference", opt->reference,
                  "auto (the ray caster at 64 spp, max depth 16, transparency cut-off 0) or a flat EXR")
      ->capture_default_str();
  cmd->add_option("--repeat", opt->repeat, "Renders per cell (median and min-max of the time)")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  cmd->add_option(
      "--report", opt->reportDir,
      "Folder for sweep.csv, sweep.json, index.html and plots/ (--crossover: default crossover-report)");
  cmd->add_option("--shard", opt->shard, "K/N: run only the cells whose number is K modulo N");
  cmd->add_flag("--resume", opt->resume,
                "Skip the cells already in the report folder's sweep.csv (--crossover: crossover.json)");
  cmd->add_option("--merge", opt->merge, "Shard report folders to join into --report (no scenes)");
  cmd->add_flag(
      "--crossover", opt->crossover,
      "Instead: where the rasterizer and the ray caster cross over, on generated meshes of 1e2 to 1e7 "
      "triangles at 320x240 to 3840x2160 (crossover.csv, crossover.json, plots)");
  cmd->add_flag("--quick", opt->quick,
                "With --crossover: at most 1e5 triangles and 640x480 (about a minute)");
  opt->renderCli.add(*cmd, /*withRenderer=*/true);
  return [opt, cmd]() -> int {
    if (!cmd->parsed()) return -1;
    if (opt->crossover) return runCrossoverStudy(*opt);
    if (opt->quick) throw InputError("command line", "--quick", "applies to --crossover only");
    if (opt->reportDir.empty())
      throw InputError("command line", "--report", "is required: the folder for the tables and plots");
    if (opt->merge.empty() && opt->scenes.empty())
      throw InputError("command line", "SCENE", "no scene given (or --merge DIR...)");
    if (opt->merge.empty() && opt->vary.empty())
      throw InputError("command line", "--vary", "nothing varies: give at least one --vary NAME=V1,V2,...");
    return runSweep(*opt);
  };
}

}  // namespace rastray
