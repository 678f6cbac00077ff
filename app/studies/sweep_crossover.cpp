#include "app/studies/sweep_crossover.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <thread>

#include "app/bench/child_process.h"
#include "app/bench/terrain_scene.h"
#include "app/report/csv.h"
#include "app/report/html.h"
#include "common/error.h"
#include "common/image.h"
#include "common/interrupt.h"

namespace rastray::crossover {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// A run shorter than this is repeated (up to maxRuns runs, the fastest
// kept): other work on the machine only ever adds time, so the fastest run
// is the best estimate of the renderer's own; long runs are not repeated to
// keep the full study within about 20 minutes.
constexpr double kRepeatBelowSeconds = 5.0;
constexpr const char* kRenderers[] = {"raster", "raytrace"};
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kAddressSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kAddressSanitizer = true;
#else
constexpr bool kAddressSanitizer = false;
#endif
#else
constexpr bool kAddressSanitizer = false;
#endif

std::string num(double v, const char* format = "%.6g") {
  if (!std::isfinite(v)) return "";
  char buf[40];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

std::string bytes(uint64_t v) { return v ? std::to_string(v) : std::string(); }

nlohmann::json numberOrNull(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

// "visibility/shaded" peak memory in MiB; "-" where not measured.
std::string mib(uint64_t visibility, uint64_t shaded) {
  auto one = [](uint64_t b) { return b ? num(double(b) / 1048576.0, "%.0f") : std::string("-"); };
  return one(visibility) + "/" + one(shaded);
}

std::string sizeText(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

// "1e5" for powers of ten, the digits otherwise.
std::string countText(uint64_t n) {
  int k = 0;
  uint64_t m = n;
  while (m >= 10 && m % 10 == 0) {
    m /= 10;
    ++k;
  }
  return m == 1 && k >= 2 ? "1e" + std::to_string(k) : std::to_string(n);
}

std::string firstLine(const std::string& s) {
  std::string line = s.substr(0, s.find('\n'));
  return line.size() > 300 ? line.substr(0, 300) + "..." : line;
}

std::string cpuModel() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) {
      const size_t colon = line.find(':');
      if (colon != std::string::npos) return line.substr(line.find_first_not_of(' ', colon + 1));
    }
  return "unknown";
}

double loadAverage() {
  std::ifstream in("/proc/loadavg");
  double one = kNaN;
  in >> one;
  return in ? one : kNaN;
}

uint64_t totalMemoryBytes() {
  std::ifstream in("/proc/meminfo");
  std::string key, unit;
  uint64_t value = 0;
  while (in >> key >> value) {
    std::getline(in, unit);
    if (key == "MemTotal:") return value * 1024;
  }
  return 0;
}

// One render of one scene variant in a child process.
struct Run {
  std::string status = "ok", detail;
  double seconds = kNaN, bvhBuild = kNaN, wall = kNaN;
  uint64_t peakRss = 0;
};

Run renderInChild(const std::string& rastray, const std::string& scene, const std::string& renderer,
                  ImageSize size, int threads, const std::string& scratch, const ChildLimits& limits) {
  const std::vector<std::string> args = {"render",
                                         scene,
                                         "-o",
                                         scratch + "/cell.exr",
                                         "--renderer",
                                         renderer,
                                         "--size",
                                         std::to_string(size.width),
                                         std::to_string(size.height),
                                         "--spp",
                                         "1",
                                         "--threads",
                                         std::to_string(threads),
                                         "--json"};
  const ChildResult c = runChild(rastray, args, scratch, limits);
  Run r;
  r.peakRss = c.peakRssBytes;
  r.wall = c.wallSeconds;
  const std::string err = firstLine(c.err);
  // What a process says when it cannot get memory: std::bad_alloc caught by
  // main(), or the dynamic loader (or AddressSanitizer) failing to map
  // memory under RLIMIT_AS.
  const bool memory = c.err.find("out of memory") != std::string::npos ||
                      c.err.find("bad_alloc") != std::string::npos ||
                      c.err.find("failed to map") != std::string::npos ||
                      c.err.find("ReserveShadowMemoryRange") != std::string::npos ||  // AddressSanitizer
                      c.err.find("annot allocate memory") != std::string::npos;
  if (c.started && !c.timedOut && c.signal == 0 && c.exitCode != 0 && memory) {
    r.status = "out of memory";
    r.detail = "exit " + std::to_string(c.exitCode) + ": " + err;
  } else if (!c.started) {
    r.status = "failed";
    r.detail = "could not run " + rastray + (c.err.empty() ? "" : ": " + err);
  } else if (c.timedOut) {
    r.status = "timeout";
    r.detail = "killed after " + num(limits.timeoutSeconds) + " s";
  } else if (c.signal != 0) {
    r.status = "killed";
    r.detail = "signal " + std::to_string(c.signal) + (c.signal == 9 ? " (the kernel's OOM killer?)" : "");
  } else if (c.exitCode != 0) {
    r.status = "failed";
    r.detail = "exit " + std::to_string(c.exitCode) + ": " + err;
  } else {
    try {
      const nlohmann::json j = nlohmann::json::parse(c.out);
      r.seconds = j.at("seconds").get<double>();
      const nlohmann::json& timings = j.at("timings");
      if (timings.contains("raytrace.bvh_build")) r.bvhBuild = timings.at("raytrace.bvh_build").get<double>();
    } catch (const std::exception& e) {
      r.status = "failed";
      r.detail = std::string("unreadable --json output: ") + e.what();
    }
  }
  return r;
}

// Runs one variant once, or up to maxRuns times when a run is short; keeps
// the fastest run (its frame time, BVH build and wall time) and the largest
// peak memory.
struct Variant {
  Run summary;
  int runs = 0;
};

Variant measureVariant(const std::string& rastray, const std::string& scene, const std::string& renderer,
                       ImageSize size, int threads, int maxRuns, const std::string& scratch,
                       const ChildLimits& limits) {
  Variant v;
  for (int i = 0; i < maxRuns; ++i) {
    const Run r = renderInChild(rastray, scene, renderer, size, threads, scratch, limits);
    v.summary.peakRss = std::max(v.summary.peakRss, r.peakRss);
    if (r.status != "ok") {
      v.summary.status = r.status;
      v.summary.detail = r.detail;
      return v;
    }
    ++v.runs;
    if (!(r.seconds >= v.summary.seconds)) {  // the first run, or a faster one
      v.summary.seconds = r.seconds;
      v.summary.bvhBuild = r.bvhBuild;
      v.summary.wall = r.wall;
    }
    if (r.seconds >= kRepeatBelowSeconds) break;
  }
  return v;
}

// A scratch folder that is removed with everything in it when it goes.
struct ScratchDir {
  std::string path;
  ScratchDir() {
    std::string templ = (std::filesystem::temp_directory_path() / "rastray-crossover-XXXXXX").string();
    if (!::mkdtemp(templ.data())) throw InputError(templ, "", "cannot create a temporary folder");
    path = templ;
  }
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
};

}  // namespace

StudyMeta::StudyMeta() : loadStart(kNaN), loadEnd(kNaN) {}

CellResult::CellResult()
    : visibilitySeconds(kNaN), shadedSeconds(kNaN), bvhBuildSeconds(kNaN), processSeconds(kNaN) {}

std::vector<uint64_t> defaultTriangles(bool quick) {
  std::vector<uint64_t> t;
  for (uint64_t n = 100; n <= (quick ? 100'000ull : 10'000'000ull); n *= 10) t.push_back(n);
  return t;
}

std::vector<ImageSize> defaultSizes(bool quick) {
  std::vector<ImageSize> s = {{320, 240}, {640, 480}, {1280, 720}, {1920, 1080}, {3840, 2160}};
  if (quick) s.resize(2);
  return s;
}

Winner winner(const std::vector<CellResult>& rows, uint64_t triangles, int width, int height, bool shaded) {
  double t[2] = {kNaN, kNaN};
  for (const CellResult& r : rows)
    if (r.triangles == triangles && r.width == width && r.height == height && r.ok())
      t[r.renderer == "raster" ? 0 : 1] = shaded ? r.shadedSeconds : r.visibilitySeconds;
  Winner w;
  if (!(t[0] > 0) || !(t[1] > 0)) return w;
  const int fast = t[0] <= t[1] ? 0 : 1;
  w.renderer = kRenderers[fast];
  w.ratio = t[1 - fast] / t[fast];
  return w;
}

std::vector<std::string> csvColumns() {
  // One name a line would be clang-format's layout; a table reads better.
  // clang-format off
  return {"triangles", "width", "height", "pixels", "renderer", "status", "runs",
          "visibility_s", "shaded_s", "bvh_build_s", "process_s",
          "visibility_peak_rss_bytes", "shaded_peak_rss_bytes", "detail"};
  // clang-format on
}

std::string toCsv(const std::vector<CellResult>& rows) {
  std::string out;
  const std::vector<std::string> columns = csvColumns();
  for (size_t i = 0; i < columns.size(); ++i) out += (i ? "," : "") + columns[i];
  out += "\n";
  for (const CellResult& r : rows) {
    out += std::to_string(r.triangles) + "," + std::to_string(r.width) + "," + std::to_string(r.height) +
           "," + std::to_string(uint64_t(r.width) * uint64_t(r.height)) + "," + r.renderer + "," +
           csvQuote(r.status) + "," + std::to_string(r.runs) + "," + num(r.visibilitySeconds) + "," +
           num(r.shadedSeconds) + "," + num(r.bvhBuildSeconds) + "," + num(r.processSeconds) + "," +
           bytes(r.visibilityPeakRssBytes) + "," + bytes(r.shadedPeakRssBytes) + "," + csvQuote(r.detail) +
           "\n";
  }
  return out;
}

nlohmann::json toJson(const StudyMeta& meta, const std::vector<CellResult>& rows) {
  using nlohmann::json;
  json j;
  j["schema"] = kJsonSchema;
  j["version"] = kJsonVersion;
  j["quick"] = meta.quick;
  j["threads"] = meta.threads;
  j["machine"] = {
      {"cpu", meta.cpu},
      {"hardwareThreads", meta.hardwareThreads},
      {"memoryBytes", meta.memoryBytes},
      {"loadAverage", {{"start", numberOrNull(meta.loadStart)}, {"end", numberOrNull(meta.loadEnd)}}}};
  j["childMemoryLimitBytes"] = meta.childMemoryLimit;
  j["spp"] = 1;
  j["scene"] =
      "generated terrain y = 0.06 sin(2 pi x / 0.5) cos(2 pi z / 0.5) seen from about 60 degrees above, "
      "tessellated as a regular grid in screen space for each image aspect (every triangle about pixels / "
      "triangles pixels, 3% margin); lit: grey diffuse, one directional light; unlit: emissive, no light";
  j["triangles"] = meta.triangles;
  json sizes = json::array();
  for (const ImageSize& s : meta.sizes) sizes.push_back({s.width, s.height});
  j["sizes"] = sizes;
  j["seconds"] = meta.seconds;
  json rowsJson = json::array();
  for (const CellResult& r : rows)
    rowsJson.push_back({{"triangles", r.triangles},
                        {"width", r.width},
                        {"height", r.height},
                        {"pixels", uint64_t(r.width) * uint64_t(r.height)},
                        {"renderer", r.renderer},
                        {"status", r.status},
                        {"detail", r.detail},
                        {"runs", r.runs},
                        {"seconds",
                         {{"visibility", numberOrNull(r.visibilitySeconds)},
                          {"shaded", numberOrNull(r.shadedSeconds)},
                          {"bvhBuild", numberOrNull(r.bvhBuildSeconds)},
                          {"process", numberOrNull(r.processSeconds)}}},
                        {"peakRssBytes",
                         {{"visibility", r.visibilityPeakRssBytes ? json(r.visibilityPeakRssBytes) : json()},
                          {"shaded", r.shadedPeakRssBytes ? json(r.shadedPeakRssBytes) : json()}}}});
  j["rows"] = rowsJson;
  json winners = json::array();
  for (const uint64_t t : meta.triangles)
    for (const ImageSize& s : meta.sizes) {
      json w = {{"triangles", t}, {"width", s.width}, {"height", s.height}};
      for (const bool shaded : {false, true}) {
        const Winner x = winner(rows, t, s.width, s.height, shaded);
        w[shaded ? "shaded" : "visibility"] = {{"faster", x.renderer.empty() ? json() : json(x.renderer)},
                                               {"ratio", x.renderer.empty() ? json() : json(x.ratio)}};
      }
      winners.push_back(w);
    }
  j["winners"] = winners;
  return j;
}

void readJson(const std::string& path, StudyMeta& meta, std::vector<CellResult>& rows) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "", "cannot open");
  try {
    const nlohmann::json j = nlohmann::json::parse(in);
    if (j.value("schema", "") != kJsonSchema || j.value("version", 0) != kJsonVersion)
      throw InputError(path, "schema",
                       "is not " + std::string(kJsonSchema) + " version " + std::to_string(kJsonVersion));
    auto number = [](const nlohmann::json& v) { return v.is_number() ? v.get<double>() : kNaN; };
    meta = StudyMeta();
    meta.quick = j.at("quick").get<bool>();
    meta.threads = j.at("threads").get<int>();
    const nlohmann::json& machine = j.at("machine");
    meta.cpu = machine.at("cpu").get<std::string>();
    meta.hardwareThreads = machine.at("hardwareThreads").get<int>();
    meta.memoryBytes = machine.at("memoryBytes").get<uint64_t>();
    meta.loadStart = number(machine.at("loadAverage").at("start"));
    meta.loadEnd = number(machine.at("loadAverage").at("end"));
    meta.childMemoryLimit = j.at("childMemoryLimitBytes").get<uint64_t>();
    meta.triangles = j.at("triangles").get<std::vector<uint64_t>>();
    meta.sizes.clear();
    for (const auto& s : j.at("sizes")) meta.sizes.push_back({s.at(0).get<int>(), s.at(1).get<int>()});
    meta.seconds = j.at("seconds").get<double>();
    rows.clear();
    for (const auto& r : j.at("rows")) {
      CellResult c;
      c.triangles = r.at("triangles").get<uint64_t>();
      c.width = r.at("width").get<int>();
      c.height = r.at("height").get<int>();
      c.renderer = r.at("renderer").get<std::string>();
      c.status = r.at("status").get<std::string>();
      c.detail = r.at("detail").get<std::string>();
      c.runs = r.at("runs").get<int>();
      const nlohmann::json& sec = r.at("seconds");
      c.visibilitySeconds = number(sec.at("visibility"));
      c.shadedSeconds = number(sec.at("shaded"));
      c.bvhBuildSeconds = number(sec.at("bvhBuild"));
      c.processSeconds = number(sec.at("process"));
      const nlohmann::json& peak = r.at("peakRssBytes");
      c.visibilityPeakRssBytes =
          peak.at("visibility").is_number() ? peak.at("visibility").get<uint64_t>() : 0;
      c.shadedPeakRssBytes = peak.at("shaded").is_number() ? peak.at("shaded").get<uint64_t>() : 0;
      rows.push_back(c);
    }
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path, "", std::string("not a crossover.json: ") + e.what());
  }
}

