#include "app/crossval/crossval_report.h"

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "app/report/html.h"
#include "app/report/svg_plot.h"
#include "common/error.h"
#include "common/image.h"
#include "compare/maps.h"

namespace rastray {

namespace {

std::string fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

std::string percent(double fraction) { return fmt("%.4f %%", 100.0 * fraction); }

}  // namespace

namespace {

// Images are shown at a display size that keeps small renders visible.
std::string figure(const std::string& src, const std::string& caption, int width, int height) {
  const int scale = width < 256 ? (256 + width - 1) / width : 1;
  return "<figure><img class=\"px\" src=\"" + src + "\" width=\"" + std::to_string(width * scale) +
         "\" height=\"" + std::to_string(height * scale) + "\" alt=\"" + escapeHtml(caption) +
         "\"><figcaption>" + caption + "</figcaption></figure>\n";
}

std::string colorBarHtml(const ColorBar& bar) {
  return "<div class=\"bar\" style=\"background:" + bar.cssGradient() +
         "\"></div><div class=\"barlabels\"><span>" + fmt("%.3g", bar.lo) + "</span><span>" +
         escapeHtml(bar.quantity) + "</span><span>" + fmt("%.3g", bar.hi) + "</span></div>";
}

std::string countersTable(const CrossvalResult& r) {
  // One row per counter name, one column per renderer.
  std::vector<std::string> names;
  for (const RenderRun* run : {&r.raster, &r.raytrace, &r.hybrid})
    for (const auto& [name, value] : run->output.counters.values)
      if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
  std::string s =
      "<table><tr><th class=\"l\">counter</th><th>raster</th><th>raytrace</th><th>hybrid</th></tr>";
  for (const std::string& name : names) {
    s += "<tr><td class=\"l\">" + escapeHtml(name) + "</td>";
    for (const RenderRun* run : {&r.raster, &r.raytrace, &r.hybrid}) {
      bool present = false;
      for (const auto& [n, v] : run->output.counters.values) present |= n == name;
      s += "<td>" + (present ? std::to_string(run->output.counters.get(name)) : std::string("&ndash;")) +
           "</td>";
    }
    s += "</tr>";
  }
  return s + "</table>";
}

std::string passesHtml(const char* renderer, const RenderRun& run) {
  std::string s = "<h3>" + std::string(renderer) + "</h3><div>ran:</div><ul>";
  for (const std::string& p : run.output.passesRun) s += "<li>" + escapeHtml(p) + "</li>";
  s += "</ul><div>left out (SPEC 8):</div><ul>";
  for (const std::string& p : run.output.passesLeftOut) s += "<li>" + escapeHtml(p) + "</li>";
  return s + "</ul>";
}

std::string visibilityTable(const VisibilityReport& v, const char* a, const char* b) {
  std::string s = "<table><tr><th class=\"l\">" + std::string(a) + " vs " + b +
                  "</th><th>count</th><th>fraction</th></tr>";
  auto row = [&](const std::string& label, uint64_t n, double f, bool bad = false) {
    s += "<tr><td class=\"l\">" + escapeHtml(label) + "</td><td" + (bad && n ? " class=\"bad\"" : "") + ">" +
         std::to_string(n) + "</td><td>" + percent(f) + "</td></tr>";
  };
  row("samples compared", v.samples.compared, 1.0);
  row("samples agreeing", v.samples.agreeing, v.samples.agreement());
  row("layers compared", v.layers.compared, 1.0);
  row("layers agreeing", v.layers.agreeing, v.layers.agreement());
  for (int c = 0; c < kMismatchClassCount; ++c)
    row(std::string("mismatch: ") + displayName(MismatchClass(c)), v.layers.count(MismatchClass(c)),
        v.layers.fraction(MismatchClass(c)), MismatchClass(c) == MismatchClass::Genuine);
  row("cut off (not compared)", v.layers.cutOff,
      v.layers.compared ? double(v.layers.cutOff) / double(v.layers.compared + v.layers.cutOff) : 0.0);
  s += "</table>";
  if (v.layers.cutOff)
    s += "<div>colour of the cut-off layers in the renderer that reached them: mean " +
         fmt("%.3g", v.cutOff.meanColor) + " per pixel, max " + fmt("%.3g", v.cutOff.maxColor) + " at (" +
         std::to_string(v.cutOff.maxX) + ", " + std::to_string(v.cutOff.maxY) + "), " +
         std::to_string(v.cutOff.samples) + " samples</div>";
  s += "<div>depth error on agreeing hits: mean " + fmt("%.3g", v.depth.meanAbsolute) + ", max " +
       fmt("%.3g", v.depth.maxAbsolute) + " (relative mean " + fmt("%.3g", v.depth.meanRelative) + ", max " +
       fmt("%.3g", v.depth.maxRelative) + ") over " + std::to_string(v.depth.count) + " hits</div>";
  return s;
}

std::string colorTable(const ColorMetrics& m, const AgreeingColorStats& agree, const char* a, const char* b) {
  std::string s =
      "<table><tr><th class=\"l\">" + std::string(a) + " vs " + b + " colour</th><th>value</th></tr>";
  auto row = [&](const std::string& k, const std::string& v) {
    s += "<tr><td class=\"l\">" + k + "</td><td>" + v + "</td></tr>";
  };
  row("mean |error|", fmt("%.3g", m.meanError));
  row("RMS error", fmt("%.3g", m.rmsError));
  row("PSNR", std::isinf(m.psnr) ? "&infin;" : fmt("%.2f dB", m.psnr));
  row("max error",
      fmt("%.3g", m.maxError) + " at (" + std::to_string(m.maxX) + ", " + std::to_string(m.maxY) + ")");
  row("pixels differing", std::to_string(m.differingPixels) + " of " + std::to_string(m.pixels));
  row("perceptibly different (Yee)", std::to_string(m.yeeFailingPixels));
  row("max |error| where hits agree",
      fmt("%.3g", agree.maxError) + " over " + std::to_string(agree.layers) + " layers");
  return s + "</table>";
}

std::string sceneName(const std::string& scenePath) {
  return std::filesystem::path(scenePath).stem().string();
}

void createFolder(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw InputError(dir, "", "cannot create the folder: " + ec.message());
}

}  // namespace

void writeCrossvalScenePage(const std::string& reportDir, const CrossvalResult& r,
                            const std::vector<ReportExplanation>& explain) {
  const std::string dir = reportDir + "/" + sceneName(r.scenePath);
  createFolder(dir);
  const int w = r.camera.width, h = r.camera.height;
  writePng(dir + "/raster.png", r.raster.output.image);
  writePng(dir + "/raytrace.png", r.raytrace.output.image);
  writePng(dir + "/hybrid.png", r.hybrid.output.image);
  writeMismatchMap(dir + "/mismatch.png", r.rasterVsRay);
  writeMismatchMap(dir + "/mismatch-hybrid.png", r.hybridVsRay);
  const ColorBar zBar = writeDepthDifferenceMap(dir + "/depth-diff.png", r.rasterVsRay);
  const ColorBar cBar =
      writeDifferenceHeatMap(dir + "/color-diff.png", r.raster.output.image, r.raytrace.output.image);
  const ColorBar hBar =
      writeDifferenceHeatMap(dir + "/color-diff-hybrid.png", r.hybrid.output.image, r.raytrace.output.image);

  std::string b =
      "<p><a href=\"../index.html\">&larr; all scenes</a></p><h1>" + escapeHtml(r.scenePath) + "</h1>";
  b += "<p>" + std::to_string(w) + "&times;" + std::to_string(h) + ", " + escapeHtml(r.camera.describe()) +
       "</p>";
  b += "<h2>Renders</h2><div class=\"row\">" +
       figure("raster.png", "rasterizer (" + fmt("%.3f s", r.raster.seconds) + ")", w, h) +
       figure("raytrace.png", "ray caster (" + fmt("%.3f s", r.raytrace.seconds) + ")", w, h) +
       figure("hybrid.png",
              "hybrid: rasterized visibility, traced rays (" + fmt("%.3f s", r.hybrid.seconds) + ")", w, h) +
       "</div>";
  b += "<h2>Where visibility differs</h2><div class=\"row\">" +
       figure("mismatch.png", "rasterizer vs ray caster, each pixel's most severe class", w, h) +
       figure("mismatch-hybrid.png", "hybrid vs ray caster", w, h) + "<figure>" + mismatchLegendHtml() +
       "</figure></div>";
  b += visibilityTable(r.rasterVsRay, "raster", "raytrace");
  b += visibilityTable(r.hybridVsRay, "hybrid", "raytrace");
  if (!explain.empty()) {
    b += "<h3>Why: one example pixel per mismatch class</h3><ul>";
    for (const ReportExplanation& e : explain) {
      const auto& ex = r.rasterVsRay.examples;
      std::string where;
      for (int c = 0; c < kMismatchClassCount; ++c)
        if (toString(MismatchClass(c)) == e.key && ex[size_t(c)])
          where = " at pixel (" + std::to_string(ex[size_t(c)]->x) + ", " + std::to_string(ex[size_t(c)]->y) +
                  "), sample " + std::to_string(ex[size_t(c)]->sample);
      b += "<li><a href=\"" + escapeHtml(e.file) + "\">" + escapeHtml(e.key) + "</a>" + where + "</li>";
    }
    b += "</ul>";
  }
  b += "<h2>Depth and colour differences</h2><div class=\"row\">";
  b += "<figure><img class=\"px\" src=\"depth-diff.png\" width=\"" + std::to_string(w < 256 ? 256 : w) +
       "\" alt=\"depth difference\"><figcaption>|&Delta;Z| where raster and ray caster agree</figcaption>" +
       colorBarHtml(zBar) + "</figure>";
  b += "<figure><img class=\"px\" src=\"color-diff.png\" width=\"" + std::to_string(w < 256 ? 256 : w) +
       "\" alt=\"colour difference\"><figcaption>raster vs ray caster, max |&Delta;| over RGBA</figcaption>" +
       colorBarHtml(cBar) + "</figure>";
  b += "<figure><img class=\"px\" src=\"color-diff-hybrid.png\" width=\"" +
       std::to_string(w < 256 ? 256 : w) +
       "\" alt=\"hybrid colour difference\"><figcaption>hybrid vs ray caster</figcaption>" +
       colorBarHtml(hBar) + "</figure></div>";
  b += colorTable(r.rasterVsRayColor, r.rasterWhereAgree, "raster", "raytrace");
  b += colorTable(r.hybridVsRayColor, r.hybridWhereAgree, "hybrid", "raytrace");
  b += "<h2>Work counters</h2>" + countersTable(r);
  b += "<h2>Passes</h2><div class=\"row\"><div>" + passesHtml("raster", r.raster) + "</div><div>" +
       passesHtml("raytrace", r.raytrace) + "</div><div>" + passesHtml("hybrid", r.hybrid) + "</div></div>";
  b += "<h2>Timings</h2><table><tr><th class=\"l\">renderer</th><th>seconds</th></tr>";
  for (const auto& [name, run] : {std::pair<const char*, const RenderRun*>{"raster", &r.raster},
                                  {"raytrace", &r.raytrace},
                                  {"hybrid", &r.hybrid}}) {
    b += "<tr><td class=\"l\">" + std::string(name) + "</td><td>" + fmt("%.4f", run->seconds) + "</td></tr>";
    for (const auto& [stage, t] : run->output.timings)
      b += "<tr><td class=\"l\">&nbsp;&nbsp;" + escapeHtml(stage) + "</td><td>" + fmt("%.4f", t) +
           "</td></tr>";
  }
  b += "</table>";
  writeTextFile(dir + "/index.html", reportPage(sceneName(r.scenePath) + " - rastray crossval", b));
}

void writeCrossvalIndex(const std::string& dir, const std::vector<CrossvalSummary>& results,
                        const RenderSettings& settings) {
  createFolder(dir);

  std::string b =
      "<h1>rastray cross-validation</h1><p>Each scene rendered by the rasterizer, the Embree ray caster "
      "and hybrid (rasterized visibility, traced secondary rays) with identical camera, samples and "
      "shading, then compared sample by sample and layer by layer.</p>";
  b += "<p>" + std::to_string(settings.spp) + " spp, rasterizer depth format " +
       escapeHtml(optionText(settings, "--depth-format")) + ", transparency " +
       escapeHtml(optionText(settings, "--transparency")) + ".</p>";
  b += "<table><tr><th class=\"l\">scene</th><th>size</th><th>samples</th><th>layers</th><th>agree</th>";
  for (int c = 0; c < kMismatchClassCount; ++c)
    b += "<th>" + std::string(displayName(MismatchClass(c))) + "</th>";
  b += "<th>cut off</th><th>max rel &Delta;Z</th><th>RMS</th><th>PSNR</th><th>hybrid &Delta; where hits "
       "agree</th>"
       "<th>raster s</th><th>raytrace s</th><th>hybrid s</th></tr>";
  for (const CrossvalSummary& r : results) {
    const std::string name = sceneName(r.scenePath);
    const VisibilityReport& v = r.rasterVsRay;
    b += "<tr><td class=\"l\"><a href=\"" + escapeHtml(name) + "/index.html\">" + escapeHtml(name) +
         "</a></td><td>" + std::to_string(r.width) + "&times;" + std::to_string(r.height) + "</td><td>" +
         std::to_string(v.samples.compared) + "</td><td>" + std::to_string(v.layers.compared) + "</td><td>" +
         percent(v.layers.agreement()) + "</td>";
    for (int c = 0; c < kMismatchClassCount; ++c) {
      const uint64_t n = v.layers.count(MismatchClass(c));
      const bool bad = MismatchClass(c) == MismatchClass::Genuine && n > 0;
      b += std::string("<td") + (bad ? " class=\"bad\"" : "") + ">" + std::to_string(n) + "</td>";
    }
    b += "<td>" + std::to_string(v.layers.cutOff) + "</td>";
    b += "<td>" + fmt("%.3g", v.depth.maxRelative) + "</td><td>" + fmt("%.3g", r.rasterVsRayColor.rmsError) +
         "</td><td>" +
         (std::isinf(r.rasterVsRayColor.psnr) ? "&infin;" : fmt("%.1f", r.rasterVsRayColor.psnr)) +
         "</td><td>" + fmt("%.3g", r.hybridWhereAgree.maxError) + "</td><td>" + fmt("%.3f", r.rasterSeconds) +
         "</td><td>" + fmt("%.3f", r.raytraceSeconds) + "</td><td>" + fmt("%.3f", r.hybridSeconds) +
         "</td></tr>";
  }
  b += "</table><h2>Mismatch classes</h2>" + mismatchLegendHtml();
  b += "<p>Shared-edge tie: both renderers hit triangles of one instance that share an edge, at a sample "
       "within "
       "the edge distance of it (SPEC 3 lets either win). Depth tie: |&Delta;Z| within the depth format's "
       "resolution (z-fighting). Near/far plane: a hit at or beyond a clipping plane. Silhouette edge: the "
       "sample "
       "lies within the edge distance of an edge of either triangle. Genuine: none of these. Cut off: "
       "layers behind the point where one renderer declared it stopped looking (a transmittance cut-off "
       "or a layer limit); they are counted apart, neither agreement nor mismatch, with their share of "
       "the colour.</p>";
  writeTextFile(dir + "/index.html", reportPage("rastray crossval", b));
}

}  // namespace rastray
