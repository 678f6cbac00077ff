#include "app/engine/render_options.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iterator>

#include "common/error.h"
#include "common/sampling.h"

namespace rastray {

namespace {

using Values = std::vector<std::string>;

[[noreturn]] void badOption(const std::string& option, const std::string& message) {
  throw InputError("command line", option, message);
}

// --- Parsing and formatting of values -------------------------------------

// A decimal integer in [lo, hi] (an optional sign, digits, nothing else).
int parseInt(const std::string& option, const std::string& text, long lo, long hi) {
  errno = 0;
  char* end = nullptr;
  const long v = text.empty() ? 0 : std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno == ERANGE || std::isspace(static_cast<unsigned char>(text[0])))
    badOption(option, "'" + text + "' is not an integer");
  if (v < lo || v > hi)
    badOption(option, "'" + text + "' is not in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return int(v);
}

// A decimal number ("inf" too: --zfar inf); NaN is refused.
double parseDouble(const std::string& option, const std::string& text) {
  char* end = nullptr;
  const double v = text.empty() ? 0.0 : std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || std::isnan(v) || std::isspace(static_cast<unsigned char>(text[0])))
    badOption(option, "'" + text + "' is not a number");
  return v;
}

double parseDoubleIn(const std::string& option, const std::string& text, double lo, double hi) {
  const double v = parseDouble(option, text);
  if (!(v >= lo && v <= hi)) {
    char range[64];
    std::snprintf(range, sizeof range, "[%g, %g]", lo, hi);
    badOption(option, "'" + text + "' is not in " + range);
  }
  return v;
}

// The shortest decimal that reads back as the same double (or float):
// toArgs must give back the same settings, bit for bit.
std::string formatDouble(double v) {
  char buf[40];
  for (int precision = 1; precision <= 17; ++precision) {
    std::snprintf(buf, sizeof buf, "%.*g", precision, v);
    if (std::strtod(buf, nullptr) == v) break;
  }
  return buf;
}
std::string formatFloat(float v) {
  char buf[40];
  for (int precision = 1; precision <= 9; ++precision) {
    std::snprintf(buf, sizeof buf, "%.*g", precision, double(v));
    if (std::strtof(buf, nullptr) == v) break;
  }
  return buf;
}

template <typename Enum>
struct Choice {
  const char* name;
  Enum value;
};

template <typename Enum, size_t N>
Enum pick(const std::string& option, const std::string& value, const Choice<Enum> (&choices)[N]) {
  std::string names;
  for (const auto& c : choices) {
    if (value == c.name) return c.value;
    names += (names.empty() ? "" : ", ") + std::string(c.name);
  }
  badOption(option, "'" + value + "' is not one of " + names);
}

template <typename Enum, size_t N>
std::string nameOf(Enum value, const Choice<Enum> (&choices)[N]) {
  for (const auto& c : choices)
    if (c.value == value) return c.name;
  return "?";
}

constexpr Choice<RendererKind> kRendererChoices[] = {
    {"raster", RendererKind::Raster}, {"raytrace", RendererKind::Raytrace}, {"hybrid", RendererKind::Hybrid}};
constexpr Choice<TextureFilter> kTextureFilters[] = {{"sampler", TextureFilter::Sampler},
                                                     {"nearest", TextureFilter::Nearest},
                                                     {"bilinear", TextureFilter::Bilinear},
                                                     {"trilinear", TextureFilter::Trilinear}};
constexpr Choice<RenderOrigin> kOrigins[] = {{"camera", RenderOrigin::Camera},
                                             {"world", RenderOrigin::World}};
constexpr Choice<RayOffsetMethod> kRayOffsets[] = {{"error-bound", RayOffsetMethod::ErrorBound},
                                                   {"float-ulps", RayOffsetMethod::FloatUlps}};
constexpr Choice<ShadowTerminator> kTerminators[] = {{"shading-normal", ShadowTerminator::ShadingNormal},
                                                     {"none", ShadowTerminator::None}};
constexpr Choice<CullMode> kCullModes[] = {
    {"none", CullMode::None}, {"back", CullMode::Back}, {"front", CullMode::Front}};
constexpr Choice<ShadowMode> kShadowModes[] = {
    {"map", ShadowMode::Map}, {"rays", ShadowMode::Rays}, {"none", ShadowMode::None}};
// --depth-format: common/depth_formula.h spells the formats.
DepthFormat parseDepthFormatOption(const std::string& value) {
  if (const std::optional<DepthFormat> format = parseDepthFormat(value)) return *format;
  badOption("--depth-format", "'" + value + "' is not one of float-reversed, float, unorm24, unorm16");
}
constexpr Choice<DepthFunc> kDepthFuncs[] = {{"less", DepthFunc::Less}, {"lequal", DepthFunc::LEqual}};
constexpr Choice<ShadingRate> kShadingRates[] = {{"sample", ShadingRate::Sample},
                                                 {"pixel", ShadingRate::Pixel}};

// --lights: nullopt for "all", else the indices to keep (sorted, unique;
// empty for "none"). Checked against the scene by selectLights.
std::optional<std::vector<size_t>> parseLightList(const std::string& value) {
  if (value == "all") return std::nullopt;
  std::vector<size_t> kept;
  if (value == "none") return kept;
  size_t start = 0;
  while (start <= value.size()) {
    const size_t end = std::min(value.find(',', start), value.size());
    const std::string item = value.substr(start, end - start);
    // At most 9 digits: no scene holds a billion lights, and stoul cannot overflow.
    if (item.empty() || item.size() > 9 ||
        !std::all_of(item.begin(), item.end(), [](char c) { return c >= '0' && c <= '9'; }))
      badOption("--lights", "'" + value + "' is not all, none or comma-separated light indices (e.g. 0,2)");
    kept.push_back(std::stoul(item));
    start = end + 1;
  }
  std::sort(kept.begin(), kept.end());
  kept.erase(std::unique(kept.begin(), kept.end()), kept.end());
  return kept;
}

std::string formatLightList(const std::optional<std::vector<size_t>>& kept) {
  if (!kept) return "all";
  if (kept->empty()) return "none";
  std::string out;
  for (size_t i : *kept) out += (out.empty() ? "" : ",") + std::to_string(i);
  return out;
}

void parseTransparency(RenderSettings& s, const std::string& value) {
  if (value == "sorted") {
    s.raster.transparency = TransparencyMode::Sorted;
  } else if (value == "exact") {
    s.raster.transparency = TransparencyMode::Exact;
  } else if (value.rfind("peel:", 0) == 0) {
    const std::string count = value.substr(5);
    const bool digits = !count.empty() && count.size() <= 9 &&
                        std::all_of(count.begin(), count.end(), [](char c) { return c >= '0' && c <= '9'; });
    if (!digits) badOption("--transparency", "'" + value + "': peel needs a layer count, e.g. peel:8");
    const long layers = std::stol(count);
    if (layers < 1 || layers > 1024) badOption("--transparency", "peel layer count must lie in [1, 1024]");
    s.raster.transparency = TransparencyMode::Peel;
    s.raster.peelLayers = int(layers);
  } else {
    badOption("--transparency", "'" + value + "' is not one of sorted, peel:N, exact");
  }
}

std::string formatTransparency(const RasterOptions& r) {
  switch (r.transparency) {
    case TransparencyMode::Sorted:
      return "sorted";
    case TransparencyMode::Exact:
      return "exact";
    case TransparencyMode::Peel:
      return "peel:" + std::to_string(r.peelLayers);
  }
  return "?";
}

Values formatVec(const std::vector<double>& v) {
  Values out;
  for (double x : v) out.push_back(formatDouble(x));
  return out;
}

std::vector<double> parseVec3(const std::string& option, const Values& values) {
  std::vector<double> v;
  for (const std::string& t : values) v.push_back(parseDouble(option, t));
  return v;
}

// --- The table --------------------------------------------------------------

constexpr RendererKind kRendererKinds[] = {RendererKind::Raster, RendererKind::Raytrace,
                                           RendererKind::Hybrid};
constexpr RendererSet kRaytrace = rendererBit(RendererKind::Raytrace);
constexpr RendererSet kHybrid = rendererBit(RendererKind::Hybrid);
constexpr RendererSet kRaster = rendererBit(RendererKind::Raster);
// Rasterized primary visibility: the rasterizer alone and hybrid.
constexpr RendererSet kRasterized = kRaster | kHybrid;
// Traced rays beyond the primary hit (secondary and shadow rays): the ray
// caster and hybrid; the rasterizer alone traces none.
constexpr RendererSet kTraced = kRaytrace | kHybrid;

// A row's parser and formatter as lambdas over the settings `s` and the
// option's values `v`.
#define RASTRAY_PARSE(...) [](RenderSettings& s, const Values& v) { __VA_ARGS__; }
#define RASTRAY_FORMAT(...) [](const RenderSettings& s) -> Values { __VA_ARGS__; }
#define RASTRAY_NO_VALUE RASTRAY_FORMAT((void)s; return {})

const std::vector<RenderOptionSpec> kRenderOptions = {
    // Camera (SPEC §2): info and compare take these rows too.
    {"--camera", kAllRenderers, OptionCondition::Always,
     "The file's camera N (camera nodes in walk order, as `info` lists them; default the first); --eye "
     "etc. apply on top",
     1, "0", RASTRAY_PARSE(s.camera.camera = parseInt("--camera", v[0], 0, 1 << 30)),
     RASTRAY_FORMAT(if (s.camera.camera < 0) return {}; return {std::to_string(s.camera.camera)})},
    {"--eye", kAllRenderers, OptionCondition::Always, "Camera position X Y Z (world space)", 3, "0 0 3",
     RASTRAY_PARSE(s.camera.eye = parseVec3("--eye", v)), RASTRAY_FORMAT(return formatVec(s.camera.eye))},
    {"--target", kAllRenderers, OptionCondition::Always, "Point the camera looks at, X Y Z", 3, "0 0 0",
     RASTRAY_PARSE(s.camera.target = parseVec3("--target", v)),
     RASTRAY_FORMAT(return formatVec(s.camera.target))},
    {"--up", kAllRenderers, OptionCondition::Always, "Camera up vector X Y Z", 3, "0 1 0",
     RASTRAY_PARSE(s.camera.up = parseVec3("--up", v)), RASTRAY_FORMAT(return formatVec(s.camera.up))},
    {"--yfov", kAllRenderers, OptionCondition::Always, "Vertical field of view in degrees (perspective)", 1,
     "40", RASTRAY_PARSE(s.camera.yfov = parseDouble("--yfov", v[0])),
     RASTRAY_FORMAT(if (!s.camera.yfov) return {}; return {formatDouble(*s.camera.yfov)})},
    {"--znear", kAllRenderers, OptionCondition::Always, "Near plane distance", 1, "0.1",
     RASTRAY_PARSE(s.camera.znear = parseDouble("--znear", v[0])),
     RASTRAY_FORMAT(if (!s.camera.znear) return {}; return {formatDouble(*s.camera.znear)})},
    {"--zfar", kAllRenderers, OptionCondition::Always, "Far plane distance ('inf' for none)", 1, "100",
     RASTRAY_PARSE(s.camera.zfar = parseDouble("--zfar", v[0])),
     RASTRAY_FORMAT(if (!s.camera.zfar) return {}; return {formatDouble(*s.camera.zfar)})},
    {"--size", kAllRenderers, OptionCondition::Always, "Image width and height in pixels (WIDTH HEIGHT)", 2,
     "8 6",
     RASTRAY_PARSE(s.camera.size = {parseInt("--size", v[0], 1, kMaxImageSide),
                                    parseInt("--size", v[1], 1, kMaxImageSide)}),
     RASTRAY_FORMAT(return {std::to_string(s.camera.width()), std::to_string(s.camera.height())})},
    // The pose (common/gltf/animation.h): the scene is flattened at it.
    {"--time", kAllRenderers, OptionCondition::Always,
     "Play the file's animations to this time in seconds (clamped to each animation's keys; `info` lists "
     "their durations); not given, none plays",
     1, "0.5", RASTRAY_PARSE(s.pose.time = parseDoubleIn("--time", v[0], -1e9, 1e9)),
     RASTRAY_FORMAT(if (!s.pose.time) return {}; return {formatDouble(*s.pose.time)})},
    {"--animation", kAllRenderers, OptionCondition::Always,
     "Which animation --time plays: all, or its index as `info` lists it", 1, "0",
     RASTRAY_PARSE(s.pose.animation = v[0] == "all" ? -1 : parseInt("--animation", v[0], 0, 1 << 30)),
     RASTRAY_FORMAT(return {s.pose.animation < 0 ? "all" : std::to_string(s.pose.animation)})},
    // Every renderer.
    {"--spp", kAllRenderers, OptionCondition::Always, "Samples per pixel", 1, "4",
     RASTRAY_PARSE(s.spp = parseInt("--spp", v[0], INT32_MIN, INT32_MAX)),
     RASTRAY_FORMAT(return {std::to_string(s.spp)})},
    {"--exposure", kAllRenderers, OptionCondition::Always,
     "Scale the image's colour by 2^EV, in stops (premultiplied RGB; alpha, depth and IDs unchanged)", 1, "1",
     RASTRAY_PARSE(s.exposure = parseDoubleIn("--exposure", v[0], -64.0, 64.0)),
     RASTRAY_FORMAT(return {formatDouble(s.exposure)})},
    {"--threads", kAllRenderers, OptionCondition::Always, "Worker threads (0: all cores)", 1, "1",
     RASTRAY_PARSE(s.threads = parseInt("--threads", v[0], 0, 1024)),
     RASTRAY_FORMAT(return {std::to_string(s.threads)})},
    {"--debug-pixel", kAllRenderers, OptionCondition::Always,
     "Trace what each stage did at pixel X Y (stderr)", 2, "1 1",
     RASTRAY_PARSE(s.debugPixel = glm::ivec2(parseInt("--debug-pixel", v[0], INT32_MIN, INT32_MAX),
                                             parseInt("--debug-pixel", v[1], INT32_MIN, INT32_MAX))),
     RASTRAY_FORMAT(if (!s.debugPixel) return {};
                    return {std::to_string(s.debugPixel->x), std::to_string(s.debugPixel->y)})},
    {"--max-memory", kAllRenderers, OptionCondition::Always,
     "Refuse (exit 2) work whose estimated peak memory exceeds this: bytes or K, M, G, T (default: 80% of "
     "physical memory)",
     1, "8G", RASTRAY_PARSE(s.memory = MemoryBudget::parse(v[0])),
     RASTRAY_FORMAT(if (!s.isGiven("--max-memory")) return {}; return {std::to_string(s.memory.bytes)})},
    {"--texture-filter", kAllRenderers, OptionCondition::Always,
     "sampler (as the file says), nearest, bilinear or trilinear", 1, "nearest",
     RASTRAY_PARSE(s.shading.textureFilter = pick("--texture-filter", v[0], kTextureFilters)),
     RASTRAY_FORMAT(return {nameOf(s.shading.textureFilter, kTextureFilters)})},
    {"--origin", kAllRenderers, OptionCondition::Always,
     "camera (rebase the scene on the eye before rounding to float) or world (no rebasing)", 1, "world",
     RASTRAY_PARSE(s.renderOrigin = pick("--origin", v[0], kOrigins)),
     RASTRAY_FORMAT(return {nameOf(s.renderOrigin, kOrigins)})},
    {"--lights", kAllRenderers, OptionCondition::Always,
     "Lights to keep: all, none, or indices as `info` lists them, e.g. 0,2 (none left: the eye light)", 1,
     "none", RASTRAY_PARSE(s.keptLights = parseLightList(v[0])),
     RASTRAY_FORMAT(return {formatLightList(s.keptLights)})},
    {"--cull", kAllRenderers, OptionCondition::Always, "Cull single-sided triangles: back, front or none", 1,
     "back", RASTRAY_PARSE(s.cull = pick("--cull", v[0], kCullModes)),
     RASTRAY_FORMAT(return {nameOf(s.cull, kCullModes)})},
    {"--shadows", kAllRenderers, OptionCondition::Always,
     "map (shadow maps: raster, hybrid), rays (raytrace, hybrid) or none (every renderer); default map, "
     "rays for raytrace and hybrid",
     1, "", RASTRAY_PARSE(s.shadows = pick("--shadows", v[0], kShadowModes)),
     RASTRAY_FORMAT(if (!s.shadows) return {}; return {nameOf(*s.shadows, kShadowModes)})},
    // Rasterized primary visibility.
    {"--depth-format", kRasterized, OptionCondition::Always, "float-reversed, float, unorm24 or unorm16", 1,
     "unorm24", RASTRAY_PARSE(s.raster.depthFormat = parseDepthFormatOption(v[0])),
     RASTRAY_FORMAT(return {toString(s.raster.depthFormat)})},
    {"--depth-func", kRasterized, OptionCondition::Always, "less or lequal", 1, "lequal",
     RASTRAY_PARSE(s.raster.depthFunc = pick("--depth-func", v[0], kDepthFuncs)),
     RASTRAY_FORMAT(return {nameOf(s.raster.depthFunc, kDepthFuncs)})},
    {"--polygon-offset", kRasterized, OptionCondition::Always, "FACTOR UNITS, as glPolygonOffset", 2, "1 1",
     RASTRAY_PARSE(s.raster.polygonOffsetFactor = float(parseDouble("--polygon-offset", v[0]));
                   s.raster.polygonOffsetUnits = float(parseDouble("--polygon-offset", v[1]))),
     RASTRAY_FORMAT(
         return {formatFloat(s.raster.polygonOffsetFactor), formatFloat(s.raster.polygonOffsetUnits)})},
    {"--transparency", kRasterized, OptionCondition::Always,
     "sorted, peel:N or exact (per-sample fragment lists)", 1, "sorted",
     RASTRAY_PARSE(parseTransparency(s, v[0])), RASTRAY_FORMAT(return {formatTransparency(s.raster)})},
    {"--shading-rate", kRasterized, OptionCondition::Always,
     "sample (shade every sample) or pixel (once per pixel and triangle, as MSAA)", 1, "pixel",
     RASTRAY_PARSE(s.raster.shadingRate = pick("--shading-rate", v[0], kShadingRates)),
     RASTRAY_FORMAT(return {nameOf(s.raster.shadingRate, kShadingRates)})},
    {"--wireframe", kRasterized, OptionCondition::Always, "Draw visible triangle edges over the image", 0, "",
     RASTRAY_PARSE((void)v; s.raster.wireframe = true), RASTRAY_NO_VALUE},
    {"--halo", kRasterized, OptionCondition::Wireframe, "Gap each edge where a nearer edge crosses it", 0, "",
     RASTRAY_PARSE((void)v; s.raster.halo = true), RASTRAY_NO_VALUE},
    {"--shadow-map-size", kRasterized, OptionCondition::ShadowMaps, "Shadow map resolution", 1, "64",
     RASTRAY_PARSE(s.raster.shadowMapSize = parseInt("--shadow-map-size", v[0], 16, 16384)),
     RASTRAY_FORMAT(return {std::to_string(s.raster.shadowMapSize)})},
    {"--shadow-bias", kRasterized, OptionCondition::ShadowMaps, "CONSTANT SLOPE shadow-map depth bias", 2,
     "1 1",
     RASTRAY_PARSE(s.raster.shadowBiasConstant = float(parseDouble("--shadow-bias", v[0]));
                   s.raster.shadowBiasSlope = float(parseDouble("--shadow-bias", v[1]))),
     RASTRAY_FORMAT(
         return {formatFloat(s.raster.shadowBiasConstant), formatFloat(s.raster.shadowBiasSlope)})},
    // Traced rays.
    {"--max-depth", kTraced, OptionCondition::Always, "Deepest secondary ray (reflection/refraction)", 1, "4",
     RASTRAY_PARSE(s.shading.maxDepth = parseInt("--max-depth", v[0], 0, 64)),
     RASTRAY_FORMAT(return {std::to_string(s.shading.maxDepth)})},
    {"--no-reflection", kTraced, OptionCondition::Always,
     "Trace no reflection ray (mirror or Fresnel); that part of the colour is black", 0, "",
     RASTRAY_PARSE((void)v; s.shading.reflection = false), RASTRAY_NO_VALUE},
    {"--no-refraction", kTraced, OptionCondition::Always,
     "Trace no refraction ray; that part of the colour is black", 0, "",
     RASTRAY_PARSE((void)v; s.shading.refraction = false), RASTRAY_NO_VALUE},
    {"--transparency-cutoff", kTraced, OptionCondition::Always,
     "Stop compositing along a ray once the remaining transmittance is below this", 1, "0.01",
     RASTRAY_PARSE(s.ray.transparencyCutoff = float(parseDoubleIn("--transparency-cutoff", v[0], 0.0, 1.0))),
     RASTRAY_FORMAT(return {formatFloat(s.ray.transparencyCutoff)})},
    {"--ray-offset", kTraced, OptionCondition::Always,
     "error-bound (from the hit's triangle, pbrt-v4) or float-ulps (from the hit point, Ray Tracing Gems "
     "ch. 6): where secondary and shadow rays start",
     1, "float-ulps", RASTRAY_PARSE(s.ray.offset = pick("--ray-offset", v[0], kRayOffsets)),
     RASTRAY_FORMAT(return {nameOf(s.ray.offset, kRayOffsets)})},
    {"--terminator", kTraced, OptionCondition::Always,
     "shading-normal (lift ray origins towards the smooth surface the vertex normals describe, Hanika "
     "2021) or none (start on the flat triangle: low-poly smooth meshes show facets in shadow edges)",
     1, "none", RASTRAY_PARSE(s.ray.terminator = pick("--terminator", v[0], kTerminators)),
     RASTRAY_FORMAT(return {nameOf(s.ray.terminator, kTerminators)})},
    // Traced primary rays.
    {"--no-packets", kRaytrace, OptionCondition::Always,
     "Trace primary rays one by one instead of in coherent packets", 0, "",
     RASTRAY_PARSE((void)v; s.ray.packets = false), RASTRAY_NO_VALUE},
    {"--no-shadow-packets", kTraced, OptionCondition::Always,
     "Trace shadow rays one to a packet instead of a kernel block's lit lanes 14 at a time (same pictures)",
     0, "", RASTRAY_PARSE((void)v; s.ray.shadowPackets = false), RASTRAY_NO_VALUE},
};

#undef RASTRAY_PARSE
#undef RASTRAY_FORMAT
#undef RASTRAY_NO_VALUE

// "raster", "raster and hybrid", "raster, raytrace and hybrid".
std::string describeRenderers(RendererSet set) {
  std::vector<std::string> names;
  for (RendererKind kind : kRendererKinds)
    if (set & rendererBit(kind)) names.push_back(toString(kind));
  std::string out;
  for (size_t i = 0; i < names.size(); ++i)
    out += (i == 0 ? "" : i + 1 == names.size() ? " and " : ", ") + names[i];
  return out;
}

std::string join(const Values& values) {
  std::string out;
  for (const std::string& v : values) out += (out.empty() ? "" : " ") + v;
  return out;
}

}  // namespace

