// A strict, small XML well-formedness checker for the report tests (SVG
// plots, HTML-embedded SVG): enough for what app/report/svg_plot.cpp writes.
#pragma once

#include <map>
#include <string>
#include <vector>

namespace rastray::test {

// One element as the checker saw it.
struct Element {
  std::string name;
  std::map<std::string, std::string> attributes;
  std::string text;  // direct character data, entities decoded
};

// A strict subset of XML 1.0, enough for what the module writes: elements
// with quoted attributes (no duplicates), character data with the five
// predefined and numeric entities, no comments, CDATA or processing
// instructions. On anything else sets *error (what and the byte offset) and
// returns nothing; otherwise every element in document order.
std::vector<Element> parseXml(const std::string& xml, std::string* error);

}  // namespace rastray::test
