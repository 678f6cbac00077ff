#include "app/serve/serve_api.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>

#include "app/engine/render_setup.h"
#include "common/error.h"
#include "common/sampling.h"

namespace rastray::serve {

namespace {

[[noreturn]] void badRequest(const std::string& message) { throw HttpError(400, message); }

// Render options a request may not set: the server decides the thread
// count (renders are serialised on its cores), and explain's pixel is the
// x, y parameters.
bool serverSets(const std::string& option) { return option == "--threads" || option == "--debug-pixel"; }

// The tokens of one render option ("--size", "320", "240"); empty for a
// flag switched off.
std::vector<std::string> optionTokens(const RenderOptionSpec& spec, const std::string& name,
                                      const std::string& value) {
  const int arity = spec.arity;
  if (arity == 0) {
    if (value == "off") return {};
    if (value != "on") badRequest(name + ": '" + value + "': a flag takes on or off");
    return {spec.name};
  }
  // One value is taken whole: it may hold commas of its own (--lights 0,2).
  // Several are one word, as `sweep --vary` writes them: 320x240 (320,240
  // and 320:240 read the same; commas were serve's first syntax).
  std::optional<std::vector<std::string>> tokens = splitOptionValue(value, arity);
  if (!tokens)
    badRequest(name + ": '" + value + "': needs " + std::to_string(arity) + " values joined by 'x' (e.g. " +
               (spec.name == std::string("--size") ? "320x240" : "1x2") + ")");
  tokens->insert(tokens->begin(), spec.name);
  return *tokens;
}

View parseView(const std::string& value) {
  for (View v : {View::Image, View::Mismatch, View::DepthDiff, View::ColorDiff})
    if (value == toString(v)) return v;
  badRequest("view: '" + value + "' is not one of image, mismatch, depth-diff, color-diff");
}

// A pixel coordinate: a decimal integer in [0, 16384) (the CLI's largest
// image side); explain itself refuses a pixel outside the image.
int parsePixel(const std::string& name, const std::string& value) {
  char* end = nullptr;
  const long v = value.empty() || value.size() > 6 ? -1 : std::strtol(value.c_str(), &end, 10);
  if (v < 0 || v >= 16384 || (end && *end != '\0') || !std::isdigit(static_cast<unsigned char>(value[0])))
    badRequest(name + ": '" + value + "' is not a pixel coordinate (0 to 16383)");
  return int(v);
}

uint64_t parseSeq(const std::string& value) {
  char* end = nullptr;
  const unsigned long long v = std::strtoull(value.c_str(), &end, 10);
  if (value.empty() || value.size() > 19 || *end != '\0' ||
      !std::isdigit(static_cast<unsigned char>(value[0])))
    badRequest("seq: '" + value + "' is not a request number");
  return v;
}

// The request's own parameters (not render options); false when `name`
// is none of them.
bool takeServerParameter(RequestParameters& r, Endpoint endpoint, const std::string& name,
                         const std::string& value, std::string& renderer) {
  if (name == "scene") {
    r.scene = value;
  } else if (name == "view" && endpoint == Endpoint::Frame) {
    r.view = parseView(value);
  } else if (name == "pair" && endpoint == Endpoint::Frame) {
    if (value != "raster" && value != "hybrid")
      badRequest("pair: '" + value + "' is not one of raster, hybrid");
    r.pair = value;
  } else if ((name == "x" || name == "y") && endpoint == Endpoint::Explain) {
    (name == "x" ? r.x : r.y) = parsePixel(name, value);
  } else if (name == "png" && endpoint == Endpoint::Frame) {
    if (value != "quick" && value != "small") badRequest("png: '" + value + "' is not one of quick, small");
    r.quickPng = value == "quick";
  } else if (name == "client") {
    if (value.size() > 64) badRequest("client: longer than 64 characters");
    r.client = value;
  } else if (name == "seq") {
    r.seq = parseSeq(value);
  } else if (name == "renderer") {
    renderer = value;
  } else {
    return false;
  }
  return true;
}

void checkCombination(const RequestParameters& r, Endpoint endpoint, const std::string& renderer,
                      bool pairGiven) {
  if (r.scene.empty()) badRequest("scene: missing (one of /api/scenes)");
  if (endpoint == Endpoint::Explain && (r.x < 0 || r.y < 0))
    badRequest("x, y: the pixel to explain is missing");
  if (!renderer.empty() && r.allRenderers())
    badRequest(
        std::string("renderer: ") +
        (endpoint == Endpoint::Explain ? "explain" : "the " + std::string(toString(r.view)) + " view") +
        " runs every renderer, as crossval does");
  if (pairGiven && r.view == View::Image) badRequest("pair: only the maps compare a pair of renderers");
  if (r.quickPng && r.view != View::Image) badRequest("png: only the image view's PNG can be quick");
}

}  // namespace

const char* toString(View view) {
  switch (view) {
    case View::Image:
      return "image";
    case View::Mismatch:
      return "mismatch";
    case View::DepthDiff:
      return "depth-diff";
    case View::ColorDiff:
      return "color-diff";
  }
  return "?";
}

RequestParameters parseRequest(const QueryParameters& query, Endpoint endpoint) {
  RequestParameters r;
  r.endpoint = endpoint;
  std::string renderer;
  std::map<const RenderOptionSpec*, std::vector<std::string>> options;
  std::string previous;
  bool pairGiven = false;
  for (const auto& [name, value] : query) {
    if (name == previous) badRequest(name + ": given more than once");
    previous = name;  // a multimap: equal names are adjacent
    pairGiven |= name == "pair";
    if (takeServerParameter(r, endpoint, name, value, renderer)) continue;
    const RenderOptionSpec* spec = findRenderOption("--" + name);
    if (!spec) badRequest("unknown parameter '" + name + "'");
    if (serverSets(spec->name))
      badRequest(name + ": set by the server" +
                 std::string(name == "threads" ? " (renders share its cores one at a time)"
                                               : " (x and y name the pixel)"));
    options[spec] = optionTokens(*spec, name, value);
  }
  checkCombination(r, endpoint, renderer, pairGiven);
  if (!r.allRenderers()) r.renderArgs = {"--renderer", renderer.empty() ? "raster" : renderer};
  for (const RenderOptionSpec& spec : renderOptionTable()) {
    const auto it = options.find(&spec);
    if (it != options.end()) r.renderArgs.insert(r.renderArgs.end(), it->second.begin(), it->second.end());
  }
  return r;
}

RenderSettings renderSettings(const RequestParameters& request) {
  try {
    return renderSettingsFrom(request.renderArgs, request.allRenderers());
  } catch (const InputError& e) {
    // The command's message, naming the parameter as the request does.
    const std::string& element = e.element();
    badRequest((element.rfind("--", 0) == 0 ? element.substr(2) : element) + ": " + e.message());
  }
}

std::string shellQuote(const std::string& word) {
  const bool plain = !word.empty() && std::all_of(word.begin(), word.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) ||
           std::string("_./:=,+-").find(c) != std::string::npos;
  });
  if (plain) return word;
  std::string out = "'";
  for (const char c : word) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string commandLine(const RequestParameters& r, Endpoint endpoint) {
  std::vector<std::string> words = {"rastray"};
  if (endpoint == Endpoint::Explain) {
    words.insert(words.end(), {"explain", r.scene, std::to_string(r.x), std::to_string(r.y)});
  } else {
    words.insert(words.end(), {r.view == View::Image ? "render" : "crossval", r.scene});
  }
  words.insert(words.end(), r.renderArgs.begin(), r.renderArgs.end());
  if (endpoint == Endpoint::Frame) {
    if (r.view == View::Image)
      words.insert(words.end(), {"-o", "render.png"});
    else
      words.insert(words.end(), {"--report", "report"});
  }
  std::string line;
  for (const std::string& w : words) line += (line.empty() ? "" : " ") + shellQuote(w);
  return line;
}

