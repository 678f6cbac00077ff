// Plots for reports a person reads, as self-contained SVG: a title, two
// labelled axes (quantity and unit), linear or log scale per axis, nice
// ticks, a legend, any number of series drawn as lines and/or markers,
// optional per-point tooltips and text, and highlighted series (a Pareto
// front as a step line).
//
// The output is one <svg> element: valid XML (every text escaped, control
// characters dropped), no scripts, no external resources, no ids (so any
// number of plots can sit in one HTML page, and the string can also be
// written as a .svg file). Colours come from the Okabe–Ito palette, which
// stays distinguishable under the common colour-vision deficiencies; each
// series also gets its own marker shape, so the plot reads in grey too.
//
// Values that cannot be drawn — NaN, ±inf, and values <= 0 on a log axis,
// or values outside a fixed axis range — are skipped and counted (the plot
// says how many under the axes); a line is broken at a skipped point. No
// coordinate written is ever NaN or infinite.
#pragma once

#include <cstddef>
#include <limits>
#include <string>
#include <vector>

namespace rastray {

enum class AxisScale { Linear, Log };

struct PlotAxis {
  std::string quantity;  // e.g. "time per frame"
  std::string unit;      // e.g. "ms"; empty for a dimensionless quantity
  AxisScale scale = AxisScale::Linear;
  // A fixed range; NaN (default) takes it from the data, widened to ticks.
  double min = std::numeric_limits<double>::quiet_NaN();
  double max = std::numeric_limits<double>::quiet_NaN();
};

// "quantity (unit)", or the quantity alone when the unit is empty.
std::string axisTitle(const PlotAxis& axis);

struct PlotPoint {
  double x = 0, y = 0;
  std::string tooltip;  // shown on hover (<title>); empty: none
  std::string text;     // written beside the marker (e.g. "2.3x"), right of it unless it would
                        // leave the plot area; empty: none
};

enum class PlotLine {
  None,      // markers only
  Straight,  // points joined in the order given
  Step,      // horizontal to the next point's x, then vertical (a Pareto front
             // of points sorted by x: the boundary of what is attainable)
};

struct PlotSeries {
  std::string name;  // legend entry
  std::vector<PlotPoint> points;
  PlotLine line = PlotLine::Straight;
  bool markers = true;
  bool highlight = false;  // drawn thicker, on top of the others
  int colour = -1;         // index into plotPalette(); -1: the series' index
  int marker = -1;         // marker shape index (circle, square, triangle,
                           // diamond, down-triangle, cross, plus); -1: series index
};

struct Plot {
  std::string title;
  PlotAxis x, y;
  std::vector<PlotSeries> series;
  int width = 760, height = 480;  // SVG user units (CSS pixels)
};

// The palette: Okabe & Ito (2008), yellow left out (too light on white),
// black last.
const std::vector<std::string>& plotPalette();

// Tick positions of one axis, in data units, ascending.
struct AxisTicks {
  double lo = 0, hi = 1;            // the drawn range (data units)
  std::vector<double> major;        // labelled
  std::vector<std::string> labels;  // one per major tick; log: "10^k" as plain text
  std::vector<double> minor;        // unlabelled (log axes: 2..9 x 10^k)
};

// Linear: steps of 1, 2 or 5 x 10^k, about `target` of them, the range
// widened to the enclosing ticks. Log: decade ticks 10^k over the range
// widened to whole decades, every n-th decade labelled when there are many,
// minor ticks at 2..9 x 10^k when there are at most 12 decades. `lo`/`hi`
// must be finite, and positive for a log axis; lo == hi is widened.
AxisTicks niceTicks(double lo, double hi, AxisScale scale, int target = 6);

// Maps a data value of an axis to a position in [from, to] (SVG units).
struct AxisMap {
  AxisScale scale = AxisScale::Linear;
  double lo = 0, hi = 1;    // data range
  double from = 0, to = 1;  // SVG range (y axes run from bottom to top)
  // false for values this axis cannot place (NaN, inf, <= 0 on a log axis,
  // outside [lo, hi] beyond rounding).
  bool drawable(double v) const;
  double operator()(double v) const;
};

struct PlotRender {
  std::string svg;
  std::size_t drawn = 0;    // points placed
  std::size_t skipped = 0;  // points left out (see above)
  // The plot area (SVG units): data points land inside it.
  double areaX = 0, areaY = 0, areaWidth = 0, areaHeight = 0;
};

PlotRender renderPlot(const Plot& plot);

// Indices of the points no other point beats in both coordinates (smaller
// x and smaller y are better, e.g. time and error), sorted by x ascending;
// points with non-finite coordinates are never on the front. Ties: of equal
// points, the first is kept.
std::vector<std::size_t> paretoFront(const std::vector<PlotPoint>& points);

// Text for XML content and attribute values: & < > " ' escaped, control
// characters other than tab and newline dropped (XML 1.0 forbids them).
std::string escapeXml(const std::string& s);

}  // namespace rastray