std::vector<NamedPlot> crossoverPlots(const StudyMeta& meta, const std::vector<CellResult>& rows) {
  std::vector<NamedPlot> plots;
  for (const bool shaded : {true, false}) {
    NamedPlot p;
    p.file = shaded ? "crossover-shaded.svg" : "crossover-visibility.svg";
    p.plot.title = std::string("Faster renderer: ") + (shaded ? "shaded frame" : "primary visibility") +
                   " (label: slower / faster time)";
    // Fixed ranges half a decade (x) and a factor 2 (y) beyond the cells, so
    // no marker or label sits on the frame.
    uint64_t tMin = ~0ull, tMax = 0;
    double pMin = 1e300, pMax = 0;
    for (const uint64_t t : meta.triangles) tMin = std::min(tMin, t), tMax = std::max(tMax, t);
    for (const ImageSize& s : meta.sizes) {
      pMin = std::min(pMin, double(s.width) * double(s.height));
      pMax = std::max(pMax, double(s.width) * double(s.height));
    }
    // Room on the right for "ray caster only" when a renderer did not run.
    bool allCompared = true;
    for (const CellResult& r : rows) allCompared = allCompared && r.ok();
    p.plot.x = {"triangles", "", AxisScale::Log, double(tMin) / 3.0,
                double(tMax) * (allCompared ? 3.0 : 100.0)};
    p.plot.y = {"image size", "pixels", AxisScale::Log, pMin / 2.0, pMax * 2.0};
    PlotSeries raster{"rasterizer faster", {}, PlotLine::None};
    raster.colour = 0;
    raster.marker = 1;  // squares
    PlotSeries ray{"ray caster faster", {}, PlotLine::None};
    ray.colour = 1;
    ray.marker = 0;  // circles
    PlotSeries none{"only one or neither renderer ran", {}, PlotLine::None};
    none.colour = 6;
    none.marker = 5;  // crosses
    for (const uint64_t t : meta.triangles)
      for (const ImageSize& s : meta.sizes) {
        const Winner w = winner(rows, t, s.width, s.height, shaded);
        PlotPoint pt{double(t), double(s.width) * double(s.height), "", ""};
        std::string times;
        for (const CellResult& r : rows)
          if (r.triangles == t && r.width == s.width && r.height == s.height)
            times += "; " + r.renderer + " " +
                     (r.ok() ? num(shaded ? r.shadedSeconds : r.visibilitySeconds, "%.4g") + " s" : r.status);
        pt.tooltip = countText(t) + " triangles at " + sizeText(s.width, s.height) + times;
        if (w.renderer.empty()) {
          // Which renderer did run, if one did (the other ran out of memory,
          // timed out or was skipped: the tooltip says which).
          for (const CellResult& r : rows)
            if (r.triangles == t && r.width == s.width && r.height == s.height && r.ok())
              pt.text = r.renderer == std::string("raster") ? "rasterizer only" : "ray caster only";
          none.points.push_back(pt);
          continue;
        }
        pt.text = num(w.ratio, w.ratio < 10 ? "%.1f" : "%.0f") + "x";
        (w.renderer == "raster" ? raster : ray).points.push_back(pt);
      }
    p.plot.series = {raster, ray};
    if (!none.points.empty()) p.plot.series.push_back(none);
    plots.push_back(p);
  }
  // Time and memory against triangles at the smallest and largest size.
  std::vector<ImageSize> ends = {meta.sizes.front()};
  if (meta.sizes.size() > 1) ends.push_back(meta.sizes.back());
  for (const bool memory : {false, true}) {
    NamedPlot p;
    p.file = memory ? "crossover-memory.svg" : "crossover-time.svg";
    p.plot.title = memory ? "Peak memory of the process rendering a shaded frame"
                          : "Time to a shaded frame (BVH build included)";
    p.plot.x = {"triangles", "", AxisScale::Log};
    p.plot.y = memory ? PlotAxis{"peak resident memory", "MiB", AxisScale::Log}
                      : PlotAxis{"time", "s", AxisScale::Log};
    int index = 0;
    for (const char* renderer : kRenderers)
      for (const ImageSize& s : ends) {
        PlotSeries series{std::string(renderer == std::string("raster") ? "rasterizer" : "ray caster") + " " +
                              sizeText(s.width, s.height),
                          {}};
        series.colour = renderer == std::string("raster") ? 0 : 1;
        series.marker = index++;
        for (const CellResult& r : rows) {
          if (r.renderer != renderer || r.width != s.width || r.height != s.height) continue;
          if (r.ok()) {
            const double y = memory ? double(r.shadedPeakRssBytes) / (1024.0 * 1024.0) : r.shadedSeconds;
            series.points.push_back(
                {double(r.triangles), y,
                 countText(r.triangles) + " triangles: " + num(y, "%.4g") + (memory ? " MiB" : " s"), ""});
          } else if (memory && r.status == "out of memory") {
            // What the process held when an allocation failed: a lower bound.
            const double y = double(std::max(r.visibilityPeakRssBytes, r.shadedPeakRssBytes)) / 1048576.0;
            if (y > 0)
              series.points.push_back(
                  {double(r.triangles), y,
                   countText(r.triangles) + " triangles: out of memory after " + num(y, "%.0f") + " MiB",
                   "out of memory (needs more)"});
          }
        }
        p.plot.series.push_back(series);
      }
    plots.push_back(p);
  }
  return plots;
}

