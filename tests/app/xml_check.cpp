#include "xml_check.h"

#include <cctype>
#include <cstddef>

namespace rastray::test {

std::vector<Element> parseXml(const std::string& xml, std::string* error) {
  std::vector<Element> all;
  std::vector<std::size_t> open;  // indices into `all`
  std::size_t i = 0, roots = 0;
  auto fail = [&](const std::string& what) {
    *error = what + " at byte " + std::to_string(i);
    return std::vector<Element>{};
  };
  auto decode = [&](const std::string& raw, std::string* out) -> bool {
    for (std::size_t k = 0; k < raw.size(); ++k) {
      const char c = raw[k];
      if (c == '<') return false;
      if (static_cast<unsigned char>(c) < 0x20 && c != '\n' && c != '\t' && c != '\r') return false;
      if (c != '&') {
        *out += c;
        continue;
      }
      const std::size_t semi = raw.find(';', k);
      if (semi == std::string::npos) return false;
      const std::string ent = raw.substr(k + 1, semi - k - 1);
      static const std::map<std::string, char> named = {
          {"amp", '&'}, {"lt", '<'}, {"gt", '>'}, {"quot", '"'}, {"apos", '\''}};
      if (named.count(ent))
        *out += named.at(ent);
      else if (ent.size() > 1 && ent[0] == '#')
        *out += '?';
      else
        return false;
      k = semi;
    }
    return true;
  };
  auto isNameChar = [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == ':' || c == '.';
  };
  while (i < xml.size()) {
    if (xml[i] != '<') {
      const std::size_t next = xml.find('<', i);
      const std::string raw = xml.substr(i, next == std::string::npos ? std::string::npos : next - i);
      std::string text;
      if (!decode(raw, &text)) return fail("bad character data");
      if (open.empty() && text.find_first_not_of(" \t\r\n") != std::string::npos)
        return fail("text outside the root element");
      if (!open.empty()) all[open.back()].text += text;
      i = next == std::string::npos ? xml.size() : next;
      continue;
    }
    ++i;
    if (i < xml.size() && xml[i] == '/') {  // closing tag
      ++i;
      std::size_t start = i;
      while (i < xml.size() && isNameChar(xml[i])) ++i;
      const std::string name = xml.substr(start, i - start);
      while (i < xml.size() && std::isspace(static_cast<unsigned char>(xml[i]))) ++i;
      if (i >= xml.size() || xml[i] != '>') return fail("bad closing tag");
      ++i;
      if (open.empty() || all[open.back()].name != name) return fail("unbalanced </" + name + ">");
      open.pop_back();
      continue;
    }
    Element e;
    std::size_t start = i;
    while (i < xml.size() && isNameChar(xml[i])) ++i;
    e.name = xml.substr(start, i - start);
    if (e.name.empty()) return fail("empty element name");
    bool selfClosing = false;
    for (;;) {
      while (i < xml.size() && std::isspace(static_cast<unsigned char>(xml[i]))) ++i;
      if (i >= xml.size()) return fail("unterminated tag");
      if (xml[i] == '>') {
        ++i;
        break;
      }
      if (xml[i] == '/') {
        if (i + 1 >= xml.size() || xml[i + 1] != '>') return fail("bad '/'");
        i += 2;
        selfClosing = true;
        break;
      }
      start = i;
      while (i < xml.size() && isNameChar(xml[i])) ++i;
      const std::string attr = xml.substr(start, i - start);
      if (attr.empty() || i >= xml.size() || xml[i] != '=') return fail("bad attribute");
      ++i;
      if (i >= xml.size() || (xml[i] != '"' && xml[i] != '\'')) return fail("unquoted attribute");
      const char q = xml[i++];
      const std::size_t end = xml.find(q, i);
      if (end == std::string::npos) return fail("unterminated attribute");
      std::string value;
      if (!decode(xml.substr(i, end - i), &value)) return fail("bad attribute value");
      if (e.attributes.count(attr)) return fail("duplicate attribute " + attr);
      e.attributes[attr] = value;
      i = end + 1;
    }
    if (open.empty()) {
      if (roots++ > 0) return fail("second root element");
    }
    all.push_back(e);
    if (!selfClosing) open.push_back(all.size() - 1);
  }
  if (!open.empty()) return fail("unclosed <" + all[open.back()].name + ">");
  if (roots != 1) return fail("no root element");
  return all;
}

}  // namespace rastray::test