namespace {

std::string queryDefault(const RenderOptionSpec& spec) {
  std::string text = defaultText(spec);
  std::replace(text.begin(), text.end(), ' ', ',');
  return text;
}

// Which options apply under each setting of what the table's conditions
// read (--shadows, --wireframe), per renderer and for all of them at once
// (the views that run every renderer), decided by RenderSettings::applies:
// the page looks its answer up rather than re-deriving the rules. A
// --shadows value a renderer refuses is marked invalid with the command
// line's message; what applies then is what applies without it, since the
// page leaves the refused value out of its requests.
nlohmann::ordered_json applicabilityJson() {
  nlohmann::ordered_json out = nlohmann::ordered_json::array();
  std::vector<std::string> shadowValues = {""};  // "": not given
  for (const std::string& v : shadowModeNames()) shadowValues.push_back(v);
  const std::vector<std::pair<std::string, std::optional<RendererKind>>> targets = {
      {"raster", RendererKind::Raster},
      {"raytrace", RendererKind::Raytrace},
      {"hybrid", RendererKind::Hybrid},
      {"all", std::nullopt}};
  for (const auto& [target, kind] : targets)
    for (const std::string& shadows : shadowValues)
      for (const bool wireframe : {false, true}) {
        const auto settings = [&](bool withShadows) {
          std::vector<std::string> args;
          if (kind) args = {"--renderer", target};
          if (withShadows && !shadows.empty()) args.insert(args.end(), {"--shadows", shadows});
          RenderSettings s = renderSettingsFrom(args, !kind);
          s.raster.wireframe = wireframe;  // a condition, not an option given
          return s;
        };
        std::string error;
        RenderSettings s;
        try {
          s = settings(true);
        } catch (const InputError& e) {
          error = e.what();
          s = settings(false);
        }
        nlohmann::ordered_json applying = nlohmann::ordered_json::array();
        for (const RenderOptionSpec& spec : renderOptionTable()) {
          if (serverSets(spec.name)) continue;
          const bool applies = kind ? s.applies(spec, *kind)
                                    : s.applies(spec, RendererKind::Raster) ||
                                          s.applies(spec, RendererKind::Raytrace) ||
                                          s.applies(spec, RendererKind::Hybrid);
          if (applies) applying.push_back(std::string(spec.name).substr(2));
        }
        out.push_back({{"renderer", target},
                       {"shadows", shadows},
                       {"wireframe", wireframe},
                       {"valid", error.empty()},
                       {"error", error},
                       {"applies", applying}});
      }
  return out;
}

}  // namespace

