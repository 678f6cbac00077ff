#include "app/bench/bench.h"

#include <sys/resource.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <utility>

#include <tbb/global_control.h>

#include "app/report/csv.h"
#include "common/memory_budget.h"
#include "raster/frame_buffers.h"

namespace rastray {

namespace {

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double processCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

nlohmann::json spreadJson(const Spread& s) {
  return {{"median", s.median}, {"min", s.min}, {"max", s.max}, {"count", s.count}};
}

// The ray counters a frame reports, in the order the table lists them.
constexpr const char* kRayCounters[] = {"rays.primary", "rays.shadow", "rays.reflection", "rays.refraction",
                                        "rays.transparency"};

}  // namespace

Spread spreadOf(std::vector<double> values) {
  Spread s;
  s.count = int(values.size());
  if (values.empty()) return s;
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  s.min = values.front();
  s.max = values.back();
  s.median = n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
  return s;
}

BenchResult runBench(const BenchRequest& request) {
  const RenderSettings& s = request.settings;
  BenchResult r;
  r.scenePath = request.scenePath;
  r.renderer = s.renderer;
  r.spp = s.spp;
  r.threads = int(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));

  const auto loadStart = std::chrono::steady_clock::now();
  const Scene scene = loadSceneForRender(request.scenePath, s);
  r.loadSeconds = secondsSince(loadStart);
  r.triangles = scene.triangleCount();

  RasterOptions raster = s.raster;
  RayOptions ray = s.ray;
  raster.keepSamples = ray.keepSamples = s.keepSamples;
  // Frame after frame, as an explorer renders: the depth target and the
  // image's storage are reused instead of allocated and filled per frame.
  RasterFrameBuffers frameBuffers;
  raster.frameBuffers = &frameBuffers;
  FrameRenderer renderer(scene, s, raster, ray);
  r.width = renderer.camera().width;
  r.height = renderer.camera().height;
  r.bvhBuildSeconds = renderer.bvhBuildSeconds();

  std::map<std::string, std::vector<double>> stageSeconds;
  std::vector<std::string> stageOrder;
  const int count = request.warmup + request.frames * request.rounds;
  for (int i = 0; i < count; ++i) {
    const auto start = std::chrono::steady_clock::now();
    const double cpuStart = processCpuSeconds();
    RenderOutput output = renderer.frame();
    const double seconds = secondsSince(start);
    const double cpuSeconds = processCpuSeconds() - cpuStart;
    if (i >= request.warmup) {
      r.frameSeconds.push_back(seconds);
      r.cpuSeconds.push_back(cpuSeconds);
      for (const auto& [name, value] : output.timings) {
        if (!stageSeconds.count(name)) stageOrder.push_back(name);
        stageSeconds[name].push_back(value);
      }
    }
    if (i + 1 == count) {
      r.counters = std::move(output.counters);
      r.passesRun = std::move(output.passesRun);
      r.passesLeftOut = std::move(output.passesLeftOut);
    }
    frameBuffers.recycle(std::move(output.image));
    if (request.progress) request.progress(i + 1, count);
    const int timed = i + 1 - request.warmup;
    if (request.afterRound && timed > 0 && timed % request.frames == 0)
      request.afterRound(timed / request.frames - 1, renderer.camera());
  }
  r.frame = spreadOf(r.frameSeconds);
  r.cpu = spreadOf(r.cpuSeconds);
  for (const std::string& name : stageOrder) r.stages.push_back({name, spreadOf(stageSeconds[name])});
  r.peakRssBytes = peakRssBytes();
  return r;
}

double raysPerSecond(const BenchResult& result, const std::string& counter) {
  return result.frame.median > 0.0 ? double(result.counters.get(counter)) / result.frame.median : 0.0;
}