const char* toString(RendererKind kind) {
  switch (kind) {
    case RendererKind::Raster:
      return "raster";
    case RendererKind::Raytrace:
      return "raytrace";
    case RendererKind::Hybrid:
      return "hybrid";
  }
  return "?";
}

std::optional<RendererKind> parseRendererKind(const std::string& name) {
  for (const auto& c : kRendererChoices)
    if (name == c.name) return c.value;
  return std::nullopt;
}

const std::vector<RenderOptionSpec>& renderOptionTable() { return kRenderOptions; }

const RenderOptionSpec* findRenderOption(const std::string& name) {
  for (const RenderOptionSpec& spec : kRenderOptions)
    if (name == spec.name) return &spec;
  return nullptr;
}

std::string describeWhereApplies(const RenderOptionSpec& spec) {
  std::string out = describeRenderers(spec.renderers);
  switch (spec.condition) {
    case OptionCondition::Always:
      break;
    case OptionCondition::ShadowMaps:
      out += " with --shadows map";
      break;
    case OptionCondition::Wireframe:
      out += " with --wireframe";
      break;
  }
  return out;
}

std::string helpWithWhere(const RenderOptionSpec& spec) {
  std::string help = spec.help;
  // The sample counts are the sampling module's to say (common/sampling.h).
  if (spec.name == std::string("--spp")) help += ": " + supportedSampleCounts();
  if (spec.renderers != kAllRenderers || spec.condition != OptionCondition::Always)
    help += " [" + describeWhereApplies(spec) + "]";
  return help;
}

