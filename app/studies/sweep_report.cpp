#include "app/studies/sweep_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>

#include "app/report/html.h"
#include "common/error.h"
#include "common/image.h"

namespace rastray::sweep {

namespace {

std::string sig3(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

std::string baseName(const std::string& path) { return std::filesystem::path(path).stem().string(); }

// File-name safe: letters, digits, '-' and '.'; anything else becomes '-'.
std::string safe(const std::string& s) {
  std::string out;
  for (const char c : s) out += std::isalnum(static_cast<unsigned char>(c)) || c == '.' ? c : '-';
  return out;
}

std::string settingsText(const SweepMeta& meta, const CellResult& r) {
  std::string out;
  for (size_t a = 0; a < meta.spec.vary.size() && a < r.values.size(); ++a)
    out += (a ? ", " : "") + meta.spec.vary[a].name + " " + r.values[a];
  return out.empty() ? r.args : out;
}

double time(const CellResult& r) { return r.time.median; }

// Whole decades around the positive values, at least a tenth of a decade
// beyond the extreme points, so no point or label sits on the frame. Left
// to the plot (NaN) when no value is positive.
void decadeRange(const std::vector<PlotPoint>& points, bool x, PlotAxis& axis) {
  double lo = HUGE_VAL, hi = 0;
  for (const PlotPoint& p : points) {
    const double v = x ? p.x : p.y;
    if (v > 0 && std::isfinite(v)) {
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  }
  if (hi <= 0) return;
  axis.min = std::pow(10.0, std::floor(std::log10(lo) - 0.1));
  axis.max = std::pow(10.0, std::ceil(std::log10(hi) + 0.1));
}

}  // namespace

const std::vector<ErrorMetric>& errorMetrics() {
  static const std::vector<ErrorMetric> metrics = {
      {"visibility", "visibility error", "visibility disagreement (share of pixel centres)", "",
       [](const CellResult& r) { return r.errors.visibility; }},
      {"rms", "RMS colour error", "RMS colour error (linear RGBA)", "",
       [](const CellResult& r) { return r.errors.rms; }},
      {"perceptual", "perceptual error", "perceptual error (share of pixels, Yee)", "",
       [](const CellResult& r) { return r.errors.perceptual; }},
      {"depth", "depth error", "max relative depth error (where IDs agree)", "",
       [](const CellResult& r) { return r.errors.depthMaxRel; }},
  };
  return metrics;
}

std::vector<SweepPlot> sweepPlots(const SweepMeta& meta, const std::vector<CellResult>& rows) {
  std::vector<SweepPlot> plots;
  const std::vector<VaryAxis>& vary = meta.spec.vary;
  for (const std::string& scene : meta.spec.scenes) {
    std::vector<const CellResult*> cells;
    for (const CellResult& r : rows)
      if (r.scene == scene) cells.push_back(&r);
    if (cells.empty()) continue;
    for (const ErrorMetric& metric : errorMetrics()) {
      // The Pareto front over every cell of the scene, shared by each grouping.
      std::vector<PlotPoint> all;
      for (const CellResult* r : cells) all.push_back({time(*r), metric.of(*r), settingsText(meta, *r), ""});
      PlotSeries front{"Pareto front", {}, PlotLine::Step};
      front.highlight = true;
      front.markers = false;
      front.colour = int(plotPalette().size()) - 1;  // black
      // Each cell on the front is labelled with its settings, so the plot
      // alone says which setting to pick for a given time budget; a label
      // that would overprint the previous one (closer than about a label's
      // width and height, in decades) is left to the tooltip.
      double lastX = -1e300, lastY = -1e300;
      for (const size_t i : paretoFront(all)) {
        PlotPoint p = all[i];
        const double lx = p.x > 0 ? std::log10(p.x) : -1e300, ly = p.y > 0 ? std::log10(p.y) : -1e300;
        if (std::fabs(lx - lastX) > 0.35 || std::fabs(ly - lastY) > 0.12) {
          for (const std::string& v : cells[i]->values)
            if (v != "n/a") p.text += (p.text.empty() ? "" : " ") + v;
          lastX = lx;
          lastY = ly;
        }
        front.points.push_back(p);
      }

      const size_t groupings = std::max<size_t>(vary.size(), 1);
      for (size_t a = 0; a < groupings; ++a) {
        Plot plot;
        plot.title = baseName(scene) + ": " + metric.name + " against time";
        plot.x = {"render time (BVH build + frame, median)", "s", AxisScale::Log};
        plot.y = {metric.quantity, metric.unit, AxisScale::Log};
        decadeRange(all, true, plot.x);
        decadeRange(all, false, plot.y);
        std::string by = "cells";
        if (!vary.empty()) {
          by = vary[a].name;
          plot.title += ", by " + by;
          // One series per value of this option (n/a: the cells it does not apply to).
          std::vector<std::string> values = vary[a].values;
          values.push_back("n/a");
          // Joined along the other option when exactly two vary.
          const bool join = vary.size() == 2;
          const size_t other = 1 - a;
          for (const std::string& value : values) {
            PlotSeries s{vary[a].name + " " + value, {}, join ? PlotLine::Straight : PlotLine::None};
            std::vector<std::pair<size_t, PlotPoint>> points;
            for (const CellResult* r : cells) {
              if (r->values[a] != value) continue;
              size_t order = 0;
              if (join) {
                const auto& ov = vary[other].values;
                order = size_t(std::find(ov.begin(), ov.end(), r->values[other]) - ov.begin());
              }
              points.push_back({order, {time(*r), metric.of(*r), settingsText(meta, *r), ""}});
            }
            if (points.empty()) continue;
            std::stable_sort(points.begin(), points.end(),
                             [](const auto& p, const auto& q) { return p.first < q.first; });
            for (auto& p : points) s.points.push_back(p.second);
            plot.series.push_back(std::move(s));
          }
        } else {
          PlotSeries s{"cells", {}, PlotLine::None};
          s.points = all;
          plot.series.push_back(std::move(s));
        }
        plot.series.push_back(front);
        plots.push_back(
            {safe(baseName(scene)) + "-" + metric.key + "-by-" + safe(by) + ".svg", std::move(plot)});
      }
    }
  }
  return plots;
}

void writeSweepReport(const std::string& dir, const SweepMeta& meta, const std::vector<CellResult>& rows) {
  std::error_code ec;
  std::filesystem::create_directories(std::filesystem::path(dir) / "plots", ec);
  if (ec) throw InputError(dir, "", "cannot create the report folder: " + ec.message());

  std::string body = "<h1>rastray sweep</h1>\n<pre>";
  body += escapeHtml(describe(meta.spec));
  body += "</pre>\n<p>Reference: " + escapeHtml(meta.reference) + ". Cells: " + std::to_string(rows.size()) +
          " of " + std::to_string(meta.cells) + " (" + escapeHtml(meta.shard) + "), each rendered " +
          std::to_string(meta.spec.repeat) + " times. Fingerprint " + escapeHtml(meta.fingerprint) +
          ".</p>\n";
  body +=
      "<p>How to read the plots: each point is one cell; further left is faster, lower is more accurate. "
      "The black step line is the Pareto front: the cells no other cell beats in both time and error. A "
      "setting worth its cost moves a point down more than it moves it right. Errors of exactly 0 (the "
      "reference's own setting) cannot be drawn on a log axis and are counted under the plot.</p>\n";

  const std::vector<SweepPlot> plots = sweepPlots(meta, rows);
  std::map<std::string, std::string> svgs;
  for (const SweepPlot& p : plots) {
    const PlotRender rendered = renderPlot(p.plot);
    writeTextFile((std::filesystem::path(dir) / "plots" / p.file).string(), rendered.svg);
    body += "<figure>" + rendered.svg + "<figcaption><a href=\"plots/" + escapeHtml(p.file) + "\">" +
            escapeHtml(p.file) + "</a></figcaption></figure>\n";
  }

  // Which cells lie on the time/error Pareto front of their scene, per error.
  std::map<size_t, std::string> onFront;
  for (const std::string& scene : meta.spec.scenes)
    for (const ErrorMetric& metric : errorMetrics()) {
      std::vector<PlotPoint> points;
      std::vector<size_t> index;
      for (const CellResult& r : rows)
        if (r.scene == scene) {
          points.push_back({time(r), metric.of(r), "", ""});
          index.push_back(r.index);
        }
      for (const size_t i : paretoFront(points))
        onFront[index[i]] += std::string(onFront[index[i]].empty() ? "" : " ") + metric.key;
    }

  body += "<h2>Cells</h2>\n<table>\n<tr><th>cell</th><th>scene</th>";
  for (const VaryAxis& v : meta.spec.vary) body += "<th>" + escapeHtml(v.name) + "</th>";
  body +=
      "<th>size</th><th>time ms<br>median</th><th>min–max ms</th><th>build ms</th><th>load ms</th>"
      "<th>RMS</th><th>max</th><th>Yee %</th><th>visibility %</th><th>shared-edge ties %</th><th>max rel. "
      "Z</th><th>Pareto front "
      "of</th><th>options</th></tr>\n";
  const auto ms = [](double s) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.2f", s * 1e3);
    return std::string(buf);
  };
  for (const CellResult& r : rows) {
    body += "<tr><td>" + std::to_string(r.index) + "</td><td>" + escapeHtml(baseName(r.scene)) + "</td>";
    for (const std::string& v : r.values) body += "<td>" + escapeHtml(v) + "</td>";
    body += "<td>" + std::to_string(r.width) + "×" + std::to_string(r.height) + "</td><td>" +
            ms(r.time.median) + "</td><td>" + ms(r.time.min) + "–" + ms(r.time.max) + "</td><td>" +
            ms(r.build.median) + "</td><td>" + ms(r.load.median) + "</td><td>" + sig3(r.errors.rms) +
            "</td><td>" + sig3(r.errors.max) + "</td><td>" + sig3(100.0 * r.errors.perceptual) + "</td><td>" +
            sig3(100.0 * r.errors.visibility) + "</td><td>" + sig3(100.0 * r.errors.visibilitySharedEdge) +
            "</td><td>" + sig3(r.errors.depthMaxRel) + "</td><td>" + escapeHtml(onFront[r.index]) +
            "</td><td><code>" + escapeHtml(r.args) + "</code></td></tr>\n";
  }
  body +=
      "</table>\n<p>Data: <a href=\"sweep.csv\">sweep.csv</a>, <a href=\"sweep.json\">sweep.json</a>.</p>\n";
  writeTextFile((std::filesystem::path(dir) / "index.html").string(), reportPage("rastray sweep", body));
}

}  // namespace rastray::sweep
