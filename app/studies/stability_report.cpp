#include "app/studies/stability_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "app/report/csv.h"
#include "app/report/html.h"
#include "common/error.h"
#include "common/image.h"

namespace rastray::stability {

namespace {

std::string fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

bool asserts(const Row& r) { return !r.property.empty(); }

std::string resultWord(const Row& r) { return !asserts(r) ? "-" : r.pass ? "ok" : "FAIL"; }

// The cells of one row as the table prints them ("-": not measured).
struct Cells {
  std::string agreement, genuine, nanInf, acne, leaks, metric, seconds;
};

Cells cellsOf(const Row& r) {
  Cells c;
  c.agreement = std::isnan(r.agreement) ? "-" : fmt("%.4f", 100.0 * r.agreement);
  c.genuine = r.genuine < 0 ? "-" : std::to_string(r.genuine);
  c.nanInf = std::to_string(r.nanInf);
  c.acne = r.acne < 0 ? "-" : std::to_string(r.acne);
  c.leaks = r.leaks < 0 ? "-" : std::to_string(r.leaks);
  c.metric = r.metricName.empty() ? "-" : r.metricName + " = " + fmt("%.4g", r.metric);
  c.seconds = fmt("%.3f", r.seconds);
  return c;
}

nlohmann::json numberOrNull(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}
nlohmann::json countOrNull(int64_t v) { return v < 0 ? nlohmann::json(nullptr) : nlohmann::json(v); }

}  // namespace

std::vector<std::string> failures(const std::vector<CaseResult>& results) {
  std::vector<std::string> out;
  for (const CaseResult& c : results) {
    if (!c.error.empty()) out.push_back(c.name + ": " + c.error);
    for (const Row& r : c.rows)
      if (asserts(r) && !r.pass) {
        const Cells cells = cellsOf(r);
        out.push_back(c.name + " / " + r.variant + ": " + r.property + " (agree% " + cells.agreement +
                      ", genuine " + cells.genuine + ", nan/inf " + cells.nanInf + ", acne " + cells.acne +
                      ", leaks " + cells.leaks + ", " + cells.metric + ")");
      }
  }
  return out;
}

std::string formatTable(const std::vector<CaseResult>& results) {
  const std::vector<std::string> header = {"case",  "variant", "agree%", "genuine", "nan/inf", "acne",
                                           "leaks", "metric",  "time s", "result",  "property"};
  std::vector<std::vector<std::string>> lines;
  for (const CaseResult& c : results) {
    if (!c.error.empty())
      lines.push_back({c.name, "(error)", "-", "-", "-", "-", "-", "-", "-", "FAIL", c.error});
    for (const Row& r : c.rows) {
      const Cells x = cellsOf(r);
      lines.push_back({c.name, r.variant, x.agreement, x.genuine, x.nanInf, x.acne, x.leaks, x.metric,
                       x.seconds, resultWord(r), r.property});
    }
  }
  std::vector<size_t> width(header.size());
  for (size_t k = 0; k < header.size(); ++k) {
    width[k] = header[k].size();
    for (const auto& line : lines) width[k] = std::max(width[k], line[k].size());
  }
  // Text columns (case, variant, metric, property) left-aligned, numbers right.
  const auto left = [](size_t k) { return k == 0 || k == 1 || k == 7 || k == 9 || k == 10; };
  std::string out;
  const auto emit = [&](const std::vector<std::string>& cells) {
    std::string line;
    for (size_t k = 0; k < cells.size(); ++k) {
      const std::string pad(width[k] - cells[k].size(), ' ');
      if (k) line += "  ";
      line += left(k) ? (k + 1 == cells.size() ? cells[k] : cells[k] + pad) : pad + cells[k];
    }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    out += line + "\n";
  };
  emit(header);
  for (const auto& line : lines) emit(line);
  return out;
}

std::string tableCsv(const std::vector<CaseResult>& results) {
  std::string out =
      "case,group,variant,agreement,genuine,nan_inf,acne,leaks,metric_name,metric,seconds,property,pass\n";
  const auto num = [](double v) { return std::isfinite(v) ? fmt("%.9g", v) : std::string(); };
  const auto count = [](int64_t v) { return v < 0 ? std::string() : std::to_string(v); };
  for (const CaseResult& c : results) {
    if (!c.error.empty())
      out +=
          csvQuote(c.name) + "," + csvQuote(c.group) + ",(error),,,,,,,,," + csvQuote(c.error) + ",false\n";
    for (const Row& r : c.rows)
      out += csvQuote(c.name) + "," + csvQuote(c.group) + "," + csvQuote(r.variant) + "," + num(r.agreement) +
             "," + count(r.genuine) + "," + std::to_string(r.nanInf) + "," + count(r.acne) + "," +
             count(r.leaks) + "," + csvQuote(r.metricName) + "," + num(r.metric) + "," + num(r.seconds) +
             "," + csvQuote(r.property) + "," + (r.pass ? "true" : "false") + "\n";
  }
  return out;
}

nlohmann::json tableJson(const std::vector<CaseResult>& results, bool quick) {
  nlohmann::json cases = nlohmann::json::array();
  for (const CaseResult& c : results) {
    nlohmann::json rows = nlohmann::json::array();
    for (const Row& r : c.rows) {
      nlohmann::json images = nlohmann::json::array();
      for (const auto& [file, caption] : r.images) images.push_back({{"file", file}, {"caption", caption}});
      rows.push_back({{"variant", r.variant},
                      {"agreement", numberOrNull(r.agreement)},
                      {"genuine", countOrNull(r.genuine)},
                      {"nanInf", r.nanInf},
                      {"acne", countOrNull(r.acne)},
                      {"leaks", countOrNull(r.leaks)},
                      {"metricName", r.metricName},
                      {"metric", numberOrNull(r.metric)},
                      {"seconds", r.seconds},
                      {"property", r.property},
                      {"pass", r.pass},
                      {"images", images}});
    }
    cases.push_back({{"name", c.name},
                     {"group", c.group},
                     {"parameters", c.parameters},
                     {"quick", c.quick},
                     {"error", c.error.empty() ? nlohmann::json(nullptr) : nlohmann::json(c.error)},
                     {"rows", rows}});
  }
  const std::vector<std::string> failed = failures(results);
  return {{"schema", "rastray.stability"}, {"version", 1},       {"quick", quick},
          {"passed", failed.empty()},      {"failures", failed}, {"cases", cases}};
}

void writeStabilityReport(const std::string& dir, const std::vector<CaseResult>& results,
                          const std::string& runLine) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw InputError(dir, "", "cannot create the report folder: " + ec.message());

