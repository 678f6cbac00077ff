// HTML pieces every report shares (crossval, stability, sweep, the
// crossover study), so every page looks alike and none needs a network
// resource.
#pragma once

#include <string>

namespace rastray {

// Text escaped for HTML text and attribute values.
std::string escapeHtml(const std::string& s);
// A complete page: the title, the house style (inline), the body as given.
std::string reportPage(const std::string& title, const std::string& body);
// The mismatch-map legend, one swatch per class (compare/maps.h colours).
std::string mismatchLegendHtml();

}  // namespace rastray