std::string defaultText(const RenderOptionSpec& spec) {
  static const RenderSettings defaults;
  return join(spec.format(defaults));
}

std::vector<std::string> shadowModeNames() {
  std::vector<std::string> names;
  for (const auto& c : kShadowModes) names.push_back(c.name);
  return names;
}

std::optional<std::vector<std::string>> splitOptionValue(const std::string& value, int arity) {
  if (arity <= 1) return std::vector<std::string>{value};
  std::vector<std::string> out(1);
  for (const char c : value) {
    if (c == 'x' || c == ',' || c == ':')
      out.emplace_back();
    else
      out.back() += c;
  }
  if (int(out.size()) != arity ||
      std::any_of(out.begin(), out.end(), [](const std::string& t) { return t.empty(); }))
    return std::nullopt;
  return out;
}

RenderSettings renderSettingsFrom(const std::vector<std::string>& args, bool allRenderers) {
  RenderSettings s;
  s.allRenderers = allRenderers;
  bool rendererGiven = false;
  for (size_t i = 0; i < args.size();) {
    const std::string& name = args[i];
    if (name == "--renderer" && !allRenderers) {
      if (rendererGiven) badOption(name, "given more than once");
      if (i + 1 >= args.size()) badOption(name, "needs a value: raster, raytrace or hybrid");
      s.renderer = pick(name, args[i + 1], kRendererChoices);
      rendererGiven = true;
      i += 2;
      continue;
    }
    const RenderOptionSpec* spec = findRenderOption(name);
    if (!spec) badOption(name, "not a render option");
    if (s.isGiven(name)) badOption(name, "given more than once");
    const size_t arity = size_t(spec->arity);
    if (i + 1 + arity > args.size())
      badOption(name, "needs " + std::to_string(arity) + " value" + (arity == 1 ? "" : "s"));
    spec->parse(s, Values(args.begin() + long(i) + 1, args.begin() + long(i + 1 + arity)));
    s.given.insert(name);
    i += 1 + arity;
  }
  s.finish();
  return s;
}

