#include "app/studies/sweep_table.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "app/report/csv.h"
#include "common/error.h"

namespace rastray::sweep {

namespace {

const std::vector<std::string> kTimeColumns = {"load_s",      "load_min_s",  "load_max_s", "build_s",
                                               "build_min_s", "build_max_s", "frame_s",    "frame_min_s",
                                               "frame_max_s", "time_s",      "time_min_s", "time_max_s"};
const std::vector<std::string> kErrorColumns = {
    "rms_error",      "max_error",     "perceptual_error", "visibility_error", "visibility_shared_edge",
    "depth_mean_abs", "depth_max_abs", "depth_mean_rel",   "depth_max_rel",    "depth_pixels",
    "pixels"};

// 17 significant digits: enough for any double to read back bit for bit.
std::string num(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// The numbers of a row in CSV column order (after args).
std::vector<double> numbers(const CellResult& r) {
  const CellErrors& e = r.errors;
  return {double(r.width),
          double(r.height),
          double(r.repeat),
          r.load.median,
          r.load.min,
          r.load.max,
          r.build.median,
          r.build.min,
          r.build.max,
          r.frame.median,
          r.frame.min,
          r.frame.max,
          r.time.median,
          r.time.min,
          r.time.max,
          e.rms,
          e.max,
          e.perceptual,
          e.visibility,
          e.visibilitySharedEdge,
          e.depthMeanAbs,
          e.depthMaxAbs,
          e.depthMeanRel,
          e.depthMaxRel,
          double(e.depthPixels),
          double(e.pixels)};
}

void setNumbers(CellResult& r, const std::vector<double>& v) {
  size_t i = 0;
  r.width = int(v[i++]);
  r.height = int(v[i++]);
  r.repeat = int(v[i++]);
  for (TimeStats* t : {&r.load, &r.build, &r.frame, &r.time}) {
    *t = {v[i], v[i + 1], v[i + 2]};
    i += 3;
  }
  CellErrors& e = r.errors;
  e.rms = v[i++];
  e.max = v[i++];
  e.perceptual = v[i++];
  e.visibility = v[i++];
  e.visibilitySharedEdge = v[i++];
  e.depthMeanAbs = v[i++];
  e.depthMaxAbs = v[i++];
  e.depthMeanRel = v[i++];
  e.depthMaxRel = v[i++];
  e.depthPixels = uint64_t(v[i++]);
  e.pixels = uint64_t(v[i++]);
}

nlohmann::json jsonNumber(double v) {
  if (std::isfinite(v)) return v;
  return num(v);
}

double fromJsonNumber(const nlohmann::json& j) {
  if (j.is_string()) return std::strtod(j.get<std::string>().c_str(), nullptr);
  return j.get<double>();
}

nlohmann::json statsJson(const TimeStats& t) {
  return {{"median", jsonNumber(t.median)}, {"min", jsonNumber(t.min)}, {"max", jsonNumber(t.max)}};
}

TimeStats statsFromJson(const nlohmann::json& j) {
  return {fromJsonNumber(j.at("median")), fromJsonNumber(j.at("min")), fromJsonNumber(j.at("max"))};
}

std::string sig3(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

}  // namespace

std::vector<std::string> csvColumns(const std::vector<VaryAxis>& vary) {
  std::vector<std::string> c = {"cell", "scene"};
  for (const VaryAxis& v : vary) c.push_back(v.name);
  c.insert(c.end(), {"args", "width", "height", "repeat"});
  c.insert(c.end(), kTimeColumns.begin(), kTimeColumns.end());
  c.insert(c.end(), kErrorColumns.begin(), kErrorColumns.end());
  return c;
}

bool isTimeColumn(const std::string& column) {
  return std::find(kTimeColumns.begin(), kTimeColumns.end(), column) != kTimeColumns.end();
}

std::string toCsv(const std::vector<VaryAxis>& vary, const std::vector<CellResult>& rows) {
  std::string out;
  const std::vector<std::string> columns = csvColumns(vary);
  for (size_t i = 0; i < columns.size(); ++i) out += (i ? "," : "") + csvQuote(columns[i]);
  out += "\n";
  for (const CellResult& r : rows) {
    out += std::to_string(r.index) + "," + csvQuote(r.scene);
    for (const std::string& v : r.values) out += "," + csvQuote(v);
    out += "," + csvQuote(r.args);
    for (const double v : numbers(r)) out += "," + num(v);
    out += "\n";
  }
  return out;
}

std::vector<CellResult> readCsv(const std::string& path, const std::vector<VaryAxis>& vary) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "", "cannot open");
  const std::vector<std::string> columns = csvColumns(vary);
  std::vector<std::string> fields;
  if (!readCsvRecord(in, fields) || fields != columns)
    throw InputError(path, "line 1",
                     "not the header of this sweep's CSV (expected " + std::to_string(columns.size()) +
                         " columns starting cell,scene)");
  std::vector<CellResult> rows;
  for (int line = 2; readCsvRecord(in, fields); ++line) {
    if (fields.size() == 1 && fields[0].empty()) continue;
    if (fields.size() != columns.size())
      throw InputError(path, "line " + std::to_string(line),
                       std::to_string(fields.size()) + " fields, expected " + std::to_string(columns.size()));
    CellResult r;
    size_t i = 0;
    char* end = nullptr;
    const auto number = [&](const std::string& s) {
      const double v = std::strtod(s.c_str(), &end);
      if (s.empty() || *end != '\0')
        throw InputError(path, "line " + std::to_string(line) + ": " + columns[i - 1],
                         "'" + s + "' is not a number");
      return v;
    };
    r.index = size_t(number(fields[i++]));
    r.scene = fields[i++];
    for (size_t a = 0; a < vary.size(); ++a) r.values.push_back(fields[i++]);
    r.args = fields[i++];
    std::vector<double> v;
    while (i < fields.size()) v.push_back(number(fields[i++]));
    setNumbers(r, v);
    rows.push_back(std::move(r));
  }
  return rows;
}

nlohmann::json toJson(const SweepMeta& meta, const std::vector<CellResult>& rows) {
  nlohmann::json vary = nlohmann::json::array();
  for (const VaryAxis& v : meta.spec.vary) vary.push_back({{"name", v.name}, {"values", v.values}});
  nlohmann::json j;
  j["schema"] = kJsonSchema;
  j["version"] = kJsonVersion;
  j["fingerprint"] = meta.fingerprint;
  j["sweep"] = {{"scenes", meta.spec.scenes},
                {"vary", vary},
                {"options", meta.spec.plainArgs},
                {"reference", meta.spec.reference},
                {"repeat", meta.spec.repeat}};
  j["reference"] = meta.reference;
  j["cells"] = meta.cells;
  j["shard"] = meta.shard;
  nlohmann::json out = nlohmann::json::array();
  for (const CellResult& r : rows) {
    nlohmann::json settings = nlohmann::json::object();
    for (size_t a = 0; a < meta.spec.vary.size() && a < r.values.size(); ++a)
      settings[meta.spec.vary[a].name] = r.values[a];
    const CellErrors& e = r.errors;
    out.push_back({{"cell", r.index},
                   {"scene", r.scene},
                   {"settings", settings},
                   {"args", r.args},
                   {"width", r.width},
                   {"height", r.height},
                   {"repeat", r.repeat},
                   {"seconds",
                    {{"load", statsJson(r.load)},
                     {"build", statsJson(r.build)},
                     {"frame", statsJson(r.frame)},
                     {"time", statsJson(r.time)}}},
                   {"errors",
                    {{"rms", jsonNumber(e.rms)},
                     {"max", jsonNumber(e.max)},
                     {"perceptual", jsonNumber(e.perceptual)},
                     {"visibility", jsonNumber(e.visibility)},
                     {"visibilitySharedEdge", jsonNumber(e.visibilitySharedEdge)},
                     {"depth",
                      {{"meanAbsolute", jsonNumber(e.depthMeanAbs)},
                       {"maxAbsolute", jsonNumber(e.depthMaxAbs)},
                       {"meanRelative", jsonNumber(e.depthMeanRel)},
                       {"maxRelative", jsonNumber(e.depthMaxRel)},
                       {"pixels", e.depthPixels}}},
                     {"pixels", e.pixels}}}});
  }
  j["rows"] = out;
  return j;
}

void readJson(const std::string& path, SweepMeta& meta, std::vector<CellResult>& rows) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "", "cannot open");
  try {
    const nlohmann::json j = nlohmann::json::parse(in);
    if (j.value("schema", "") != kJsonSchema || j.value("version", 0) != kJsonVersion)
      throw InputError(path, "schema",
                       "expected " + std::string(kJsonSchema) + " version " + std::to_string(kJsonVersion));
    meta = {};
    meta.fingerprint = j.at("fingerprint").get<std::string>();
    const nlohmann::json& s = j.at("sweep");
    meta.spec.scenes = s.at("scenes").get<std::vector<std::string>>();
    for (const nlohmann::json& v : s.at("vary"))
      meta.spec.vary.push_back(
          {v.at("name").get<std::string>(), v.at("values").get<std::vector<std::string>>()});
    meta.spec.plainArgs = s.at("options").get<std::vector<std::string>>();
    meta.spec.reference = s.at("reference").get<std::string>();
    meta.spec.repeat = s.at("repeat").get<int>();
    meta.reference = j.at("reference").get<std::string>();
    meta.cells = j.at("cells").get<size_t>();
    meta.shard = j.at("shard").get<std::string>();
    rows.clear();
    for (const nlohmann::json& r : j.at("rows")) {
      CellResult c;
      c.index = r.at("cell").get<size_t>();
      c.scene = r.at("scene").get<std::string>();
      for (const VaryAxis& v : meta.spec.vary)
        c.values.push_back(r.at("settings").at(v.name).get<std::string>());
      c.args = r.at("args").get<std::string>();
      c.width = r.at("width").get<int>();
      c.height = r.at("height").get<int>();
      c.repeat = r.at("repeat").get<int>();
      const nlohmann::json& t = r.at("seconds");
      c.load = statsFromJson(t.at("load"));
      c.build = statsFromJson(t.at("build"));
      c.frame = statsFromJson(t.at("frame"));
      c.time = statsFromJson(t.at("time"));
      const nlohmann::json& e = r.at("errors");
      const nlohmann::json& d = e.at("depth");
      CellErrors& x = c.errors;
      x.rms = fromJsonNumber(e.at("rms"));
      x.max = fromJsonNumber(e.at("max"));
      x.perceptual = fromJsonNumber(e.at("perceptual"));
      x.visibility = fromJsonNumber(e.at("visibility"));
      x.visibilitySharedEdge = fromJsonNumber(e.at("visibilitySharedEdge"));
      x.depthMeanAbs = fromJsonNumber(d.at("meanAbsolute"));
      x.depthMaxAbs = fromJsonNumber(d.at("maxAbsolute"));
      x.depthMeanRel = fromJsonNumber(d.at("meanRelative"));
      x.depthMaxRel = fromJsonNumber(d.at("maxRelative"));
      x.depthPixels = d.at("pixels").get<uint64_t>();
      x.pixels = e.at("pixels").get<uint64_t>();
      rows.push_back(std::move(c));
    }
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path, "", std::string("not a sweep.json: ") + e.what());
  }
}

