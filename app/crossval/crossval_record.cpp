#include "app/crossval/crossval_record.h"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/error.h"
#include "common/image.h"

namespace rastray {

namespace {

// Finite doubles as JSON numbers (nlohmann writes the shortest text that
// reads back to the same double); the others, which JSON cannot hold, as
// strings.
nlohmann::json number(double v) {
  if (std::isfinite(v)) return v;
  return std::isnan(v) ? "nan" : (v > 0 ? "inf" : "-inf");
}

// Reading: a missing field names the record and the field.
struct Reader {
  const std::string& file;

  const nlohmann::json& at(const nlohmann::json& j, const char* key, const std::string& where) const {
    if (!j.is_object() || !j.contains(key)) throw InputError(file, where + key, "missing");
    return j.at(key);
  }
  double real(const nlohmann::json& j, const char* key, const std::string& where) const {
    const nlohmann::json& v = at(j, key, where);
    if (v.is_number()) return v.get<double>();
    if (v == "inf") return INFINITY;
    if (v == "-inf") return -INFINITY;
    if (v == "nan") return NAN;
    throw InputError(file, where + key, "not a number");
  }
  uint64_t count(const nlohmann::json& j, const char* key, const std::string& where) const {
    const nlohmann::json& v = at(j, key, where);
    if (!v.is_number_unsigned()) throw InputError(file, where + key, "not a count");
    return v.get<uint64_t>();
  }
  int integer(const nlohmann::json& j, const char* key, const std::string& where) const {
    const nlohmann::json& v = at(j, key, where);
    if (!v.is_number_integer()) throw InputError(file, where + key, "not an integer");
    return v.get<int>();
  }
  std::string text(const nlohmann::json& j, const char* key, const std::string& where) const {
    const nlohmann::json& v = at(j, key, where);
    if (!v.is_string()) throw InputError(file, where + key, "not a string");
    return v.get<std::string>();
  }
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
                 {"meanColor", number(v.cutOff.meanColor)},
                 {"maxColor", number(v.cutOff.maxColor)},
                 {"maxAt", {v.cutOff.maxX, v.cutOff.maxY}}};
  j["depthError"] = {{"meanAbsolute", number(v.depth.meanAbsolute)},
                     {"maxAbsolute", number(v.depth.maxAbsolute)},
                     {"meanRelative", number(v.depth.meanRelative)},
                     {"maxRelative", number(v.depth.maxRelative)}};
  return j;
}

VisibilityReport visibilityFromJson(const Reader& r, const nlohmann::json& j, const std::string& where) {
  VisibilityReport v;
  const nlohmann::json& samples = r.at(j, "samples", where);
  v.samples.compared = r.count(samples, "compared", where + "samples.");
  v.samples.agreeing = r.count(samples, "agreeing", where + "samples.");
  const nlohmann::json& layers = r.at(j, "layers", where);
  v.layers.compared = r.count(layers, "compared", where + "layers.");
  v.layers.agreeing = r.count(layers, "agreeing", where + "layers.");
  const nlohmann::json& classes = r.at(j, "mismatches", where);
  for (int c = 0; c < kMismatchClassCount; ++c)
    v.layers.mismatches[size_t(c)] = r.count(classes, toString(MismatchClass(c)), where + "mismatches.");
  const std::string cw = where + "cutOff.";
  const nlohmann::json& cut = r.at(j, "cutOff", where);
  v.layers.cutOff = r.count(cut, "layers", cw);
  v.cutOff.samples = r.count(cut, "samples", cw);
  v.cutOff.meanColor = r.real(cut, "meanColor", cw);
  v.cutOff.maxColor = r.real(cut, "maxColor", cw);
  const nlohmann::json& at = r.at(cut, "maxAt", cw);
  if (!at.is_array() || at.size() != 2) throw InputError(r.file, cw + "maxAt", "not a pixel [x, y]");
  v.cutOff.maxX = at[0].get<int>();
  v.cutOff.maxY = at[1].get<int>();
  const std::string dw = where + "depthError.";
  const nlohmann::json& depth = r.at(j, "depthError", where);
  v.depth.meanAbsolute = r.real(depth, "meanAbsolute", dw);
  v.depth.maxAbsolute = r.real(depth, "maxAbsolute", dw);
  v.depth.meanRelative = r.real(depth, "meanRelative", dw);
  v.depth.maxRelative = r.real(depth, "maxRelative", dw);
  return v;
}

nlohmann::json colorJson(const ColorMetrics& m, const AgreeingColorStats& agree) {
  return {{"mean", number(m.meanError)},
          {"rms", number(m.rmsError)},
          {"psnr", number(m.psnr)},
          {"max", number(m.maxError)},
          {"maxAt", {m.maxX, m.maxY}},
          {"yeeFailingPixels", m.yeeFailingPixels},
          {"maxWhereHitsAgree", number(agree.maxError)},
          {"layersWhereHitsAgree", agree.layers}};
}

void colorFromJson(const Reader& r, const nlohmann::json& j, const std::string& where, ColorMetrics& m,
                   AgreeingColorStats& agree) {
  m.meanError = r.real(j, "mean", where);
  m.rmsError = r.real(j, "rms", where);
  m.psnr = r.real(j, "psnr", where);
  m.maxError = r.real(j, "max", where);
  const nlohmann::json& at = r.at(j, "maxAt", where);
  if (!at.is_array() || at.size() != 2) throw InputError(r.file, where + "maxAt", "not a pixel [x, y]");
  m.maxX = at[0].get<int>();
  m.maxY = at[1].get<int>();
  m.yeeFailingPixels = r.count(j, "yeeFailingPixels", where);
  agree.maxError = r.real(j, "maxWhereHitsAgree", where);
  agree.layers = r.count(j, "layersWhereHitsAgree", where);
}

VisibilityReport countsOf(const VisibilityReport& v) {
  VisibilityReport s;
  s.samples = v.samples;
  s.layers = v.layers;
  s.depth = v.depth;
  s.cutOff = v.cutOff;
  return s;
}

std::string fnv1a(const std::vector<std::string>& words) {
  // FNV-1a, 64 bit, over the words each ended by a NUL: a name for the
  // option set (as app/studies/sweep.cpp names a sweep), not a security measure.
  uint64_t h = 1469598103934665603ull;
  for (const std::string& w : words) {
    for (const unsigned char c : w + '\0') {
      h ^= c;
      h *= 1099511628211ull;
    }
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

std::string joined(const std::vector<std::string>& words) {
  if (words.empty()) return "(no render option)";
  std::string s;
  for (const std::string& w : words) s += (s.empty() ? "" : " ") + w;
  return s;
}

nlohmann::json readJsonFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "", "cannot read");
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path, "", std::string("not JSON: ") + e.what());
  }
}