std::vector<std::string> toArgs(const RenderSettings& s, const std::set<std::string>& leaveOut) {
  std::vector<std::string> args;
  if (!s.allRenderers) args = {"--renderer", toString(s.renderer)};
  for (const RenderOptionSpec& spec : kRenderOptions) {
    if (!s.isGiven(spec.name) || leaveOut.count(spec.name)) continue;
    args.push_back(spec.name);
    const Values values = spec.format(s);
    args.insert(args.end(), values.begin(), values.end());
  }
  return args;
}

std::string optionText(const RenderSettings& s, const std::string& name) {
  const RenderOptionSpec* spec = findRenderOption(name);
  RASTRAY_CHECK(spec, name + " has no row in the render-option table");
  return join(spec->format(s));
}

std::string renderOptionsMarkdown() {
  std::string out =
      "| Option | Values | Default | Applies to | What it does |\n"
      "|---|---|---|---|---|\n"
      "| `--renderer` | 1 | `raster` | (chooses) | raster, raytrace or hybrid |\n";
  for (const RenderOptionSpec& spec : kRenderOptions) {
    const std::string shown = defaultText(spec);
    std::string help = spec.help;
    if (spec.name == std::string("--spp")) help += ": " + supportedSampleCounts();
    for (char& c : help)
      if (c == '|') c = '/';
    out += "| `" + std::string(spec.name) + "` | " + (spec.arity == 0 ? "flag" : std::to_string(spec.arity)) +
           " | " + (shown.empty() ? "" : "`" + shown + "`") + " | " + describeWhereApplies(spec) + " | " +
           help + " |\n";
  }
  return out;
}

