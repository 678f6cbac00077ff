// `rastray bench SCENE --renderer raster|raytrace|hybrid --size W H --spp N
// --frames K [render and camera options] [--peers]`
#include <malloc.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>

#include <tbb/global_control.h>

#include "app/bench/bench.h"
#include "app/bench/bench_peers.h"
#include "app/bench/terrain_scene.h"
#include "app/report/csv.h"
#include "cli/commands.h"
#include "cli/render_options_cli.h"
#include "common/error.h"
#include "common/interrupt.h"

namespace rastray {

namespace {

struct BenchCommandOptions {
  std::string scene;
  int frames = 10;
  int warmup = 1;
  std::string workDir = "bench-work";
  std::string jsonPath;
  std::string csvPath;
  bool peers = false;
  int rounds = 3;
  std::string peersCsvPath;
  RenderSettings settings;  // from renderCli, once the command line is parsed
  RenderOptionsCli renderCli;
};

// "terrain:N": the crossover study's generated terrain of N triangles
// (app/bench/terrain_scene.h), laid out for the image's aspect, written
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

// Our frames and one peer's, gathered over every round.
struct PeerRow {
  PeerRun run;  // the first round's, with every round's frames appended
  Spread wall, cpu;
};

// Rounds alternate ours and the peer, so load on a shared machine hits both
// alike; ours stays prepared (scene, BVH) across rounds. The rasterizer and
// hybrid run beside llvmpipe, the ray caster beside Embree's viewer. Runs
// the peer after our round `round`; stops once it did not run.
void runPeerRound(const BenchCommandOptions& opt, RendererKind renderer, int round, PeerRequest request,
                  std::vector<PeerRow>* rows, bool terminal) {
  if (!rows->empty() && !rows->front().run.ran) return;  // absent or failing: once is enough
  if (terminal) std::fprintf(stderr, "\rbench: peers, round %d/%d ", round + 1, opt.rounds);
  const PeerRun run = renderer == RendererKind::Raytrace ? runEmbreeViewer(request) : runOsmesaPeer(request);
  if (rows->empty()) {
    rows->push_back({run, {}, {}});
  } else {
    PeerRun& all = rows->front().run;
    all.frameMs.insert(all.frameMs.end(), run.frameMs.begin(), run.frameMs.end());
    all.cpuMs.insert(all.cpuMs.end(), run.cpuMs.begin(), run.cpuMs.end());
    if (!run.ran) all.error = run.error.empty() ? run.skipped : run.error;
  }
  PeerRow& row = rows->front();
  std::vector<double> wall, cpu;
  for (double ms : row.run.frameMs) wall.push_back(ms / 1e3);
  for (double ms : row.run.cpuMs) cpu.push_back(ms / 1e3);
  row.wall = spreadOf(wall);
  row.cpu = spreadOf(cpu);
}

void printPeerTable(const BenchResult& ours, const Spread& wall, const Spread& cpu,
                    const std::vector<PeerRow>& rows, int rounds, int frames) {
  std::printf(
      "\npeers: %d rounds of %d frames, alternating with ours; ratio = peer / rastray (above 1: rastray "
      "is faster)\n",
      rounds, frames);
  std::printf("%-40s %10s %10s %10s %10s %8s %8s\n", "renderer", "median ms", "min ms", "max ms", "cpu ms",
              "ratio", "cpu ratio");
  const std::string name = std::string("rastray ") + toString(ours.renderer);
  std::printf("%-40s %10.3f %10.3f %10.3f %10.3f %8s %8s\n", name.c_str(), wall.median * 1e3, wall.min * 1e3,
              wall.max * 1e3, cpu.median * 1e3, "1.00", "1.00");
  for (const PeerRow& row : rows) {
    const PeerRun& p = row.run;
    if (!p.ran) {
      std::printf("%-40s %s: %s\n", p.peer.c_str(), p.skipped.empty() ? "failed" : "skipped",
                  p.skipped.empty() ? p.error.c_str() : p.skipped.c_str());
      continue;
    }
    char cpuText[32] = "-", cpuRatio[32] = "-";
    if (row.cpu.count > 0) {
      std::snprintf(cpuText, sizeof cpuText, "%.3f", row.cpu.median * 1e3);
      std::snprintf(cpuRatio, sizeof cpuRatio, "%.2f", row.cpu.median / cpu.median);
    }
    std::printf("%-40s %10.3f %10.3f %10.3f %10s %8.2f %8s\n", p.peer.c_str(), row.wall.median * 1e3,
                row.wall.min * 1e3, row.wall.max * 1e3, cpuText, row.wall.median / wall.median, cpuRatio);
    if (ours.renderer == RendererKind::Raytrace && ours.spp == 1) {
      const double rays = double(ours.width) * double(ours.height);
      std::printf("  primary rays: rastray %.2f Mrays/s, %s %.2f Mrays/s (one ray per pixel, eye light)\n",
                  rays / wall.median / 1e6, p.peer.c_str(), rays / row.wall.median / 1e6);
    }
    if (!p.renderer.empty()) std::printf("  %s: %s\n", p.peer.c_str(), p.renderer.c_str());
    if (!p.error.empty()) std::printf("  note: a later round failed: %s\n", p.error.c_str());
  }
}

// Work of ours that the peers leave out (they draw one eye-lit, unshadowed
// surface per pixel): the comparison is fair only without it.
std::vector<std::string> workPeersLeaveOut(const BenchResult& ours) {
  std::vector<std::string> extra;
  const auto count = [&](const char* name) { return ours.counters.get(name); };
  if (count("raster.shadow_maps") > 0)
    extra.push_back(std::to_string(count("raster.shadow_maps")) + " shadow maps");
  for (const char* kind : {"rays.shadow", "rays.reflection", "rays.refraction", "rays.transparency"})
    if (count(kind) > 0) extra.push_back(std::to_string(count(kind)) + " " + kind);
  if (count("raster.fragments_transparent") > 0) extra.push_back("a transparency pass");
  return extra;
}

void appendPeersCsv(const std::string& path, const BenchResult& ours, const Spread& wall, const Spread& cpu,
                    const std::vector<PeerRow>& rows) {
  const bool fresh = !std::filesystem::exists(path) || std::filesystem::file_size(path) == 0;
  std::ofstream f(path, std::ios::app);
  if (fresh)
    f << "scene,renderer,width,height,spp,threads,rastray_median_ms,rastray_cpu_ms,peer,peer_median_ms,"
         "peer_min_ms,peer_max_ms,peer_cpu_ms,ratio,cpu_ratio\n";
  const std::string scene = csvQuote(ours.scenePath);
  for (const PeerRow& row : rows) {
    if (!row.run.ran) continue;
    char peerCpu[32] = "", cpuRatio[32] = "";  // empty: the peer reports no CPU time
    if (row.cpu.count) {
      std::snprintf(peerCpu, sizeof peerCpu, "%.3f", row.cpu.median * 1e3);
      std::snprintf(cpuRatio, sizeof cpuRatio, "%.3f", row.cpu.median / cpu.median);
    }
    char line[4096];  // the scene path is the only field of unbounded length
    std::snprintf(line, sizeof line, "%s,%s,%d,%d,%d,%d,%.3f,%.3f,%s,%.3f,%.3f,%.3f,%s,%.3f,%s\n",
                  scene.c_str(), toString(ours.renderer), ours.width, ours.height, ours.spp, ours.threads,
                  wall.median * 1e3, cpu.median * 1e3, row.run.peer.c_str(), row.wall.median * 1e3,
                  row.wall.min * 1e3, row.wall.max * 1e3, peerCpu, row.wall.median / wall.median, cpuRatio);
    f << line;
  }
  if (!f) throw InputError(path, "file", "cannot append");
}

// The folder an output file goes into is made before the frames, so a run
// never ends in "cannot write" after minutes of work.
void makeParentFolder(const std::string& path) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  std::error_code error;
  if (!parent.empty()) std::filesystem::create_directories(parent, error);
  if (error) throw InputError(path, "folder", "cannot create " + parent.string() + ": " + error.message());
}

int runBenchCommand(BenchCommandOptions& opt) {
  opt.settings = opt.renderCli.settings(/*allRenderers=*/false);
  if (opt.frames < 1) throw InputError("command line", "--frames", "must be at least 1");
  for (const std::string* path : {&opt.csvPath, &opt.peersCsvPath, &opt.jsonPath})
    if (!path->empty()) makeParentFolder(*path);
  std::unique_ptr<tbb::global_control> threads;
  if (opt.settings.threads > 0)
    threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                    size_t(opt.settings.threads));
  // Frame after frame, a renderer keeps its buffers. The renderers allocate
  // theirs per frame, and glibc maps blocks over 128 KiB fresh from the
  // kernel and unmaps them on free, so each frame would pay page faults and
  // zeroing for every buffer again (about 12 % of the CPU time of a 1080p
  // Cornell-box frame). Keeping freed memory in the heap (blocks up to 32
  // MiB, glibc's largest threshold) measures the steady state instead.
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
  const bool terminal = isatty(STDERR_FILENO);
  // Ctrl-C (common/interrupt.h): the frame in progress stops at its next
  // tile; the tables are written only for a whole run.
  installInterruptHandlers();
  BenchRequest request;
  request.scenePath = resolveScene(opt);
  request.settings = opt.settings;
  request.frames = opt.frames;
  request.warmup = opt.warmup;
  if (terminal) request.progress = [](int i, int n) { std::fprintf(stderr, "\rbench: frame %d/%d", i, n); };
  std::vector<PeerRow> peers;
  if (opt.peers) {
    request.rounds = opt.rounds;
    request.afterRound = [&](int round, const Camera& camera) {
      PeerRequest pr;
      pr.scenePath = request.scenePath;
      pr.camera = camera;
      pr.spp = opt.settings.spp;
      pr.threads = int(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
      pr.frames = opt.frames;
      pr.workDir = opt.workDir + "/peers";
      runPeerRound(opt, opt.settings.renderer, round, pr, &peers, terminal);
    };
  }

  const BenchResult result = runBench(request);
  if (terminal) std::fputs("\r\033[K", stderr);
  throwIfInterrupted();  // e.g. during a peer's round
  const Spread& wall = result.frame;
  const Spread& cpu = result.cpu;

  const std::string text = benchText(result);
  if (opt.peers) {
    // The ratios go above the last line, which stays ours: the median of
    // our frames over every round.
    std::fputs(text.substr(0, text.rfind("\nmedian frame:") + 1).c_str(), stdout);
    printPeerTable(result, wall, cpu, peers, opt.rounds, opt.frames);
    const std::vector<std::string> extra = workPeersLeaveOut(result);
    if (!extra.empty()) {
      std::string list;
      for (const std::string& e : extra) list += (list.empty() ? "" : ", ") + e;
      std::printf(
          "note: rastray's frame also does work the peers leave out (%s); for like-for-like frames use "
          "--shadows none on a scene without mirrors, glass or BLEND\n",
          list.c_str());
    }
    std::printf("\nmedian frame: %.3f ms\n", wall.median * 1e3);
    if (!opt.peersCsvPath.empty()) appendPeersCsv(opt.peersCsvPath, result, wall, cpu, peers);
  } else {
    std::fputs(text.c_str(), stdout);
  }
  if (!opt.csvPath.empty()) {
    const bool fresh = !std::filesystem::exists(opt.csvPath) || std::filesystem::file_size(opt.csvPath) == 0;
    std::ofstream f(opt.csvPath, std::ios::app);
    if (fresh) f << benchCsvHeader() << "\n";
    f << benchCsvRow(result) << "\n";
    if (!f) throw InputError(opt.csvPath, "file", "cannot append");
  }
  if (!opt.jsonPath.empty()) {
    nlohmann::json j = benchJson(result);
    if (opt.peers) {
      j["peerRounds"] = opt.rounds;
      nlohmann::json list = nlohmann::json::array();
      for (const PeerRow& row : peers) {
        const PeerRun& p = row.run;
        list.push_back({{"peer", p.peer},
                        {"ran", p.ran},
                        {"skipped", p.skipped},
                        {"error", p.error},
                        {"command", p.command},
                        {"renderer", p.renderer},
                        {"frameMs", p.frameMs},
                        {"cpuMs", p.cpuMs},
                        {"ratio", p.ran && wall.median > 0 ? row.wall.median / wall.median : 0.0}});
      }
      j["peers"] = list;
    }
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
  CLI::Option* peers = cmd->add_flag(
      "--peers", opt->peers,
      "Run the peer in alternation with ours and print the ratios (raster, hybrid: Mesa llvmpipe "
      "through OSMesa; raytrace: Embree's viewer)");
  cmd->add_option("--rounds", opt->rounds, "With --peers: rounds of ours then the peer")
      ->check(CLI::Range(1, 100))
      ->needs(peers);
  cmd->add_option("--peers-csv", opt->peersCsvPath, "With --peers: append one row per peer to this CSV file")
      ->needs(peers);
  cmd->add_option("--csv", opt->csvPath, "Append one row to this CSV file (a header first when it is new)");
  opt->renderCli.add(*cmd, /*withRenderer=*/true);
  return [opt, cmd]() -> int { return cmd->parsed() ? runBenchCommand(*opt) : -1; };
}

}  // namespace rastray
