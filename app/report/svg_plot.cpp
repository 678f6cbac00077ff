#include "app/report/svg_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <string>
#include <vector>

namespace rastray {

namespace {

constexpr int kMarkerShapes = 7;

bool finite(double v) { return std::isfinite(v); }

// Coordinates are written with 2 decimals (1/100 px: far below what a screen
// shows); callers only pass finite values.
std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", v);
  std::string s = buf;
  if (s == "-0.00") s = "0.00";
  return s;
}

// Text width estimate for layout (sans-serif averages ~0.55 em per glyph;
// UTF-8 continuation bytes are not glyphs).
double textWidth(const std::string& s, double fontSize) {
  std::size_t glyphs = 0;
  for (unsigned char c : s)
    if ((c & 0xC0) != 0x80) ++glyphs;
  return 0.55 * fontSize * static_cast<double>(glyphs);
}

// A linear tick label: enough decimals to tell neighbouring ticks apart,
// scientific form for very large or small magnitudes.
std::string linearLabel(double v, double step) {
  if (std::fabs(v) < step * 1e-9) v = 0;  // a sum of steps that should be 0
  char buf[48];
  const double mag = std::max(std::fabs(v), step);
  if (mag >= 1e6 || step < 1e-4) {
    const int digits = std::max(0, static_cast<int>(std::ceil(std::log10(mag / step) - 1e-9)));
    std::snprintf(buf, sizeof buf, "%.*e", std::min(digits, 6), v);
    // "2.50e+06" -> "2.50e6": the exponent without sign padding.
    std::string s = buf;
    const std::size_t e = s.find('e');
    if (e != std::string::npos) {
      std::string mant = s.substr(0, e), ex = s.substr(e + 1);
      const bool negative = ex[0] == '-';
      ex = ex.substr(1);
      ex.erase(0, std::min(ex.find_first_not_of('0'), ex.size() - 1));
      s = mant + "e" + (negative ? "-" : "") + ex;
    }
    return s;
  }
  const int decimals = std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

double niceStep(double span, int target) {
  const double raw = span / std::max(1, target);
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  const double f = raw / p;
  const double nice = f < 1.5 ? 1 : f < 3 ? 2 : f < 7 ? 5 : 10;
  return nice * p;
}

AxisTicks linearTicks(double lo, double hi, int target) {
  if (lo == hi) {
    const double pad = lo == 0 ? 1 : std::fabs(lo) * 0.1;
    lo -= pad;
    hi += pad;
  }
  AxisTicks t;
  double step = niceStep(hi - lo, target);
  if (!finite(step) || step <= 0) {  // span overflowed or underflowed
    t.lo = lo;
    t.hi = hi;
    return t;
  }
  const double first = std::floor(lo / step), last = std::ceil(hi / step);
  t.lo = first * step;
  t.hi = last * step;
  for (double k = first; k <= last + 0.5; k += 1) {
    const double v = k * step;
    t.major.push_back(v);
    t.labels.push_back(linearLabel(v, step));
  }
  return t;
}

AxisTicks logTicks(double lo, double hi) {
  int k0 = static_cast<int>(std::floor(std::log10(lo) + 1e-12));
  int k1 = static_cast<int>(std::ceil(std::log10(hi) - 1e-12));
  if (k1 <= k0) k1 = k0 + 1;
  AxisTicks t;
  t.lo = std::pow(10.0, k0);
  t.hi = std::pow(10.0, k1);
  const int decades = k1 - k0;
  // At most ~10 labels: label every n-th decade, starting from a multiple of n.
  const int every = (decades + 9) / 10;
  for (int k = k0; k <= k1; ++k) {
    if (((k % every) + every) % every != 0) continue;
    t.major.push_back(std::pow(10.0, k));
    t.labels.push_back("10^" + std::to_string(k));
  }
  if (decades <= 12)
    for (int k = k0; k < k1; ++k)
      for (int m = 2; m <= 9; ++m) t.minor.push_back(m * std::pow(10.0, k));
  return t;
}

// One axis' range from its data (values the axis can place) or its fixed
// limits.
struct Range {
  bool ok = false;
  double lo = 0, hi = 0;
};

Range dataRange(const Plot& plot, const PlotAxis& axis, bool isX) {
  Range r;
  r.lo = std::numeric_limits<double>::infinity();
  r.hi = -r.lo;
  for (const PlotSeries& s : plot.series)
    for (const PlotPoint& p : s.points) {
      const double v = isX ? p.x : p.y;
      if (!finite(v) || (axis.scale == AxisScale::Log && v <= 0)) continue;
      r.lo = std::min(r.lo, v);
      r.hi = std::max(r.hi, v);
    }
  if (finite(axis.min)) r.lo = axis.min;
  if (finite(axis.max)) r.hi = axis.max;
  r.ok = finite(r.lo) && finite(r.hi) && r.lo <= r.hi && (axis.scale == AxisScale::Linear || r.lo > 0) &&
         finite(r.hi - r.lo);
  if (!r.ok) {  // nothing to draw on this axis: a unit range keeps the frame
    r.lo = axis.scale == AxisScale::Log ? 1 : 0;
    r.hi = 10;
  }
  return r;
}

// A fixed limit is kept as given; a data-driven one widens to the ticks.
AxisTicks axisTicks(const PlotAxis& axis, const Range& r) {
  AxisTicks t = niceTicks(r.lo, r.hi, axis.scale);
  const bool fixedLo = finite(axis.min), fixedHi = finite(axis.max);
  if (fixedLo || fixedHi) {
    if (fixedLo) t.lo = axis.min;
    if (fixedHi) t.hi = axis.max;
    std::vector<double> major;
    std::vector<std::string> labels;
    for (std::size_t i = 0; i < t.major.size(); ++i)
      if (t.major[i] >= t.lo * (1 - 1e-12) && t.major[i] <= t.hi * (1 + 1e-12)) {
        major.push_back(t.major[i]);
        labels.push_back(t.labels[i]);
      }
    t.major = major;
    t.labels = labels;
    t.minor.erase(
        std::remove_if(t.minor.begin(), t.minor.end(), [&](double v) { return v < t.lo || v > t.hi; }),
        t.minor.end());
  }
  return t;
}

// A tick label as SVG text content: "10^k" becomes 10 with a superscript k
// (written with a true minus sign).
std::string labelSvg(const std::string& label, AxisScale scale) {
  if (scale == AxisScale::Log && label.rfind("10^", 0) == 0) {
    std::string e = label.substr(3);
    if (!e.empty() && e[0] == '-') e = "\xE2\x88\x92" + e.substr(1);
    return "10<tspan dy=\"-0.45em\" font-size=\"75%\">" + escapeXml(e) + "</tspan>";
  }
  return escapeXml(label);
}

// Marker `shape` of radius r centred at (x, y), as an SVG element.
std::string markerSvg(int shape, double x, double y, double r, const std::string& paint) {
  const std::string cx = num(x), cy = num(y);
  switch (shape % kMarkerShapes) {
    case 0:
      return "<circle cx=\"" + cx + "\" cy=\"" + cy + "\" r=\"" + num(r) + "\" " + paint + "/>";
    case 1:
      return "<rect x=\"" + num(x - r * 0.9) + "\" y=\"" + num(y - r * 0.9) + "\" width=\"" + num(1.8 * r) +
             "\" height=\"" + num(1.8 * r) + "\" " + paint + "/>";
    case 2:
      return "<path d=\"M" + num(x) + " " + num(y - 1.2 * r) + "L" + num(x + 1.1 * r) + " " +
             num(y + 0.8 * r) + "L" + num(x - 1.1 * r) + " " + num(y + 0.8 * r) + "Z\" " + paint + "/>";
    case 3:
      return "<path d=\"M" + num(x) + " " + num(y - 1.3 * r) + "L" + num(x + 1.1 * r) + " " + cy + "L" +
             num(x) + " " + num(y + 1.3 * r) + "L" + num(x - 1.1 * r) + " " + cy + "Z\" " + paint + "/>";
    case 4:
      return "<path d=\"M" + num(x) + " " + num(y + 1.2 * r) + "L" + num(x + 1.1 * r) + " " +
             num(y - 0.8 * r) + "L" + num(x - 1.1 * r) + " " + num(y - 0.8 * r) + "Z\" " + paint + "/>";
    case 5:
      return "<path d=\"M" + num(x - r) + " " + num(y - r) + "L" + num(x + r) + " " + num(y + r) + "M" +
             num(x - r) + " " + num(y + r) + "L" + num(x + r) + " " + num(y - r) + "\" " + paint + "/>";
    default:
      return "<path d=\"M" + num(x - 1.2 * r) + " " + cy + "L" + num(x + 1.2 * r) + " " + cy + "M" + cx +
             " " + num(y - 1.2 * r) + "L" + cx + " " + num(y + 1.2 * r) + "\" " + paint + "/>";
  }
}

// Crosses and pluses are strokes only; the other shapes are filled.
bool strokedShape(int shape) { return shape % kMarkerShapes >= 5; }

}  // namespace

std::string axisTitle(const PlotAxis& axis) {
  return axis.unit.empty() ? axis.quantity : axis.quantity + " (" + axis.unit + ")";
}

const std::vector<std::string>& plotPalette() {
  static const std::vector<std::string> palette = {"#0072B2", "#D55E00", "#009E73", "#CC79A7",
                                                   "#E69F00", "#56B4E9", "#000000"};
  return palette;
}

AxisTicks niceTicks(double lo, double hi, AxisScale scale, int target) {
  if (hi < lo) std::swap(lo, hi);
  return scale == AxisScale::Log ? logTicks(lo, hi) : linearTicks(lo, hi, target);
}

bool AxisMap::drawable(double v) const {
  if (!finite(v)) return false;
  if (scale == AxisScale::Log && v <= 0) return false;
  // A relative slack of 1e-9 keeps values the ticks rounded onto the edge.
  const double slack = 1e-9 * std::max(std::fabs(lo), std::fabs(hi));
  return v >= lo - slack && v <= hi + slack;
}

double AxisMap::operator()(double v) const {
  double t;
  if (scale == AxisScale::Log)
    t = (std::log10(v) - std::log10(lo)) / (std::log10(hi) - std::log10(lo));
  else
    t = (v / 2 - lo / 2) / (hi / 2 - lo / 2);  // halves: hi - lo may overflow
  t = std::clamp(t, 0.0, 1.0);
  return from + t * (to - from);
}

std::string escapeXml(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  for (char c : s) {
    const unsigned char u = static_cast<unsigned char>(c);
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        if (u < 0x20 && c != '\t' && c != '\n') break;
        if (u == 0x7F) break;
        out += c;
    }
  }
  return out;
}