  std::string b =
      "<style>img.px{min-width:256px;height:auto}td.fail{color:#b00020;font-weight:600}"
      "td.ok{color:#0a7a2f}section{margin-top:28px}</style>"
      "<h1>rastray numerical stability</h1><p>Each case of the generated family (scenes/stiff/) rendered by "
      "each renderer under the variants that matter for it, measured against its reference (the ray caster, "
      "or the same scene at the origin), with the property the case asserts.</p><p><code>" +
      escapeHtml(runLine) + "</code></p>";
  const std::vector<std::string> failed = failures(results);
  if (failed.empty()) {
    b += "<p class=\"good\">Every asserted property holds.</p>";
  } else {
    b += "<p class=\"bad\">" + std::to_string(failed.size()) + " failed:</p><ul>";
    for (const std::string& f : failed) b += "<li>" + escapeHtml(f) + "</li>";
    b += "</ul>";
  }
  b += "<table><tr><th class=\"l\">case</th><th class=\"l\">variant</th><th>agree %</th><th>genuine</th>"
       "<th>NaN/Inf</th><th>acne</th><th>leaks</th><th class=\"l\">metric</th><th>time s</th>"
       "<th class=\"l\">result</th><th class=\"l\">property</th></tr>";
  for (const CaseResult& c : results) {
    const std::string link = "<a href=\"#" + escapeHtml(c.name) + "\">" + escapeHtml(c.name) + "</a>";
    if (!c.error.empty())
      b += "<tr><td class=\"l\">" + link +
           "</td><td class=\"l\">(error)</td><td colspan=\"7\"></td>"
           "<td class=\"l fail\">FAIL</td><td class=\"l\">" +
           escapeHtml(c.error) + "</td></tr>";
    for (const Row& r : c.rows) {
      const Cells x = cellsOf(r);
      const std::string cls = !asserts(r) ? "l" : r.pass ? "l ok" : "l fail";
      b += "<tr><td class=\"l\">" + link + "</td><td class=\"l\">" + escapeHtml(r.variant) + "</td><td>" +
           x.agreement + "</td><td>" + x.genuine + "</td><td" + (r.nanInf ? " class=\"bad\"" : "") + ">" +
           x.nanInf + "</td><td>" + x.acne + "</td><td>" + x.leaks + "</td><td class=\"l\">" +
           escapeHtml(x.metric) + "</td><td>" + x.seconds + "</td><td class=\"" + cls + "\">" +
           resultWord(r) + "</td><td class=\"l\">" + escapeHtml(r.property) + "</td></tr>";
    }
  }
  b += "</table>";
  b += "<p>agree %: the share of compared samples and layers whose (instance, triangle) match the reference; "
       "genuine: mismatching layers no tolerance explains (compare/classify.h). Acne: samples darkened where "
       "double-precision shadow rays say a light reaches them; leaks: samples lit where they say it is "
       "blocked. For shadow maps, disagreements within one map texel of a shadow edge (the maps' resolution, "
       "not their bias) are counted apart, in the property text. Mismatch maps use this legend:</p>" +
       mismatchLegendHtml();

