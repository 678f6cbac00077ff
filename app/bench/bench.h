// `rastray bench`: frames of one renderer on a prepared scene (loaded,
// rebased, analysed and, for rays, its BVH built once), timed one by one.
// Load and BVH build are reported apart from the frame; a frame is what
// FrameRenderer::frame() does (app/engine/render_setup.h): every pass the scene
// needs, up to the resolved image in memory, no file written.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/engine/render_setup.h"

namespace rastray {

// Median, smallest and largest of a set of times (seconds).
struct Spread {
  double median = 0.0, min = 0.0, max = 0.0;
  int count = 0;
};
// The median of an even count is the mean of the two middle values.
Spread spreadOf(std::vector<double> values);

struct BenchRequest {
  std::string scenePath;
  RenderSettings settings;  // finish() called
  int frames = 10;          // timed frames
  int warmup = 1;           // untimed frames first (caches, page faults, TBB's workers)
  // Rounds of `frames` timed frames on the one prepared scene; after each,
  // afterRound (when set) runs with the round's index and the camera — the
  // peers run there, in alternation with ours (`bench --peers`).
  int rounds = 1;
  std::function<void(int round, const Camera& camera)> afterRound;
  // Called after each frame (timed or not) with its index and the count;
  // the command shows progress with it.
  std::function<void(int frame, int count)> progress;
};

struct StageTime {
  std::string name;  // a RenderOutput::timings stage (raster.setup, raytrace.bvh_build, ...)
  Spread seconds;
};

struct BenchResult {
  std::string scenePath;
  RendererKind renderer = RendererKind::Raster;
  int width = 0, height = 0, spp = 1, threads = 0;  // threads: what TBB ran with
  uint64_t triangles = 0;
  double loadSeconds = 0.0;          // read, flatten and rebase the glTF
  double bvhBuildSeconds = -1.0;     // negative without a ray caster
  std::vector<double> frameSeconds;  // the timed frames of every round, in order
  Spread frame;
  // CPU time of all this process's threads per timed frame: less sensitive
  // than wall time to other work on a shared machine (it still counts
  // cache and memory contention).
  std::vector<double> cpuSeconds;
  Spread cpu;
  std::vector<StageTime> stages;  // per-stage times over the timed frames
  CounterSet counters;            // of the last frame (every frame does the same work)
  std::vector<std::string> passesRun, passesLeftOut;
  uint64_t peakRssBytes = 0;  // this process's peak resident memory after the frames
};

// Loads the scene, prepares it and renders warmup + frames frames.
BenchResult runBench(const BenchRequest& request);

// Rays of `kind` (a rays.* counter) per second of median frame.
double raysPerSecond(const BenchResult& result, const std::string& counter);

// Schema rastray.bench v1: the request's settings, load/build, frames,
// stages, counters, rays per second and peak memory.
nlohmann::json benchJson(const BenchResult& result);

// One CSV row (no line break) and its header, for scripts that gather
// many runs into one table (bench/scaling.sh).
std::string benchCsvHeader();
std::string benchCsvRow(const BenchResult& result);

// The human-readable table `rastray bench` prints, ending in the line
// "median frame: <ms> ms" that scripts read.
std::string benchText(const BenchResult& result);

}  // namespace rastray