std::string formatTable(const std::vector<VaryAxis>& vary, const std::vector<CellResult>& rows) {
  std::vector<std::string> header = {"cell", "scene"};
  for (const VaryAxis& v : vary) header.push_back(v.name);
  header.insert(header.end(), {"size", "time ms", "min-max ms", "build ms", "load ms", "RMS", "max", "Yee %",
                               "vis %", "maxrelZ"});
  std::vector<std::vector<std::string>> cells;
  const auto ms = [](double s) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.2f", s * 1e3);
    return std::string(buf);
  };
  const auto pct = [](double f) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3f", f * 100.0);
    return std::string(buf);
  };
  for (const CellResult& r : rows) {
    std::vector<std::string> line = {std::to_string(r.index), r.scene};
    const size_t slash = r.scene.find_last_of('/');
    if (slash != std::string::npos) line[1] = r.scene.substr(slash + 1);
    line.insert(line.end(), r.values.begin(), r.values.end());
    line.insert(line.end(), {std::to_string(r.width) + "x" + std::to_string(r.height), ms(r.time.median),
                             ms(r.time.min) + "-" + ms(r.time.max), ms(r.build.median), ms(r.load.median),
                             sig3(r.errors.rms), sig3(r.errors.max), pct(r.errors.perceptual),
                             pct(r.errors.visibility), sig3(r.errors.depthMaxRel)});
    cells.push_back(line);
  }
  std::vector<size_t> width(header.size());
  for (size_t c = 0; c < header.size(); ++c) {
    width[c] = header[c].size();
    for (const auto& line : cells) width[c] = std::max(width[c], line[c].size());
  }
  std::ostringstream out;
  const auto print = [&](const std::vector<std::string>& line) {
    for (size_t c = 0; c < line.size(); ++c) {
      // Text columns (scene and settings) left-aligned, numbers right-aligned.
      const bool text = c >= 1 && c < 2 + vary.size();
      out << (c ? "  " : "");
      if (text)
        out << line[c] << std::string(width[c] - line[c].size(), ' ');
      else
        out << std::string(width[c] - line[c].size(), ' ') << line[c];
    }
    out << "\n";
  };
  print(header);
  for (const auto& line : cells) print(line);
  return out.str();
}

}  // namespace rastray::sweep