std::string formatTable(const std::vector<CellResult>& rows) {
  std::string out;
  char line[256];
  std::snprintf(line, sizeof line, "%-10s %-10s %-9s %10s %10s %10s %10s %12s  %s\n", "triangles", "size",
                "renderer", "visib. s", "shaded s", "bvh s", "process s", "peak MiB v/s", "status");
  out += line;
  for (const CellResult& r : rows) {
    auto cell = [](double v) { return std::isfinite(v) ? num(v, "%.4f") : std::string("-"); };
    std::snprintf(line, sizeof line, "%-10s %-10s %-9s %10s %10s %10s %10s %12s  %s\n",
                  countText(r.triangles).c_str(), sizeText(r.width, r.height).c_str(), r.renderer.c_str(),
                  cell(r.visibilitySeconds).c_str(), cell(r.shadedSeconds).c_str(),
                  cell(r.bvhBuildSeconds).c_str(), cell(r.processSeconds).c_str(),
                  mib(r.visibilityPeakRssBytes, r.shadedPeakRssBytes).c_str(),
                  (r.status + (r.detail.empty() ? "" : ": " + r.detail)).c_str());
    out += line;
  }
  return out;
}

StudyMeta studyMeta(const CrossoverOptions& options) {
  StudyMeta meta;
  meta.quick = options.quick;
  meta.triangles = options.triangles.empty() ? defaultTriangles(options.quick) : options.triangles;
  meta.sizes = options.sizes.empty() ? defaultSizes(options.quick) : options.sizes;
  meta.hardwareThreads = int(std::thread::hardware_concurrency());
  meta.threads = options.threads > 0 ? options.threads : meta.hardwareThreads;
  meta.cpu = cpuModel();
  meta.memoryBytes = totalMemoryBytes();
  for (const uint64_t t : meta.triangles)
    if (t == 0 || t > 400'000'000ull)
      throw InputError("command line", "--crossover", "triangle counts must be 1 to 4e8");
  for (const ImageSize& s : meta.sizes)
    if (s.width < 1 || s.height < 1 || s.width > 16384 || s.height > 16384)
      throw InputError("command line", "--crossover", "image sizes must be 1 to 16384 pixels a side");
  return meta;
}