  for (const CaseResult& c : results) {
    b += "<section id=\"" + escapeHtml(c.name) + "\"><h2>" + escapeHtml(c.name) + "</h2><p>" +
         escapeHtml(c.group) + ": " + escapeHtml(c.parameters) + (c.quick ? " (in --quick)" : "") + "</p>";
    if (!c.error.empty()) b += "<p class=\"bad\">" + escapeHtml(c.error) + "</p>";
    for (const Row& r : c.rows) {
      if (r.images.empty()) continue;
      b += "<h3>" + escapeHtml(r.variant) + "</h3><div class=\"row\">";
      for (const auto& [file, caption] : r.images)
        b += "<figure><img class=\"px\" src=\"" + escapeHtml(file) + "\" alt=\"" + escapeHtml(caption) +
             "\"><figcaption>" + escapeHtml(caption) + "</figcaption></figure>";
      b += "</div>";
    }
    b += "</section>";
  }
  writeTextFile((std::filesystem::path(dir) / "index.html").string(), reportPage("rastray stability", b));
}

std::string sceneFamilyReadme(const std::vector<Case>& cases) {
  std::string s =
      "# scenes/stiff: stiff and extreme scenes for `rastray stability`\n\n"
      "Generated, do not edit: every file here is written by the case generators in\n"
      "`app/stability_cases_*.cpp` (deterministic: the same code writes the same bytes).\n"
      "Regenerate with\n\n"
      "```sh\n./build/rastray stability --write-scenes scenes/stiff\n```\n\n"
      "and run the study on these files (rather than freshly generated ones) with\n"
      "`./build/rastray stability --scenes scenes/stiff`. `quick`: part of `--quick`.\n\n"
      "| case | group | quick | parameters |\n|---|---|:-:|---|\n";
  for (const Case& c : cases) {
    std::string parameters;  // a '|' would end the table cell
    for (char ch : c.parameters) parameters += ch == '|' ? std::string("\\|") : std::string(1, ch);
    s += "| [" + c.name + "](" + c.name + ".gltf) | " + c.group + " | " + (c.quick ? "yes" : "") + " | " +
         parameters + " |\n";
  }
  return s;
}

}  // namespace rastray::stability
