// `rastray bench SCENE --renderer raster|raytrace|hybrid --size W H --spp N
// --frames K [render and camera options]`
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>

#include <tbb/global_control.h>

#include "app/bench.h"
#include "app/commands.h"
#include "app/sweep_crossover_scene.h"
#include "common/error.h"

namespace rastray {

namespace {

struct BenchCommandOptions {
  std::string scene;
  int frames = 10;
  int warmup = 1;
  std::string workDir = "bench-work";
  std::string jsonPath;
  std::string csvPath;
  RenderSettings settings;
};

// "terrain:N": the crossover study's generated terrain of N triangles
// (app/sweep_crossover_scene.h), laid out for the image's aspect, written
// once into the work directory as a .glb every peer can read.
std::string resolveScene(const BenchCommandOptions& opt) {
  const std::string prefix = "terrain:";
  if (opt.scene.rfind(prefix, 0) != 0) return opt.scene;
  const std::string count = opt.scene.substr(prefix.size());
  double triangles = 0.0;
  try {
    size_t used = 0;
    triangles = std::stod(count, &used);
    if (used != count.size()) throw std::invalid_argument(count);
  } catch (const std::exception&) {
    throw InputError("command line", "scene",
                     "'" + opt.scene + "': expected terrain:<triangles>, e.g. terrain:1e6");
  }
  if (!(triangles >= 1.0 && triangles <= 4e8) || triangles != std::floor(triangles))
    throw InputError("command line", "scene",
                     "'" + opt.scene + "': the triangle count must be a whole number in 1..4e8");
  const int w = opt.settings.camera.width(), h = opt.settings.camera.height();
  std::filesystem::create_directories(opt.workDir);
  const std::string path = opt.workDir + "/terrain-" + std::to_string(uint64_t(triangles)) + "-" +
                           std::to_string(w) + "x" + std::to_string(h) + ".glb";
  if (!std::filesystem::exists(path)) {
    const std::string partial = path + ".partial";
    crossover::crossoverScene(uint64_t(triangles), false, double(w) / double(h)).writeGlb(partial);
    std::filesystem::rename(partial, path);
  }
  return path;
}

int runBenchCommand(BenchCommandOptions& opt) {
  opt.settings.finish();
  if (opt.frames < 1) throw InputError("command line", "--frames", "must be at least 1");
  std::unique_ptr<tbb::global_control> threads;
  if (opt.settings.threads > 0)
    threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                    size_t(opt.settings.threads));
  const bool terminal = isatty(STDERR_FILENO);
  BenchRequest request;
  request.scenePath = resolveScene(opt);
  request.settings = opt.settings;
  request.frames = opt.frames;
  request.warmup = opt.warmup;
  if (terminal) request.progress = [](int i, int n) { std::fprintf(stderr, "\rbench: frame %d/%d", i, n); };

  BenchResult result = runBench(request);
  if (terminal) std::fputs("\r\033[K", stderr);
  std::fputs(benchText(result).c_str(), stdout);
  if (!opt.csvPath.empty()) {
    const bool fresh = !std::filesystem::exists(opt.csvPath) || std::filesystem::file_size(opt.csvPath) == 0;
    std::ofstream f(opt.csvPath, std::ios::app);
    if (fresh) f << benchCsvHeader() << "\n";
    f << benchCsvRow(result) << "\n";
    if (!f) throw InputError(opt.csvPath, "file", "cannot append");
  }
  if (!opt.jsonPath.empty()) {
    const nlohmann::json j = benchJson(result);
    const std::string partial = opt.jsonPath + ".partial";
    {
      std::ofstream f(partial);
      f << j.dump(2) << "\n";
      if (!f) throw InputError(opt.jsonPath, "file", "cannot write");
    }
    std::filesystem::rename(partial, opt.jsonPath);
  }
  return 0;
}

}  // namespace

CommandRunner addBenchCommand(CLI::App& app) {
  auto opt = std::make_shared<BenchCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "bench", "Time frames of one renderer on a prepared scene (load and BVH build apart)");
  cmd->add_option("scene", opt->scene, "glTF 2.0 file, or terrain:N for a generated terrain of N triangles")
      ->required();
  cmd->add_option("--frames", opt->frames, "Timed frames (after the warm-up)")->check(CLI::Range(1, 100000));
  cmd->add_option("--warmup", opt->warmup, "Untimed frames first")->check(CLI::Range(0, 1000));
  cmd->add_option("--work-dir", opt->workDir,
                  "Where generated terrains and the peers' exported OBJ files go");
  cmd->add_option("--json", opt->jsonPath, "Also write the results as JSON (schema rastray.bench v1)");
  cmd->add_option("--csv", opt->csvPath, "Append one row to this CSV file (a header first when it is new)");
  addRenderSettings(*cmd, opt->settings);
  return [opt, cmd]() -> int { return cmd->parsed() ? runBenchCommand(*opt) : -1; };
}

}  // namespace rastray