nlohmann::ordered_json optionTableJson() {
  nlohmann::ordered_json options = nlohmann::ordered_json::array();
  for (const RenderOptionSpec& spec : renderOptionTable()) {
    if (serverSets(spec.name)) continue;
    nlohmann::ordered_json renderers = nlohmann::ordered_json::array();
    for (RendererKind kind : {RendererKind::Raster, RendererKind::Raytrace, RendererKind::Hybrid})
      if (spec.renderers & rendererBit(kind)) renderers.push_back(toString(kind));
    const char* condition = spec.condition == OptionCondition::ShadowMaps  ? "shadow-maps"
                            : spec.condition == OptionCondition::Wireframe ? "wireframe"
                                                                           : "always";
    options.push_back({{"name", std::string(spec.name).substr(2)},
                       {"values", spec.arity},
                       {"renderers", renderers},
                       {"condition", condition},
                       {"applies", describeWhereApplies(spec)},
                       {"help", helpWithWhere(spec)},
                       // In the query's own form: multiple values joined by commas, as the page writes them.
                       {"default", queryDefault(spec)}});
  }
  nlohmann::ordered_json spp = nlohmann::ordered_json::array();
  for (int n = 1; n <= 256; ++n)
    if (isSupportedSampleCount(n)) spp.push_back(n);
  return {{"schema", "rastray.serve.options"},
          {"version", 1},
          {"options", options},
          {"sppValues", spp},
          {"applicability", applicabilityJson()}};
}