std::vector<std::size_t> paretoFront(const std::vector<PlotPoint>& points) {
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (finite(points[i].x) && finite(points[i].y)) order.push_back(i);
  // By x, then y; stable so that of equal points the first comes first.
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return points[a].x < points[b].x || (points[a].x == points[b].x && points[a].y < points[b].y);
  });
  std::vector<std::size_t> front;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i : order)
    if (points[i].y < best) {  // strictly better than every faster point
      front.push_back(i);
      best = points[i].y;
    }
  return front;
}

namespace {

// The frame of one plot: sizes, the plot area, ticks and the data→SVG maps.
struct PlotFrame {
  double font = 13, small = 11;
  double ax0 = 0, ax1 = 0, ay0 = 0, ay1 = 0, width = 0, height = 0;
  AxisTicks tx, ty;
  AxisMap mx, my;
};

// Grid, plot area, ticks, tick labels and axis titles.
void appendAxes(std::string& s, const Plot& plot, const PlotFrame& f) {
  const double font = f.font, small = f.small;
  const double ax0 = f.ax0, ax1 = f.ax1, ay0 = f.ay0, ay1 = f.ay1;
  const AxisTicks &tx = f.tx, &ty = f.ty;
  const AxisMap &mx = f.mx, &my = f.my;
  // Grid and ticks: minor ticks light, major ticks with a grid line and label.
  s += "<g class=\"grid\" stroke=\"#e4e4e4\" stroke-width=\"1\">\n";
  for (double v : tx.major)
    if (mx.drawable(v))
      s += "<line x1=\"" + num(mx(v)) + "\" y1=\"" + num(ay0) + "\" x2=\"" + num(mx(v)) + "\" y2=\"" +
           num(ay1) + "\"/>\n";
  for (double v : ty.major)
    if (my.drawable(v))
      s += "<line x1=\"" + num(ax0) + "\" y1=\"" + num(my(v)) + "\" x2=\"" + num(ax1) + "\" y2=\"" +
           num(my(v)) + "\"/>\n";
  s += "</g>\n";
  s += "<rect class=\"plot-area\" x=\"" + num(f.ax0) + "\" y=\"" + num(f.ay0) + "\" width=\"" + num(f.width) +
       "\" height=\"" + num(f.height) + "\" fill=\"none\" stroke=\"#333333\" stroke-width=\"1\"/>\n";
  s += "<g class=\"ticks\" stroke=\"#333333\" stroke-width=\"1\">\n";
  for (double v : tx.minor)
    if (mx.drawable(v))
      s += "<line x1=\"" + num(mx(v)) + "\" y1=\"" + num(ay1) + "\" x2=\"" + num(mx(v)) + "\" y2=\"" +
           num(ay1 + 3) + "\"/>\n";
  for (double v : tx.major)
    if (mx.drawable(v))
      s += "<line x1=\"" + num(mx(v)) + "\" y1=\"" + num(ay1) + "\" x2=\"" + num(mx(v)) + "\" y2=\"" +
           num(ay1 + 6) + "\"/>\n";
  for (double v : ty.minor)
    if (my.drawable(v))
      s += "<line x1=\"" + num(ax0 - 3) + "\" y1=\"" + num(my(v)) + "\" x2=\"" + num(ax0) + "\" y2=\"" +
           num(my(v)) + "\"/>\n";
  for (double v : ty.major)
    if (my.drawable(v))
      s += "<line x1=\"" + num(ax0 - 6) + "\" y1=\"" + num(my(v)) + "\" x2=\"" + num(ax0) + "\" y2=\"" +
           num(my(v)) + "\"/>\n";
  s += "</g>\n";
  s += "<g class=\"x-tick-labels\" font-size=\"" + num(small) + "\" text-anchor=\"middle\">\n";
  for (std::size_t i = 0; i < tx.major.size(); ++i)
    if (mx.drawable(tx.major[i]))
      s += "<text x=\"" + num(mx(tx.major[i])) + "\" y=\"" + num(ay1 + 8 + small) + "\">" +
           labelSvg(tx.labels[i], plot.x.scale) + "</text>\n";
  s += "</g>\n";
  s += "<g class=\"y-tick-labels\" font-size=\"" + num(small) + "\" text-anchor=\"end\">\n";
  for (std::size_t i = 0; i < ty.major.size(); ++i)
    if (my.drawable(ty.major[i]))
      s += "<text x=\"" + num(ax0 - 9) + "\" y=\"" + num(my(ty.major[i]) + small * 0.35) + "\">" +
           labelSvg(ty.labels[i], plot.y.scale) + "</text>\n";
  s += "</g>\n";
  s += "<text class=\"x-title\" x=\"" + num(ax0 + f.width / 2) + "\" y=\"" +
       num(ay1 + 8 + small + 10 + font) + "\" text-anchor=\"middle\" font-size=\"" + num(font) + "\">" +
       escapeXml(axisTitle(plot.x)) + "</text>\n";
  const double yTitleX = 14 + font * 0.8, yTitleY = ay0 + f.height / 2;
  s += "<text class=\"y-title\" x=\"" + num(yTitleX) + "\" y=\"" + num(yTitleY) +
       "\" text-anchor=\"middle\" font-size=\"" + num(font) + "\" transform=\"rotate(-90 " + num(yTitleX) +
       " " + num(yTitleY) + ")\">" + escapeXml(axisTitle(plot.y)) + "</text>\n";
}

// Every series' line, markers, tooltips and point texts, clipped to the
// plot area; counts what was drawn and skipped into `out`.
void appendSeries(std::string& s, const Plot& plot, const PlotFrame& f, PlotRender& out) {
  const double small = f.small;
  const double ax0 = f.ax0, ax1 = f.ax1, ay0 = f.ay0;
  const AxisMap &mx = f.mx, &my = f.my;
  // Data, clipped by a nested <svg> (no clipPath id needed) whose viewBox
  // equals its box, so coordinates are those of the whole plot. Every point
  // drawn lies in the plot area and so do the lines between them; the clip,
  // 8 units wider on each side, only keeps markers and texts at the edges
  // whole. Highlighted series go last, on top.
  std::vector<std::size_t> order(plot.series.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_partition(order.begin(), order.end(), [&](std::size_t i) { return !plot.series[i].highlight; });
  const std::vector<std::string>& palette = plotPalette();
  const double pad = 8;
  const std::string box = num(ax0 - pad) + "\" y=\"" + num(ay0 - pad) + "\" width=\"" +
                          num(f.width + 2 * pad) + "\" height=\"" + num(f.height + 2 * pad);
  s += "<svg class=\"data\" x=\"" + box + "\" viewBox=\"" + num(ax0 - pad) + " " + num(ay0 - pad) + " " +
       num(f.width + 2 * pad) + " " + num(f.height + 2 * pad) + "\" overflow=\"hidden\">\n";
  for (std::size_t si : order) {
    const PlotSeries& ser = plot.series[si];
    const std::string colour =
        palette[static_cast<std::size_t>(ser.colour >= 0 ? ser.colour : static_cast<int>(si)) %
                palette.size()];
    const int shape = ser.marker >= 0 ? ser.marker : static_cast<int>(si);
    const double width = ser.highlight ? 3 : 1.6, radius = ser.highlight ? 4.5 : 3.5;
    // Map every point once; a point that cannot be placed breaks the line.
    std::vector<bool> ok(ser.points.size());
    std::vector<double> px(ser.points.size()), py(ser.points.size());
    for (std::size_t i = 0; i < ser.points.size(); ++i) {
      const PlotPoint& p = ser.points[i];
      ok[i] = mx.drawable(p.x) && my.drawable(p.y);
      if (ok[i]) {
        px[i] = mx(p.x);
        py[i] = my(p.y);
        ++out.drawn;
      } else {
        ++out.skipped;
      }
    }
    s += "<g class=\"series\">\n<title>" + escapeXml(ser.name) + "</title>\n";
    if (ser.line != PlotLine::None) {
      std::string d;
      bool open = false;
      for (std::size_t i = 0; i < ser.points.size(); ++i) {
        if (!ok[i]) {
          open = false;
          continue;
        }
        if (!open) {
          d += "M" + num(px[i]) + " " + num(py[i]);
          open = true;
        } else if (ser.line == PlotLine::Step) {
          d += "H" + num(px[i]) + "V" + num(py[i]);
        } else {
          d += "L" + num(px[i]) + " " + num(py[i]);
        }
      }
      if (!d.empty())
        s += "<path d=\"" + d + "\" fill=\"none\" stroke=\"" + colour + "\" stroke-width=\"" + num(width) +
             "\" stroke-linejoin=\"round\"/>\n";
    }
    const std::string paint = strokedShape(shape)
                                  ? "fill=\"none\" stroke=\"" + colour + "\" stroke-width=\"1.6\""
                                  : "fill=\"" + colour + "\" stroke=\"#ffffff\" stroke-width=\"0.8\"";
    for (std::size_t i = 0; i < ser.points.size(); ++i) {
      if (!ok[i]) continue;
      const PlotPoint& p = ser.points[i];
      const bool hasTip = !p.tooltip.empty();
      if (ser.markers || hasTip) {
        // A line-only series with tooltips gets invisible hover targets.
        const std::string m = ser.markers ? markerSvg(shape, px[i], py[i], radius, paint)
                                          : "<circle cx=\"" + num(px[i]) + "\" cy=\"" + num(py[i]) +
                                                "\" r=\"5\" fill-opacity=\"0\"/>";
        if (hasTip)
          s += "<g><title>" + escapeXml(p.tooltip) + "</title>" + m + "</g>\n";
        else
          s += m + "\n";
      }
      if (!p.text.empty()) {
        // Right of the marker, or left of it when it would run past the plot area.
        const bool toLeft = px[i] + radius + 3 + textWidth(p.text, small) > ax1;
        s += "<text x=\"" + num(toLeft ? px[i] - radius - 3 : px[i] + radius + 3) + "\" y=\"" +
             num(py[i] - radius - 2) + "\" font-size=\"" + num(small) +
             (toLeft ? "\" text-anchor=\"end" : "") +
             "\" fill=\"#222222\" stroke=\"#ffffff\" stroke-width=\"3\" paint-order=\"stroke\">" +
             escapeXml(p.text) + "</text>\n";
      }
    }
    s += "</g>\n";
  }
  s += "</svg>\n";
}

// The legend column right of the plot area.
void appendLegend(std::string& s, const Plot& plot, const PlotFrame& f) {
  const double small = f.small;
  const double ax1 = f.ax1, ay0 = f.ay0;
  const std::vector<std::string>& palette = plotPalette();
  // Legend: a line and marker sample per series, in the given order.
  if (!plot.series.empty()) {
    const double lx = ax1 + 14, ly = ay0 + 4;
    s += "<g class=\"legend\" font-size=\"" + num(small) + "\">\n";
    for (std::size_t si = 0; si < plot.series.size(); ++si) {
      const PlotSeries& ser = plot.series[si];
      const std::string colour =
          palette[static_cast<std::size_t>(ser.colour >= 0 ? ser.colour : static_cast<int>(si)) %
                  palette.size()];
      const int shape = ser.marker >= 0 ? ser.marker : static_cast<int>(si);
      const double y = ly + 18 * static_cast<double>(si) + 6;
      if (ser.line != PlotLine::None)
        s += "<line x1=\"" + num(lx) + "\" y1=\"" + num(y) + "\" x2=\"" + num(lx + 24) + "\" y2=\"" + num(y) +
             "\" stroke=\"" + colour + "\" stroke-width=\"" + num(ser.highlight ? 3 : 1.6) + "\"/>\n";
      if (ser.markers) {
        const std::string paint = strokedShape(shape)
                                      ? "fill=\"none\" stroke=\"" + colour + "\" stroke-width=\"1.6\""
                                      : "fill=\"" + colour + "\"";
        s += markerSvg(shape, lx + 12, y, 3.5, paint) + "\n";
      }
      s += "<text x=\"" + num(lx + 30) + "\" y=\"" + num(y + small * 0.35) + "\">" + escapeXml(ser.name) +
           "</text>\n";
    }
    s += "</g>\n";
  }
}

}  // namespace

PlotRender renderPlot(const Plot& plot) {
  PlotRender out;
  const double W = std::max(plot.width, 200), H = std::max(plot.height, 150);
  const double font = 13, small = 11;

  const Range rx = dataRange(plot, plot.x, true), ry = dataRange(plot, plot.y, false);
  const AxisTicks tx = axisTicks(plot.x, rx), ty = axisTicks(plot.y, ry);

  // Layout: title on top, y labels and title on the left, x labels and title
  // below, the legend in a column on the right.
  double yLabelWidth = 0;
  for (const std::string& l : ty.labels) yLabelWidth = std::max(yLabelWidth, textWidth(l, small));
  double legendWidth = 0;
  for (const PlotSeries& s : plot.series) legendWidth = std::max(legendWidth, textWidth(s.name, small));
  legendWidth = plot.series.empty() ? 0 : std::min(legendWidth + 40, W * 0.35);
  const double left = 14 + font + 8 + yLabelWidth + 8;
  const double top = plot.title.empty() ? 16 : 16 + font * 1.4 + 8;
  const double right = 16 + legendWidth;
  const double bottom = 8 + small + 10 + font + 22;  // tick labels, axis title, skipped note
  out.areaX = left;
  out.areaY = top;
  out.areaWidth = std::max(40.0, W - left - right);
  out.areaHeight = std::max(40.0, H - top - bottom);
  const double ax0 = out.areaX, ax1 = out.areaX + out.areaWidth;
  const double ay0 = out.areaY, ay1 = out.areaY + out.areaHeight;

  const AxisMap mx{plot.x.scale, tx.lo, tx.hi, ax0, ax1};
  const AxisMap my{plot.y.scale, ty.lo, ty.hi, ay1, ay0};
  const PlotFrame frame{font, small, ax0, ax1, ay0, ay1, out.areaWidth, out.areaHeight, tx, ty, mx, my};

  std::string s;
  s += "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + num(W) + "\" height=\"" + num(H) +
       "\" viewBox=\"0 0 " + num(W) + " " + num(H) +
       "\" font-family=\"sans-serif\" style=\"max-width:100%;height:auto\" role=\"img\">\n";
  s += "<title>" +
       escapeXml(plot.title.empty() ? axisTitle(plot.y) + " against " + axisTitle(plot.x) : plot.title) +
       "</title>\n";
  s += "<rect width=\"100%\" height=\"100%\" fill=\"#ffffff\"/>\n";
  if (!plot.title.empty())
    s += "<text x=\"" + num(ax0 + out.areaWidth / 2) + "\" y=\"" + num(16 + font) +
         "\" text-anchor=\"middle\" font-size=\"" + num(font * 1.2) + "\" font-weight=\"bold\">" +
         escapeXml(plot.title) + "</text>\n";

  appendAxes(s, plot, frame);
  appendSeries(s, plot, frame, out);
  appendLegend(s, plot, frame);

  if (out.skipped > 0)
    s += "<text class=\"skipped\" x=\"" + num(ax0) + "\" y=\"" + num(H - 6) + "\" font-size=\"" + num(small) +
         "\" fill=\"#555555\">" + std::to_string(out.skipped) + " point" + (out.skipped == 1 ? "" : "s") +
         " not shown (not finite, not positive on a log axis, or outside the axis range)</text>\n";
  s += "</svg>\n";
  out.svg = std::move(s);
  return out;
}

}  // namespace rastray