ShadowMode RenderSettings::shadowModeFor(RendererKind kind) const {
  const ShadowMode traced = ray.shadows ? ShadowMode::Rays : ShadowMode::None;
  if (kind == RendererKind::Raytrace) return traced;
  if (kind == RendererKind::Hybrid && allRenderers) return traced;
  switch (raster.shadows) {
    case RasterShadows::None:
      return ShadowMode::None;
    case RasterShadows::Map:
      return ShadowMode::Map;
    case RasterShadows::Traced:
      return ShadowMode::Rays;
  }
  return ShadowMode::None;
}

bool RenderSettings::applies(const RenderOptionSpec& spec, RendererKind kind) const {
  if (!(spec.renderers & rendererBit(kind))) return false;
  switch (spec.condition) {
    case OptionCondition::Always:
      return true;
    case OptionCondition::ShadowMaps:
      return shadowModeFor(kind) == ShadowMode::Map;
    case OptionCondition::Wireframe:
      return raster.wireframe;
  }
  return false;
}

void RenderSettings::finish() {
  if (!isSupportedSampleCount(spp))
    badOption("--spp", std::to_string(spp) + " is not supported (use " + supportedSampleCounts() + ")");
  if (!isGiven("--max-memory")) memory = MemoryBudget::machineDefault();
  if (isGiven("--animation") && !pose.time)
    badOption("--animation", "chooses what --time plays: give --time too");

  // Shadows: map needs the rasterizer, rays a ray tracer, none applies to
  // every renderer (the ray caster then traces no shadow rays, nor does
  // hybrid for its secondary hits). raster.shadows is the rasterizer's
  // technique; with allRenderers, that of the rasterizer alone.
  const RendererKind rasterizing = allRenderers ? RendererKind::Raster : renderer;
  const ShadowMode shadowMode = shadows                               ? *shadows
                                : rasterizing == RendererKind::Raster ? ShadowMode::Map
                                                                      : ShadowMode::Rays;
  const RendererSet shadowModeRenderers = shadowMode == ShadowMode::Rays   ? kTraced
                                          : shadowMode == ShadowMode::None ? kAllRenderers
                                                                           : kRasterized;
  if (!allRenderers && !(shadowModeRenderers & rendererBit(renderer)))
    badOption("--shadows", "'" + nameOf(shadowMode, kShadowModes) + "' applies to " +
                               describeRenderers(shadowModeRenderers) + ", not to --renderer " +
                               toString(renderer));
  raster.shadows = shadowMode == ShadowMode::None  ? RasterShadows::None
                   : shadowMode == ShadowMode::Map ? RasterShadows::Map
                   : allRenderers                  ? RasterShadows::Map  // the rasterizer alone has no rays
                                                   : RasterShadows::Traced;
  ray.shadows = shadowMode != ShadowMode::None;

  raster.spp = spp;
  raster.cull = cull;
  raster.shading = shading;
  raster.keepSamples = keepSamples;
  ray.spp = spp;
  ray.shading = shading;
  ray.keepSamples = keepSamples;

  // Options given where they do not apply are refused, not ignored; given
  // means given, so the default value given to the wrong renderer is
  // refused too.
  for (const RenderOptionSpec& spec : kRenderOptions) {
    if (!isGiven(spec.name)) continue;
    const std::string where = "applies to " + describeWhereApplies(spec);
    if (allRenderers) {
      if (std::none_of(std::begin(kRendererKinds), std::end(kRendererKinds),
                       [&](RendererKind kind) { return applies(spec, kind); }))
        badOption(spec.name, where + ", and none of the renderers here " +
                                 (spec.condition == OptionCondition::ShadowMaps ? "uses shadow maps"
                                                                                : "draws a wireframe"));
    } else if (!applies(spec, renderer)) {
      std::string context;
      if (spec.renderers & rendererBit(renderer))
        context = spec.condition == OptionCondition::ShadowMaps
                      ? " with --shadows " + nameOf(shadowModeFor(renderer), kShadowModes)
                      : std::string(" without --wireframe");
      badOption(spec.name, where + ", not to --renderer " + toString(renderer) + context);
    }
  }
}

}  // namespace rastray
