// The SVG plot module: well-formed XML (checked by a small parser,
// tests/app/xml_check.h, not by the module), labelled axes, decade ticks on
// log axes, points inside the plot area, values a log axis cannot place
// skipped and counted, never a NaN coordinate.
#include "app/report/svg_plot.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <regex>
#include <string>
#include <vector>

#include "xml_check.h"

namespace rastray {
namespace {

using test::Element;
using test::parseXml;

std::vector<Element> parseOk(const std::string& svg) {
  std::string error;
  std::vector<Element> elements = parseXml(svg, &error);
  EXPECT_TRUE(error.empty()) << error << "\n" << svg;
  return elements;
}

// Every number in every coordinate attribute and path of the document (path
// commands M L H V Z and separators split them; "nan"/"inf" stay whole).
std::vector<std::string> numbersIn(const std::vector<Element>& elements) {
  static const std::string coordinateAttributes[] = {"x",  "y",  "cx", "cy",    "r",      "x1",     "x2",
                                                     "y1", "y2", "d",  "width", "height", "viewBox"};
  std::vector<std::string> out;
  for (const Element& e : elements)
    for (const std::string& name : coordinateAttributes) {
      const auto it = e.attributes.find(name);
      if (it == e.attributes.end() || it->second == "100%") continue;
      std::string token;
      for (char c : it->second + " ") {
        if (std::string("MLHVZ ,").find(c) != std::string::npos) {
          if (!token.empty()) out.push_back(token);
          token.clear();
        } else {
          token += c;
        }
      }
    }
  return out;
}

// The checker itself rejects what it must (else the tests below prove nothing).
TEST(SvgPlot, XmlCheckerRejectsMalformedDocuments) {
  for (const char* bad : {"<svg><g></svg>", "<svg a=\"1\" a=\"2\"/>", "<svg>a & b</svg>", "<svg x=1/>",
                          "<svg></svg><svg></svg>", "<svg>", "<svg><text>1 < 2</text></svg>"}) {
    std::string error;
    parseXml(bad, &error);
    EXPECT_FALSE(error.empty()) << bad;
  }
  std::string error;
  EXPECT_EQ(parseXml("<svg a=\"&lt;\"><g/>t&amp;</svg>", &error).size(), 2u);
  EXPECT_TRUE(error.empty()) << error;
}

Plot samplePlot() {
  Plot p;
  p.title = "Error <against> time & \"cost\"";
  p.x = {"time per frame", "ms", AxisScale::Log};
  p.y = {"RMS error", "", AxisScale::Log};
  PlotSeries a{"spp", {{1, 0.1, "1 spp"}, {4, 0.05, "4 spp"}, {16, 0.02, ""}, {64, 0.011, "", "64x"}}};
  PlotSeries b{"depth format 'unorm16'", {{2, 0.2}, {3, 0.15}}, PlotLine::None};
  p.series = {a, b};
  return p;
}

TEST(SvgPlot, IsWellFormedXmlWithEscapedText) {
  const PlotRender r = renderPlot(samplePlot());
  const std::vector<Element> elements = parseOk(r.svg);
  ASSERT_FALSE(elements.empty());
  EXPECT_EQ(elements[0].name, "svg");
  EXPECT_EQ(elements[0].attributes.at("xmlns"), "http://www.w3.org/2000/svg");
  // The title came through escaped and reads back as given.
  bool title = false;
  for (const Element& e : elements)
    if (e.name == "text" && e.text == "Error <against> time & \"cost\"") title = true;
  EXPECT_TRUE(title);
  // No script, no reference to anything outside the document.
  for (const Element& e : elements) {
    EXPECT_NE(e.name, "script");
    EXPECT_NE(e.name, "image");
    EXPECT_NE(e.name, "foreignObject");
    for (const auto& [name, value] : e.attributes) {
      EXPECT_NE(name, "href");
      EXPECT_NE(name, "xlink:href");
      EXPECT_EQ(name.rfind("on", 0), std::string::npos) << name;
    }
  }
}

TEST(SvgPlot, EscapesMarkupAndDropsControlCharacters) {
  EXPECT_EQ(escapeXml("a<b>&\"c'"), "a&lt;b&gt;&amp;&quot;c&apos;");
  EXPECT_EQ(escapeXml(std::string("x\x01y\x1Fz\tw\n", 9)), "xyz\tw\n");
  Plot p;
  p.x = {"t", "s"};
  p.y = {"e", ""};
  p.title = std::string("bad\x02 </svg> <script>alert(1)</script>");
  p.series = {{"</g>", {{1, 1, "<b>&amp;"}}}};
  const std::vector<Element> elements = parseOk(renderPlot(p).svg);
  for (const Element& e : elements) EXPECT_NE(e.name, "script");
}

TEST(SvgPlot, AxesCarryTheirTitlesWithUnits) {
  const std::vector<Element> elements = parseOk(renderPlot(samplePlot()).svg);
  std::string xTitle, yTitle;
  for (const Element& e : elements) {
    const auto c = e.attributes.find("class");
    if (c == e.attributes.end()) continue;
    if (c->second == "x-title") xTitle = e.text;
    if (c->second == "y-title") yTitle = e.text;
  }
  EXPECT_EQ(xTitle, "time per frame (ms)");
  EXPECT_EQ(yTitle, "RMS error");
  // Both series are in the legend.
  std::vector<std::string> legend;
  bool inLegend = false;
  for (const Element& e : elements) {
    if (e.name == "g") inLegend = e.attributes.count("class") && e.attributes.at("class") == "legend";
    if (inLegend && e.name == "text") legend.push_back(e.text);
  }
  EXPECT_EQ(legend, (std::vector<std::string>{"spp", "depth format 'unorm16'"}));
}

TEST(SvgPlot, LogTicksAreDecadesWithMinorTicks) {
  const AxisTicks t = niceTicks(0.003, 250, AxisScale::Log);
  EXPECT_DOUBLE_EQ(t.lo, 1e-3);
  EXPECT_DOUBLE_EQ(t.hi, 1e3);
  ASSERT_EQ(t.major.size(), 7u);
  for (int k = -3; k <= 3; ++k) {
    EXPECT_NEAR(t.major[k + 3], std::pow(10.0, k), 1e-12 * std::pow(10.0, k));
    EXPECT_EQ(t.labels[k + 3], "10^" + std::to_string(k));
  }
  // 2..9 in each of the 6 decades.
  ASSERT_EQ(t.minor.size(), 48u);
  EXPECT_NEAR(t.minor[0], 2e-3, 1e-15);
  EXPECT_NEAR(t.minor.back(), 900, 1e-9);

  // An exact decade is not widened; a range inside one decade becomes one decade.
  const AxisTicks exact = niceTicks(10, 1000, AxisScale::Log);
  EXPECT_DOUBLE_EQ(exact.lo, 10);
  EXPECT_DOUBLE_EQ(exact.hi, 1000);
  const AxisTicks inside = niceTicks(2, 8, AxisScale::Log);
  EXPECT_DOUBLE_EQ(inside.lo, 1);
  EXPECT_DOUBLE_EQ(inside.hi, 10);

  // Many decades: at most ~10 labels, every n-th decade, no minor ticks.
  const AxisTicks wide = niceTicks(1e-30, 1e30, AxisScale::Log);
  EXPECT_LE(wide.major.size(), 11u);
  EXPECT_GE(wide.major.size(), 5u);
  EXPECT_TRUE(wide.minor.empty());

  // In the SVG the labels are 10 with a superscript exponent (true minus sign).
  const std::string svg = renderPlot(samplePlot()).svg;
  EXPECT_NE(svg.find("10<tspan dy=\"-0.45em\" font-size=\"75%\">\xE2\x88\x92"
                     "2</tspan>"),
            std::string::npos);
  EXPECT_NE(svg.find("10<tspan dy=\"-0.45em\" font-size=\"75%\">2</tspan>"), std::string::npos);
}

TEST(SvgPlot, LinearTicksAreNiceAndCoverTheData) {
  const AxisTicks t = niceTicks(0.13, 9.7, AxisScale::Linear);
  EXPECT_LE(t.lo, 0.13);
  EXPECT_GE(t.hi, 9.7);
  ASSERT_GE(t.major.size(), 4u);
  ASSERT_LE(t.major.size(), 12u);
  const double step = t.major[1] - t.major[0];
  const double mant = step / std::pow(10.0, std::floor(std::log10(step)));
  EXPECT_TRUE(std::fabs(mant - 1) < 1e-9 || std::fabs(mant - 2) < 1e-9 || std::fabs(mant - 5) < 1e-9) << step;
  EXPECT_EQ(t.labels.front(), "0");
  EXPECT_EQ(t.labels.back(), "10");
  const AxisTicks frac = niceTicks(0, 0.25, AxisScale::Linear);
  EXPECT_EQ(frac.labels[1], "0.05");
  // One value: widened around it, never a zero-width range.
  const AxisTicks one = niceTicks(3, 3, AxisScale::Linear);
  EXPECT_LT(one.lo, 3);
  EXPECT_GT(one.hi, 3);
}

TEST(SvgPlot, PointsLandInsideThePlotArea) {
  Plot p;
  p.x = {"triangles", "", AxisScale::Log};
  p.y = {"time", "s", AxisScale::Linear};
  PlotSeries s{"raster", {}};
  for (int k = 0; k < 6; ++k) s.points.push_back({std::pow(10.0, k + 2) * 1.7, 0.5 * k + 0.01});
  s.marker = 0;  // circles: centres are attributes
  p.series = {s};
  const PlotRender r = renderPlot(p);
  EXPECT_EQ(r.drawn, 6u);
  EXPECT_EQ(r.skipped, 0u);
  const std::vector<Element> elements = parseOk(r.svg);
  double ax = -1, ay = -1, aw = -1, ah = -1;
  std::vector<std::pair<double, double>> centres;
  bool inData = false;
  for (const Element& e : elements) {
    if (e.name == "rect" && e.attributes.count("class") && e.attributes.at("class") == "plot-area") {
      ax = std::stod(e.attributes.at("x"));
      ay = std::stod(e.attributes.at("y"));
      aw = std::stod(e.attributes.at("width"));
      ah = std::stod(e.attributes.at("height"));
    }
    if (e.name == "svg" && e.attributes.count("class")) inData = e.attributes.at("class") == "data";
    if (e.name == "g" && e.attributes.count("class") && e.attributes.at("class") == "legend") inData = false;
    if (inData && e.name == "circle")
      centres.push_back({std::stod(e.attributes.at("cx")), std::stod(e.attributes.at("cy"))});
  }
  EXPECT_NEAR(ax, r.areaX, 0.01);
  EXPECT_NEAR(aw, r.areaWidth, 0.01);
  ASSERT_EQ(centres.size(), 6u);
  for (std::size_t i = 0; i < centres.size(); ++i) {
    EXPECT_GE(centres[i].first, ax);
    EXPECT_LE(centres[i].first, ax + aw);
    EXPECT_GE(centres[i].second, ay);
    EXPECT_LE(centres[i].second, ay + ah);
    if (i > 0) {  // x and y both grow: right and up on screen
      EXPECT_GT(centres[i].first, centres[i - 1].first);
      EXPECT_LT(centres[i].second, centres[i - 1].second);
    }
  }
  // Equal ratios on a log axis are equal distances: each point is x10 the last.
  const double d1 = centres[1].first - centres[0].first, d4 = centres[5].first - centres[4].first;
  EXPECT_NEAR(d1, d4, 0.02);
}

TEST(SvgPlot, AxisMapPlacesTheEndsAndRejectsWhatItCannotPlace) {
  const AxisMap lin{AxisScale::Linear, -2, 6, 100, 500};
  EXPECT_DOUBLE_EQ(lin(-2), 100);
  EXPECT_DOUBLE_EQ(lin(6), 500);
  EXPECT_DOUBLE_EQ(lin(2), 300);
  EXPECT_FALSE(lin.drawable(std::nan("")));
  EXPECT_FALSE(lin.drawable(7));
  const AxisMap lg{AxisScale::Log, 1e-2, 1e2, 400, 0};  // a y axis: up is smaller
  EXPECT_DOUBLE_EQ(lg(1), 200);
  EXPECT_NEAR(lg(10), 100, 1e-9);
  EXPECT_FALSE(lg.drawable(0));
  EXPECT_FALSE(lg.drawable(-1));
  EXPECT_FALSE(lg.drawable(std::numeric_limits<double>::infinity()));
}

TEST(SvgPlot, UnplaceableValuesAreSkippedCountedAndNeverNaN) {
  const double inf = std::numeric_limits<double>::infinity(), nan = std::nan("");
  Plot p;
  p.title = "bad values";
  p.x = {"x", "s", AxisScale::Log};
  p.y = {"y", "", AxisScale::Log};
  PlotSeries s{"mixed", {{1, 1}, {nan, 2}, {2, -1}, {0, 3}, {inf, 4}, {4, 0}, {8, nan}, {16, 16, "tip"}}};
  PlotSeries front{"front", {{1, 1}, {-inf, 1}}, PlotLine::Step, true, true};
  p.series = {s, front};
  const PlotRender r = renderPlot(p);
  EXPECT_EQ(r.drawn, 3u);
  EXPECT_EQ(r.skipped, 7u);
  EXPECT_NE(r.svg.find("7 points not shown"), std::string::npos);
  const std::vector<Element> elements = parseOk(r.svg);
  const std::vector<std::string> numbers = numbersIn(elements);
  EXPECT_GT(numbers.size(), 50u);
  for (const std::string& n : numbers) {
    char* end = nullptr;
    const double v = std::strtod(n.c_str(), &end);
    EXPECT_TRUE(*end == '\0' && std::isfinite(v)) << n;
  }
  EXPECT_EQ(r.svg.find("nan"), std::string::npos);
  EXPECT_EQ(r.svg.find("inf"), std::string::npos);

  // A plot with nothing drawable still has its frame and axes, and says so.
  Plot empty = p;
  empty.series = {{"none", {{nan, nan}, {-1, -2}}}};
  const PlotRender e = renderPlot(empty);
  EXPECT_EQ(e.drawn, 0u);
  EXPECT_EQ(e.skipped, 2u);
  parseOk(e.svg);
  EXPECT_EQ(e.svg.find("nan"), std::string::npos);

  // Linear axes spanning the whole double range do not overflow.
  Plot huge;
  huge.x = {"x", ""};
  huge.y = {"y", ""};
  huge.series = {{"h", {{-1.7e308, -1.7e308}, {1.7e308, 1.7e308}}}};
  const PlotRender h = renderPlot(huge);
  parseOk(h.svg);
  EXPECT_EQ(h.svg.find("nan"), std::string::npos);
  EXPECT_EQ(h.svg.find("inf"), std::string::npos);
}

TEST(SvgPlot, FixedRangeSkipsPointsOutsideIt) {
  Plot p;
  p.x = {"x", "", AxisScale::Linear, 0, 10};
  p.y = {"y", ""};
  p.series = {{"s", {{-5, 1}, {5, 1}, {15, 1}}}};
  const PlotRender r = renderPlot(p);
  EXPECT_EQ(r.drawn, 1u);
  EXPECT_EQ(r.skipped, 2u);
}

TEST(SvgPlot, StepLineAndTooltips) {
  Plot p;
  p.x = {"time", "s", AxisScale::Log};
  p.y = {"error", "", AxisScale::Log};
  p.series = {{"front", {{1, 10, "a"}, {10, 1, "b"}}, PlotLine::Step, false, true}};
  const PlotRender r = renderPlot(p);
  const std::vector<Element> elements = parseOk(r.svg);
  // The step path goes horizontally, then vertically.
  bool step = false;
  int tips = 0;
  for (const Element& e : elements) {
    if (e.name == "path" && e.attributes.count("d") &&
        std::regex_match(e.attributes.at("d"), std::regex(R"(M[0-9.]+ [0-9.]+H[0-9.]+V[0-9.]+)")))
      step = true;
    if (e.name == "title" && (e.text == "a" || e.text == "b")) ++tips;
  }
  EXPECT_TRUE(step) << r.svg;
  EXPECT_EQ(tips, 2);  // hover targets even without markers
}

// A point's text stays inside the plot area: left of a marker near the right edge.
TEST(SvgPlot, PointTextsStayInsideThePlotArea) {
  Plot p;
  p.x = {"x", ""};
  p.y = {"y", ""};
  p.series = {{"s", {{0, 0, "", "a long label at the left"}, {10, 10, "", "a long label at the right"}}}};
  const PlotRender r = renderPlot(p);
  std::string error;
  int anchoredEnd = 0, texts = 0;
  for (const test::Element& e : test::parseXml(r.svg, &error)) {
    if (e.name != "text" || e.text.rfind("a long label", 0) != 0) continue;
    ++texts;
    const double x = std::stod(e.attributes.at("x"));
    const bool end = e.attributes.count("text-anchor") && e.attributes.at("text-anchor") == "end";
    anchoredEnd += end;
    EXPECT_EQ(end, e.text == "a long label at the right");
    EXPECT_GE(x, r.areaX);
    EXPECT_LE(x, r.areaX + r.areaWidth);
  }
  EXPECT_TRUE(error.empty()) << error;
  EXPECT_EQ(texts, 2);
  EXPECT_EQ(anchoredEnd, 1);
}

TEST(SvgPlot, ParetoFrontKeepsTheUnbeatenPointsInOrder) {
  const double nan = std::nan("");
  const std::vector<PlotPoint> pts = {{5, 1}, {1, 9}, {2, 4}, {3, 5}, {2, 4}, {nan, 0}, {8, 0.5}, {1, 10}};
  EXPECT_EQ(paretoFront(pts), (std::vector<std::size_t>{1, 2, 0, 6}));
  EXPECT_TRUE(paretoFront({}).empty());
}

TEST(SvgPlot, PaletteHasDistinctColours) {
  const std::vector<std::string>& pal = plotPalette();
  ASSERT_GE(pal.size(), 7u);
  for (std::size_t i = 0; i < pal.size(); ++i)
    for (std::size_t j = i + 1; j < pal.size(); ++j) EXPECT_NE(pal[i], pal[j]);
}

}  // namespace
}  // namespace rastray
