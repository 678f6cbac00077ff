#include "compare/maps.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "common/image.h"
#include "compare/color_metrics.h"

namespace rastray {

namespace {

glm::dvec3 rgb255(int r, int g, int b) { return glm::dvec3(r, g, b) / 255.0; }

// writePng encodes linear colour to sRGB; give it the linear value of the
// wanted display colour (alpha 1: the maps are opaque).
glm::vec4 linearFromSrgb(const glm::dvec3& srgb) {
  return {srgbToLinear(float(srgb.r)), srgbToLinear(float(srgb.g)), srgbToLinear(float(srgb.b)), 1.0f};
}

}  // namespace

glm::dvec3 ColorBar::srgbAt(double value) const {
  if (std::isnan(value)) return missing;
  if (stops.empty()) return glm::dvec3(0.0);
  const double t = hi > lo ? std::clamp((value - lo) / (hi - lo), 0.0, 1.0) : 0.0;
  if (t <= stops.front().position) return stops.front().srgb;
  for (size_t i = 1; i < stops.size(); ++i)
    if (t <= stops[i].position) {
      const double u = (t - stops[i - 1].position) / (stops[i].position - stops[i - 1].position);
      return glm::mix(stops[i - 1].srgb, stops[i].srgb, u);
    }
  return stops.back().srgb;
}

std::string ColorBar::cssGradient() const {
  std::string css = "linear-gradient(to right";
  for (const ColorStop& s : stops) {
    char buf[64];
    std::snprintf(buf, sizeof buf, ", %s %.4g%%", cssColor(s.srgb).c_str(), s.position * 100.0);
    css += buf;
  }
  return css + ")";
}

ColorBar heatColorBar(const std::string& quantity, double lo, double hi) {
  ColorBar bar;
  bar.quantity = quantity;
  bar.lo = lo;
  bar.hi = hi;
  bar.stops = {{0.0, rgb255(0, 0, 4)},
               {0.25, rgb255(87, 16, 110)},
               {0.5, rgb255(188, 55, 84)},
               {0.75, rgb255(249, 142, 9)},
               {1.0, rgb255(252, 255, 164)}};
  bar.missing = rgb255(0x40, 0x60, 0x40);  // muted green: off the inferno scale
  return bar;
}

const std::vector<LegendEntry>& mismatchLegend() {
  // Ties and edges in cool or pale colours, plane effects in magenta,
  // genuine mismatches in saturated red: the eye finds red first.
  static const std::vector<LegendEntry> legend = {
      {PixelVisibility::BothEmpty, "both-empty", "both empty", rgb255(0, 0, 0)},
      {PixelVisibility::Agree, "agree", "agree", rgb255(64, 64, 64)},
      {PixelVisibility::CutOff, "cut-off", "cut off (one renderer stopped early)", rgb255(150, 110, 60)},
      {PixelVisibility::SilhouetteEdge, toString(MismatchClass::SilhouetteEdge),
       displayName(MismatchClass::SilhouetteEdge), rgb255(66, 135, 245)},
      {PixelVisibility::SharedEdgeTie, toString(MismatchClass::SharedEdgeTie),
       displayName(MismatchClass::SharedEdgeTie), rgb255(80, 220, 220)},
      {PixelVisibility::DepthTie, toString(MismatchClass::DepthTie), displayName(MismatchClass::DepthTie),
       rgb255(250, 215, 50)},
      {PixelVisibility::NearFarPlane, toString(MismatchClass::NearFarPlane),
       displayName(MismatchClass::NearFarPlane), rgb255(220, 80, 220)},
      {PixelVisibility::Genuine, toString(MismatchClass::Genuine), displayName(MismatchClass::Genuine),
       rgb255(255, 0, 0)},
  };
  return legend;
}

glm::dvec3 mismatchColor(PixelVisibility v) {
  for (const LegendEntry& e : mismatchLegend())
    if (e.value == v) return e.srgb;
  return glm::dvec3(1.0);
}

std::string cssColor(const glm::dvec3& srgb) {
  char buf[8];
  auto byte = [](double c) { return int(std::lround(std::clamp(c, 0.0, 1.0) * 255.0)); };
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x", byte(srgb.r), byte(srgb.g), byte(srgb.b));
  return buf;
}

void writeMismatchMap(const std::string& path, const VisibilityReport& visibility) {
  FlatImage map(visibility.width, visibility.height);
  for (size_t i = 0; i < visibility.pixels.size(); ++i)
    map.color[i] = linearFromSrgb(mismatchColor(visibility.pixels[i]));
  writePng(path, map);
}

ColorBar writeHeatMap(const std::string& path, int width, int height, const std::vector<float>& values,
                      const std::string& quantity) {
  double hi = 0.0;
  for (float v : values)
    if (std::isfinite(v)) hi = std::max(hi, double(v));
  const ColorBar bar = heatColorBar(quantity, 0.0, hi > 0.0 ? hi : 1.0);
  FlatImage map(width, height);
  for (size_t i = 0; i < values.size(); ++i) map.color[i] = linearFromSrgb(bar.srgbAt(values[i]));
  writePng(path, map);
  return bar;
}

ColorBar writeDifferenceHeatMap(const std::string& path, const FlatImage& a, const FlatImage& b) {
  return writeHeatMap(path, a.width, a.height, colorDifference(a, b), "max |A - B| over RGBA (linear)");
}

ColorBar writeDepthDifferenceMap(const std::string& path, const VisibilityReport& visibility) {
  return writeHeatMap(path, visibility.width, visibility.height, visibility.pixelDepthError,
                      "|ZA - ZB| on agreeing hits (view depth)");
}

}  // namespace rastray