std::vector<CellResult> measureCells(const CrossoverOptions& options, StudyMeta& meta,
                                     const std::function<void(const CellResult&, size_t, size_t)>& onCell,
                                     const std::vector<CellResult>& finished) {
  meta = studyMeta(options);
  const std::string rastray = options.rastray.empty() ? selfExecutable() : options.rastray;
  ChildLimits limits;
  limits.timeoutSeconds = options.cellTimeoutSeconds;
  limits.addressSpaceBytes = options.childMemoryLimitBytes;
  if (limits.addressSpaceBytes == 0 && !kAddressSanitizer)
    limits.addressSpaceBytes = uint64_t(0.85 * double(availableMemoryBytes()));
  const int maxRuns = std::max(1, options.maxRuns);
  meta.childMemoryLimit = limits.addressSpaceBytes;

  meta.loadStart = loadAverage();
  const auto start = std::chrono::steady_clock::now();
  // The generated meshes and the children's output live here; removed on
  // return and when an interruption unwinds.
  ScratchDir scratch;
  std::vector<CellResult> rows;
  const size_t total = meta.triangles.size() * meta.sizes.size() * 2;
  // Cells per renderer that ran out of memory or time: a cell with at least
  // as many triangles and pixels as one of them is skipped.
  std::vector<std::pair<uint64_t, uint64_t>> failed[2];
  for (const uint64_t t : meta.triangles) {
    // The two variants of this count for one aspect ratio, written when a
    // cell first needs them and kept for the sizes that share it (the sizes
    // are in order); the meshes are freed before any child runs.
    std::string lit, unlit;
    double aspect = 0;
    for (const ImageSize& s : meta.sizes)
      for (int k = 0; k < 2; ++k) {
        throwIfInterrupted();
        CellResult r;
        r.triangles = t;
        r.width = s.width;
        r.height = s.height;
        r.renderer = kRenderers[k];
        const uint64_t pixels = uint64_t(s.width) * uint64_t(s.height);
        const auto earlier = std::find_if(finished.begin(), finished.end(), [&](const CellResult& f) {
          return f.triangles == t && f.width == s.width && f.height == s.height && f.renderer == r.renderer;
        });
        if (earlier != finished.end()) r = *earlier;  // measured by the run being resumed
        for (const auto& [ft, fp] : failed[k])
          if (r.status.empty() && t >= ft && pixels >= fp) {
            r.status = "skipped";
            r.detail = "a smaller cell of this renderer (" + countText(ft) + " triangles, " +
                       std::to_string(fp) + " pixels) did not run";
          }
        if (r.status.empty()) {
          const double sizeAspect = double(s.width) / double(s.height);
          if (sizeAspect != aspect) {
            if (!lit.empty()) {
              std::filesystem::remove(lit);
              std::filesystem::remove(unlit);
            }
            aspect = sizeAspect;
            const std::string name = std::to_string(t) + "-" + sizeText(s.width, s.height) + ".glb";
            lit = scratch.path + "/lit-" + name;
            unlit = scratch.path + "/unlit-" + name;
            crossoverScene(t, true, aspect).writeGlb(lit);
            crossoverScene(t, false, aspect).writeGlb(unlit);
            throwIfInterrupted();
          }
          const Variant vis =
              measureVariant(rastray, unlit, r.renderer, s, meta.threads, maxRuns, scratch.path, limits);
          r.visibilityPeakRssBytes = vis.summary.peakRss;
          if (vis.summary.status != "ok") {
            r.status = vis.summary.status;
            r.detail = "primary visibility: " + vis.summary.detail;
          } else {
            const Variant shaded =
                measureVariant(rastray, lit, r.renderer, s, meta.threads, maxRuns, scratch.path, limits);
            r.shadedPeakRssBytes = shaded.summary.peakRss;
            r.status = shaded.summary.status;
            r.detail = shaded.summary.status == "ok" ? "" : "shaded frame: " + shaded.summary.detail;
            r.visibilitySeconds = vis.summary.seconds;
            r.runs = std::min(vis.runs, shaded.runs);
            if (r.ok()) {
              r.shadedSeconds = shaded.summary.seconds;
              r.bvhBuildSeconds = shaded.summary.bvhBuild;
              r.processSeconds = shaded.summary.wall;
            }
          }
        }
        // Only a cell that ran out of a resource says the larger ones will too.
        if (r.status == "out of memory" || r.status == "killed" || r.status == "timeout")
          failed[k].push_back({t, pixels});
        rows.push_back(r);
        if (onCell) onCell(r, rows.size(), total);
      }
    if (!lit.empty()) {
      std::filesystem::remove(lit);
      std::filesystem::remove(unlit);
    }
  }
  meta.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  meta.loadEnd = loadAverage();
  return rows;
}