nlohmann::json benchJson(const BenchResult& r) {
  nlohmann::json j;
  j["schema"] = "rastray.bench";
  j["version"] = 1;
  j["scene"] = r.scenePath;
  j["renderer"] = toString(r.renderer);
  j["width"] = r.width;
  j["height"] = r.height;
  j["spp"] = r.spp;
  j["threads"] = r.threads;
  j["triangles"] = r.triangles;
  j["loadSeconds"] = r.loadSeconds;
  j["bvhBuildSeconds"] = r.bvhBuildSeconds >= 0.0 ? nlohmann::json(r.bvhBuildSeconds) : nlohmann::json();
  j["frameSeconds"] = r.frameSeconds;
  j["frame"] = spreadJson(r.frame);
  j["cpuSeconds"] = r.cpuSeconds;
  j["cpu"] = spreadJson(r.cpu);
  nlohmann::json stages = nlohmann::json::object();
  for (const StageTime& st : r.stages) stages[st.name] = spreadJson(st.seconds);
  j["stages"] = stages;
  nlohmann::json counters = nlohmann::json::object();
  for (const auto& [name, value] : r.counters.values) counters[name] = value;
  j["counters"] = counters;
  nlohmann::json rays = nlohmann::json::object();
  for (const char* name : kRayCounters)
    if (r.counters.get(name) > 0) rays[name] = raysPerSecond(r, name);
  j["raysPerSecond"] = rays;
  j["passesRun"] = r.passesRun;
  j["passesLeftOut"] = r.passesLeftOut;
  j["peakRssBytes"] = r.peakRssBytes;
  return j;
}

std::string benchCsvHeader() {
  return "scene,renderer,width,height,spp,threads,triangles,load_ms,bvh_build_ms,frame_median_ms,frame_min_"
         "ms,"
         "frame_max_ms,frames,peak_rss_mib,primary_mrays_per_s";
}

std::string benchCsvRow(const BenchResult& r) {
  char row[4096];  // the scene path is the only field of unbounded length
  const std::string scene = csvQuote(r.scenePath);
  char bvh[32] = "";  // empty without a ray caster
  if (r.bvhBuildSeconds >= 0.0) std::snprintf(bvh, sizeof bvh, "%.3f", r.bvhBuildSeconds * 1e3);
  std::snprintf(row, sizeof row, "%s,%s,%d,%d,%d,%d,%llu,%.3f,%s,%.3f,%.3f,%.3f,%d,%.1f,%.3f", scene.c_str(),
                toString(r.renderer), r.width, r.height, r.spp, r.threads,
                static_cast<unsigned long long>(r.triangles), r.loadSeconds * 1e3, bvh, r.frame.median * 1e3,
                r.frame.min * 1e3, r.frame.max * 1e3, r.frame.count,
                double(r.peakRssBytes) / (1024.0 * 1024.0), raysPerSecond(r, "rays.primary") / 1e6);
  return row;
}

std::string benchText(const BenchResult& r) {
  std::string out;
  char line[256];
  const auto add = [&](const char* format, auto... args) {
    std::snprintf(line, sizeof line, format, args...);
    out += line;
  };
  add("%s: %s %dx%d, %d spp, %d threads, %llu triangles\n", r.scenePath.c_str(), toString(r.renderer),
      r.width, r.height, r.spp, r.threads, static_cast<unsigned long long>(r.triangles));
  add("load %.1f ms", r.loadSeconds * 1e3);
  if (r.bvhBuildSeconds >= 0.0) add(", BVH build %.1f ms", r.bvhBuildSeconds * 1e3);
  add(" (not in the frame); peak memory %.1f MiB\n\n", double(r.peakRssBytes) / (1024.0 * 1024.0));

  add("%-34s %10s %10s %10s\n", "stage (ms, over frames)", "median", "min", "max");
  for (const StageTime& st : r.stages)
    add("%-34s %10.3f %10.3f %10.3f\n", st.name.c_str(), st.seconds.median * 1e3, st.seconds.min * 1e3,
        st.seconds.max * 1e3);
  add("%-34s %10.3f %10.3f %10.3f\n", "frame", r.frame.median * 1e3, r.frame.min * 1e3, r.frame.max * 1e3);
  add("%-34s %10.3f %10.3f %10.3f\n", "frame, CPU time of all threads", r.cpu.median * 1e3, r.cpu.min * 1e3,
      r.cpu.max * 1e3);

  add("\n%-34s %16s\n", "counter (one frame)", "value");
  for (const auto& [name, value] : r.counters.values)
    add("%-34s %16llu\n", name.c_str(), static_cast<unsigned long long>(value));
  bool anyRays = false;
  for (const char* name : kRayCounters) {
    if (r.counters.get(name) == 0) continue;
    if (!anyRays) add("\n%-34s %16s\n", "rays per second (median frame)", "Mrays/s");
    anyRays = true;
    add("%-34s %16.2f\n", name, raysPerSecond(r, name) / 1e6);
  }
  if (!r.passesLeftOut.empty()) {
    out += "\nleft out:\n";
    for (const std::string& p : r.passesLeftOut) out += "  " + p + "\n";
  }
  add("\nmedian frame: %.3f ms\n", r.frame.median * 1e3);
  return out;
}

}  // namespace rastray
