#include "app/report/html.h"

#include "app/report/svg_plot.h"
#include "compare/maps.h"

namespace rastray {

// XML escaping (app/report/svg_plot.h) is valid HTML text and attribute escaping.
std::string escapeHtml(const std::string& s) { return escapeXml(s); }

// One page style for every page: no external resources.
const char* const kStyle = R"(<style>
body{font-family:system-ui,-apple-system,"Segoe UI",sans-serif;margin:24px;color:#1d1d1f;background:#fafafa}
h1{font-size:22px}h2{font-size:18px;margin-top:28px}h3{font-size:15px}
table{border-collapse:collapse;margin:8px 0;font-size:13px}
th,td{border:1px solid #ccc;padding:3px 8px;text-align:right}th{background:#eee}td.l,th.l{text-align:left}
.row{display:flex;flex-wrap:wrap;gap:16px;align-items:flex-start}
figure{margin:0;background:#fff;border:1px solid #ddd;padding:8px}
figcaption{font-size:13px;margin-top:6px;max-width:512px}
img.px{image-rendering:pixelated;display:block;background:repeating-conic-gradient(#ddd 0% 25%,#fff 0% 50%) 50%/16px 16px}
.bar{height:14px;width:256px;border:1px solid #888}
.barlabels{display:flex;justify-content:space-between;width:258px;font-size:12px}
.swatch{display:inline-block;width:14px;height:14px;border:1px solid #888;vertical-align:middle;margin-right:4px}
.bad{color:#b00020;font-weight:600}.good{color:#0a7a2f}
code,pre{font-size:12px}pre{background:#fff;border:1px solid #ddd;padding:8px;overflow-x:auto}
</style>)";

std::string reportPage(const std::string& title, const std::string& body) {
  return "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>" + escapeHtml(title) +
         "</title>" + kStyle + "</head><body>\n" + body + "\n</body></html>\n";
}

std::string mismatchLegendHtml() {
  std::string s;
  for (const LegendEntry& e : mismatchLegend())
    s += "<div><span class=\"swatch\" style=\"background:" + cssColor(e.srgb) + "\"></span>" +
         escapeHtml(e.label) + "</div>";
  return s;
}

}  // namespace rastray