void checkSchema(const Reader& r, const nlohmann::json& j, const char* schema) {
  if (r.text(j, "schema", "") != schema) throw InputError(r.file, "schema", "is not " + std::string(schema));
  if (r.integer(j, "version", "") != kCrossvalRecordVersion)
    throw InputError(r.file, "version", "is not " + std::to_string(kCrossvalRecordVersion));
}

// What identifies the scene file's content cheaply: size and modification
// time (nanoseconds of the file clock). An edited scene is rendered again.
nlohmann::json sceneFileJson(const std::string& path) {
  std::error_code ec;
  const uintmax_t bytes = std::filesystem::file_size(path, ec);
  const auto modified = std::filesystem::last_write_time(path, ec);
  if (ec) return nullptr;
  return {{"bytes", uint64_t(bytes)}, {"modified", int64_t(modified.time_since_epoch().count())}};
}

}  // namespace

CrossvalSummary summarize(const CrossvalResult& result, int spp) {
  CrossvalSummary s;
  s.scenePath = result.scenePath;
  s.width = result.camera.width;
  s.height = result.camera.height;
  s.spp = spp;
  s.rasterVsRay = countsOf(result.rasterVsRay);
  s.hybridVsRay = countsOf(result.hybridVsRay);
  s.rasterVsRayColor = result.rasterVsRayColor;
  s.hybridVsRayColor = result.hybridVsRayColor;
  s.rasterWhereAgree = result.rasterWhereAgree;
  s.hybridWhereAgree = result.hybridWhereAgree;
  s.rasterSeconds = result.raster.seconds;
  s.raytraceSeconds = result.raytrace.seconds;
  s.hybridSeconds = result.hybrid.seconds;
  return s;
}

nlohmann::json summaryJson(const CrossvalSummary& r) {
  return {{"scene", r.scenePath},
          {"width", r.width},
          {"height", r.height},
          {"spp", r.spp},
          {"rasterVsRaytrace",
           {{"visibility", visibilityJson(r.rasterVsRay)},
            {"color", colorJson(r.rasterVsRayColor, r.rasterWhereAgree)}}},
          {"hybridVsRaytrace",
           {{"visibility", visibilityJson(r.hybridVsRay)},
            {"color", colorJson(r.hybridVsRayColor, r.hybridWhereAgree)}}},
          {"seconds",
           {{"raster", number(r.rasterSeconds)},
            {"raytrace", number(r.raytraceSeconds)},
            {"hybrid", number(r.hybridSeconds)}}}};
}