namespace {

std::optional<std::string> valueOf(const TraceEvent& e, const std::string& name) {
  for (const auto& [n, v] : e.values)
    if (n == name) return v;
  return std::nullopt;
}

// traceVector's "(x, y, z)" and traceNumber's "%.9g" (9 significant
// digits: the drawing is exact to far below a pixel).
std::optional<glm::dvec3> vectorOf(const TraceEvent& e, const std::string& name) {
  const auto text = valueOf(e, name);
  glm::dvec3 v;
  if (!text || std::sscanf(text->c_str(), "(%lf, %lf, %lf)", &v.x, &v.y, &v.z) != 3) return std::nullopt;
  return v;
}

std::optional<double> numberOf(const TraceEvent& e, const std::string& name) {
  const auto text = valueOf(e, name);
  if (!text) return std::nullopt;
  return std::strtod(text->c_str(), nullptr);
}

glm::dvec3 toView(const Camera& c, const glm::dvec3& p) {
  return glm::dvec3(c.viewFromWorld * glm::dvec4(p, 1.0));
}

// View space to image pixels (Camera::ndcScale's convention).
glm::dvec2 imageOf(const Camera& c, const glm::dvec3& v) {
  const glm::dvec2 s = c.ndcScale();
  const double depth = c.projection == Projection::Perspective ? -v.z : 1.0;
  return c.imageFromNdc({v.x / (s.x * depth), v.y / (s.y * depth)});
}

// Keeps the part of view-space segment [a, b] in front of the near plane
// (perspective); false when none is.
bool clipToNear(const Camera& c, glm::dvec3& a, glm::dvec3& b) {
  if (c.projection != Projection::Perspective) return true;
  const double da = -a.z, db = -b.z, zn = c.znear;
  if (da < zn && db < zn) return false;
  if (da < zn) a += (b - a) * ((zn - da) / (db - da));
  if (db < zn) b += (a - b) * ((zn - db) / (da - db));
  return true;
}

}  // namespace

nlohmann::ordered_json rayOverlayJson(const Camera& camera, const std::vector<TraceEvent>& events,
                                      double sceneSize) {
  nlohmann::ordered_json rays = nlohmann::ordered_json::array();
  const double far = 4.0 * (sceneSize > 0.0 && std::isfinite(sceneSize) ? sceneSize : 1.0);
  for (const TraceEvent& e : events) {
    if (e.stage != TraceStage::Ray) continue;
    const auto origin = vectorOf(e, "origin"), dir = vectorOf(e, "dir");
    const auto tNear = numberOf(e, "tnear"), tFar = numberOf(e, "tfar"), tHit = numberOf(e, "t");
    if (!origin || !dir || !tNear || !tFar) continue;
    // To the hit; else to the end of the range, a far point standing in for
    // an infinite one (a miss, a directional light).
    double tEnd = tHit ? *tHit : std::min(*tFar, *tNear + far);
    if (!std::isfinite(tEnd)) tEnd = *tNear + far;
    glm::dvec3 a = toView(camera, *origin + *dir * *tNear), b = toView(camera, *origin + *dir * tEnd);
    if (!clipToNear(camera, a, b)) continue;
    const glm::dvec2 from = imageOf(camera, a), to = imageOf(camera, b);
    rays.push_back({{"sample", e.sample},
                    {"kind", valueOf(e, "kind").value_or("?")},
                    {"depth", e.depth},
                    {"outcome", e.outcome},
                    {"from", {from.x, from.y}},
                    {"to", {to.x, to.y}}});
  }
  return rays;
}

std::string base64(const std::string& bytes) {
  static const char* kDigits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const size_t n = std::min<size_t>(3, bytes.size() - i);
    uint32_t group = 0;
    for (size_t k = 0; k < 3; ++k)
      group = (group << 8) | (k < n ? static_cast<unsigned char>(bytes[i + k]) : 0u);
    for (size_t k = 0; k < 4; ++k) out += k <= n ? kDigits[(group >> (18 - 6 * k)) & 63] : '=';
  }
  return out;
}

}  // namespace rastray::serve