void writeCrossoverTables(const std::string& dir, const StudyMeta& meta,
                          const std::vector<CellResult>& rows) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw InputError(dir, "", "cannot create the report folder: " + ec.message());
  writeTextFile(dir + "/crossover.csv", toCsv(rows));
  writeTextFile(dir + "/crossover.json", toJson(meta, rows).dump(2) + "\n");
}

void writeCrossoverReport(const std::string& dir, const StudyMeta& meta,
                          const std::vector<CellResult>& rows) {
  writeCrossoverTables(dir, meta, rows);
  std::string body = "<h1>Rasterizer against ray caster: where each wins</h1>\n";
  body +=
      "<p>Generated terrain meshes of " + countText(meta.triangles.front()) + " to " +
      countText(meta.triangles.back()) +
      " triangles (the same surface, tessellated finer as a regular grid in screen space: every triangle "
      "covers about pixels / triangles pixels), rendered at " +
      sizeText(meta.sizes.front().width, meta.sizes.front().height) + " to " +
      sizeText(meta.sizes.back().width, meta.sizes.back().height) +
      ", 1 spp, each render in its own process. <b>Primary visibility</b>: the scene with an emissive "
      "material "
      "and no light (no shadow map, no shadow ray). <b>Shaded frame</b>: a grey diffuse material under one "
      "directional light (shadow map for the rasterizer, shadow rays for the ray caster). Both times include "
      "the ray caster's BVH build (also listed alone: a second frame of the same scene would not pay it). "
      "Times: the renderer's own clock, the fastest of 3 runs when a run takes under 5 s (other work on "
      "the machine only adds time), else of 1. Peak memory: the render "
      "process's peak resident set (loading the scene included).</p>\n";
  body += "<p>Machine: " + escapeHtml(meta.cpu) + ", " + std::to_string(meta.hardwareThreads) +
          " hardware threads, " + num(double(meta.memoryBytes) / 1073741824.0, "%.1f") + " GiB; " +
          std::to_string(meta.threads) + " render threads; 1-minute load average " +
          num(meta.loadStart, "%.1f") + " at the start and " + num(meta.loadEnd, "%.1f") +
          " at the end (other work slows the cells); study took " + num(meta.seconds, "%.0f") + " s" +
          (meta.quick ? " (--quick)" : "") + ". Files: <a href=\"crossover.csv\">crossover.csv</a>, " +
          "<a href=\"crossover.json\">crossover.json</a>.</p>\n";
  for (const NamedPlot& p : crossoverPlots(meta, rows)) {
    const PlotRender r = renderPlot(p.plot);
    writeTextFile(dir + "/" + p.file, r.svg);
    body += "<figure>" + r.svg + "<figcaption><a href=\"" + p.file + "\">" + p.file +
            "</a></figcaption></figure>\n";
  }
  body +=
      "<h2>Every cell</h2>\n<table><tr><th>triangles</th><th>size</th><th>renderer</th><th>primary "
      "visibility (s)</th><th>shaded frame (s)</th><th>BVH build (s)</th><th>process (s)</th><th>peak memory "
      "visibility/shaded (MiB)</th><th>status</th></tr>\n";
  for (const CellResult& r : rows) {
    auto cell = [](double v) { return std::isfinite(v) ? num(v, "%.4g") : std::string("&ndash;"); };
    body += "<tr><td>" + countText(r.triangles) + "</td><td>" + sizeText(r.width, r.height) + "</td><td>" +
            r.renderer + "</td><td>" + cell(r.visibilitySeconds) + "</td><td>" + cell(r.shadedSeconds) +
            "</td><td>" + cell(r.bvhBuildSeconds) + "</td><td>" + cell(r.processSeconds) + "</td><td>" +
            mib(r.visibilityPeakRssBytes, r.shadedPeakRssBytes) + "</td><td>" +
            escapeHtml(r.status + (r.detail.empty() ? "" : ": " + r.detail)) + "</td></tr>\n";
  }
  body += "</table>\n";
  writeTextFile(dir + "/index.html", reportPage("rastray crossover study", body));
}