CrossvalSummary summaryFromJson(const nlohmann::json& j, const std::string& file) {
  const Reader r{file};
  CrossvalSummary s;
  s.scenePath = r.text(j, "scene", "");
  s.width = r.integer(j, "width", "");
  s.height = r.integer(j, "height", "");
  s.spp = r.integer(j, "spp", "");
  const nlohmann::json& raster = r.at(j, "rasterVsRaytrace", "");
  s.rasterVsRay =
      visibilityFromJson(r, r.at(raster, "visibility", "rasterVsRaytrace."), "rasterVsRaytrace.visibility.");
  colorFromJson(r, r.at(raster, "color", "rasterVsRaytrace."), "rasterVsRaytrace.color.", s.rasterVsRayColor,
                s.rasterWhereAgree);
  const nlohmann::json& hybrid = r.at(j, "hybridVsRaytrace", "");
  s.hybridVsRay =
      visibilityFromJson(r, r.at(hybrid, "visibility", "hybridVsRaytrace."), "hybridVsRaytrace.visibility.");
  colorFromJson(r, r.at(hybrid, "color", "hybridVsRaytrace."), "hybridVsRaytrace.color.", s.hybridVsRayColor,
                s.hybridWhereAgree);
  const nlohmann::json& seconds = r.at(j, "seconds", "");
  s.rasterSeconds = r.real(seconds, "raster", "seconds.");
  s.raytraceSeconds = r.real(seconds, "raytrace", "seconds.");
  s.hybridSeconds = r.real(seconds, "hybrid", "seconds.");
  return s;
}

std::vector<std::string> crossvalResultOptions(const RenderSettings& settings) {
  // Neither the thread count (renders are bit-identical at any count) nor
  // the memory limit changes what a scene's comparison finds.
  return toArgs(settings, {"--threads", "--max-memory"});
}

CrossvalRunRecord newCrossvalRun(const std::vector<std::string>& options) {
  CrossvalRunRecord run;
  run.options = options;
  run.fingerprint = fnv1a(options);
  // Distinct for every run started afresh: the clock and the process.
  const auto now = std::chrono::system_clock::now().time_since_epoch();
  run.run = std::to_string(std::chrono::duration_cast<std::chrono::nanoseconds>(now).count()) + "-" +
            std::to_string(::getpid());
  return run;
}

std::string crossvalRunPath(const std::string& reportDir) {
  return (std::filesystem::path(reportDir) / "crossval-run.json").string();
}

std::string crossvalScenePath(const std::string& reportDir, const std::string& scenePath) {
  return (std::filesystem::path(reportDir) / std::filesystem::path(scenePath).stem() / "crossval-scene.json")
      .string();
}

void writeRunRecord(const std::string& reportDir, const CrossvalRunRecord& run) {
  const nlohmann::json j{{"schema", kCrossvalRunSchema},
                         {"version", kCrossvalRecordVersion},
                         {"run", run.run},
                         {"fingerprint", run.fingerprint},
                         {"options", run.options}};
  writeTextFile(crossvalRunPath(reportDir), j.dump(1) + "\n");
}

std::optional<CrossvalRunRecord> readRunRecord(const std::string& reportDir) {
  const std::string path = crossvalRunPath(reportDir);
  if (!std::filesystem::exists(path)) return std::nullopt;
  const nlohmann::json j = readJsonFile(path);
  const Reader r{path};
  checkSchema(r, j, kCrossvalRunSchema);
  CrossvalRunRecord run;
  run.run = r.text(j, "run", "");
  run.fingerprint = r.text(j, "fingerprint", "");
  const nlohmann::json& options = r.at(j, "options", "");
  if (!options.is_array()) throw InputError(path, "options", "not a list");
  for (const nlohmann::json& o : options) {
    if (!o.is_string()) throw InputError(path, "options", "not a list of strings");
    run.options.push_back(o.get<std::string>());
  }
  if (fnv1a(run.options) != run.fingerprint)
    throw InputError(path, "fingerprint", "does not match its options (" + joined(run.options) + ")");
  return run;
}

void writeSceneRecord(const std::string& reportDir, const CrossvalRunRecord& run,
                      const CrossvalSummary& summary) {
  const nlohmann::json j{{"schema", kCrossvalSceneSchema},
                         {"version", kCrossvalRecordVersion},
                         {"run", run.run},
                         {"fingerprint", run.fingerprint},
                         {"sceneFile", sceneFileJson(summary.scenePath)},
                         {"result", summaryJson(summary)}};
  writeTextFile(crossvalScenePath(reportDir, summary.scenePath), j.dump(1) + "\n");
}

std::optional<CrossvalSummary> readSceneRecord(const std::string& reportDir, const CrossvalRunRecord& run,
                                               const std::string& scenePath, std::string* why) {
  const std::string path = crossvalScenePath(reportDir, scenePath);
  if (!std::filesystem::exists(path)) return std::nullopt;
  const nlohmann::json j = readJsonFile(path);
  const Reader r{path};
  checkSchema(r, j, kCrossvalSceneSchema);
  auto skip = [&](const std::string& reason) -> std::optional<CrossvalSummary> {
    if (why) *why = path + ": " + reason;
    return std::nullopt;
  };
  if (r.text(j, "run", "") != run.run) return skip("from another run");
  CrossvalSummary s = summaryFromJson(r.at(j, "result", ""), path);
  if (s.scenePath != scenePath) return skip("made from " + s.scenePath + ", not " + scenePath);
  if (r.at(j, "sceneFile", "") != sceneFileJson(scenePath)) return skip("the scene file changed since");
  return s;
}

std::string describeOptions(const std::vector<std::string>& options) { return joined(options); }

}  // namespace rastray
