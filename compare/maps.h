// Diagnostic images of a comparison, and the legend and colour-bar
// definitions the HTML report draws beside them (so the picture and its key
// come from one table).
//
// All colours here are sRGB-encoded display values in [0, 1]; the maps are
// written as 8-bit sRGB PNGs (common/image.h writePng) and reproduce these
// values to the nearest byte.
#pragma once

#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "compare/visibility.h"

namespace rastray {

struct ColorStop {
  double position = 0.0;  // in [0, 1] along the bar
  glm::dvec3 srgb{0.0};
};

// A linear value scale [lo, hi] mapped through colour stops (piecewise
// linear in sRGB; values outside clamp to the ends).
struct ColorBar {
  std::string quantity;  // what the bar measures, e.g. "max |A - B| over RGBA"
  double lo = 0.0, hi = 1.0;
  std::vector<ColorStop> stops;
  // Colour for pixels without a value (NaN), e.g. no agreeing hit for |ΔZ|.
  glm::dvec3 missing{0.0};

  glm::dvec3 srgbAt(double value) const;
  // "linear-gradient(to right, #000004 0%, ...)" for the report's CSS.
  std::string cssGradient() const;
};

// The heat scale: five stops sampled from matplotlib's "inferno"
// (perceptually uniform, dark to bright, readable in grey).
ColorBar heatColorBar(const std::string& quantity, double lo, double hi);

struct LegendEntry {
  PixelVisibility value;
  std::string key;    // machine name: "both-empty", "agree", or toString(MismatchClass)
  std::string label;  // readable
  glm::dvec3 srgb;
};

// Mismatch-map legend in drawing order (mildest first). A pixel shows its
// most severe class (PixelVisibility order).
const std::vector<LegendEntry>& mismatchLegend();
glm::dvec3 mismatchColor(PixelVisibility v);
std::string cssColor(const glm::dvec3& srgb);  // "#rrggbb"

// Writes the visibility-mismatch map (one pixel per image pixel, coloured
// by mismatchLegend). Throws InputError (file: path) when it cannot.
void writeMismatchMap(const std::string& path, const VisibilityReport& visibility);

// Writes a heat map of per-pixel values (NaN: `missing` colour) through
// the bar; returns the bar used. The scale is [0, largest finite value]
// (1 when all are 0 or none is finite), stated in the returned bar.
ColorBar writeHeatMap(const std::string& path, int width, int height, const std::vector<float>& values,
                      const std::string& quantity);

// The colour-difference heat map: max |A − B| over RGBA per pixel.
ColorBar writeDifferenceHeatMap(const std::string& path, const FlatImage& a, const FlatImage& b);
// |ΔZ| on agreeing hits (VisibilityReport::pixelDepthError); pixels without
// an agreeing hit are drawn in the bar's `missing` colour.
ColorBar writeDepthDifferenceMap(const std::string& path, const VisibilityReport& visibility);

}  // namespace rastray