int runCrossover(const CrossoverOptions& options) {
  const bool terminal = options.progress && ::isatty(2);
  const std::string dir = options.reportDir.empty() ? "crossover-report" : options.reportDir;
  const std::string json = dir + "/crossover.json";
  // --resume: the rows of an earlier run of the same study in DIR are kept.
  StudyMeta earlierMeta;
  std::vector<CellResult> earlier;
  if (options.resume && std::filesystem::exists(json)) {
    readJson(json, earlierMeta, earlier);
    const StudyMeta now = studyMeta(options);
    const auto same = [](const std::vector<ImageSize>& a, const std::vector<ImageSize>& b) {
      return std::equal(a.begin(), a.end(), b.begin(), b.end(), [](const ImageSize& x, const ImageSize& y) {
        return x.width == y.width && x.height == y.height;
      });
    };
    if (earlierMeta.triangles != now.triangles || !same(earlierMeta.sizes, now.sizes) ||
        earlierMeta.threads != now.threads || earlierMeta.quick != now.quick)
      throw InputError(json, "triangles",
                       "holds another crossover study (other triangle counts, sizes, --threads or --quick): "
                       "resume needs the same study");
    std::fprintf(stderr, "resume: %zu cells already in %s\n", earlier.size(), json.c_str());
  }
  // Ctrl-C (common/interrupt.h): the cell in progress is dropped (its child
  // is stopped, the generated meshes are removed); the finished cells are
  // in crossover.csv and crossover.json, written after each, for --resume.
  installInterruptHandlers();
  const auto start = std::chrono::steady_clock::now();
  StudyMeta meta;
  std::vector<CellResult> rows;
  const auto onCell = [&](const CellResult& r, size_t done, size_t cells) {
    rows.push_back(r);
    meta.seconds =
        earlierMeta.seconds + std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    writeCrossoverTables(dir, meta, rows);
    if (!terminal) return;
    std::fprintf(stderr, "\rcrossover: %zu/%zu cells, %.0f s (%s triangles, %s, %s: %s)\033[K", done, cells,
                 meta.seconds, countText(r.triangles).c_str(), sizeText(r.width, r.height).c_str(),
                 r.renderer.c_str(), r.status.c_str());
    if (done == cells) std::fprintf(stderr, "\n");
  };
  try {
    measureCells(options, meta, onCell, earlier);
  } catch (const Interrupted& e) {
    if (terminal) std::fprintf(stderr, "\r\033[K");
    const StudyMeta& study = meta;  // filled by measureCells before its first check
    const size_t cells = study.triangles.size() * study.sizes.size() * 2;
    std::string account = std::to_string(rows.size()) + " of " + std::to_string(cells) + " cells finished";
    if (!rows.empty()) account += " (in " + json + "; --resume runs the rest)";
    // Cells run in order: triangle count, then size, then renderer.
    const size_t next = rows.size();
    if (next < cells) {
      const uint64_t t = study.triangles[next / (study.sizes.size() * 2)];
      const ImageSize& s = study.sizes[next / 2 % study.sizes.size()];
      account += "; the cell of " + countText(t) + " triangles at " + sizeText(s.width, s.height) + " (" +
                 kRenderers[next % 2] + ") not finished";
    }
    throw e.withFinished(account);
  }
  meta.seconds += earlierMeta.seconds;
  writeCrossoverReport(dir, meta, rows);
  std::printf("%s", formatTable(rows).c_str());
  std::printf("\nwhere each renderer is faster (shaded frame; slower/faster time):\n");
  for (const uint64_t t : meta.triangles) {
    std::printf("  %-6s", countText(t).c_str());
    for (const ImageSize& s : meta.sizes) {
      const Winner w = winner(rows, t, s.width, s.height, true);
      std::printf("  %9s %-8s", sizeText(s.width, s.height).c_str(),
                  w.renderer.empty() ? "-" : (w.renderer + " " + num(w.ratio, "%.1f") + "x").c_str());
    }
    std::printf("\n");
  }
  std::printf("report: %s/index.html\n", dir.c_str());
  return 0;
}

}  // namespace rastray::crossover
