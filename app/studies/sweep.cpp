#include "app/studies/sweep.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <set>

#include <tbb/global_control.h>

#include "app/crossval/crossval.h"
#include "app/engine/render_setup.h"
#include "common/error.h"
#include "compare/color_metrics.h"
#include "compare/visibility.h"

namespace rastray::sweep {

namespace {

[[noreturn]] void bad(const std::string& element, const std::string& message) {
  throw InputError("command line", element, message);
}

std::string join(const std::vector<std::string>& parts, const std::string& separator) {
  std::string out;
  for (size_t i = 0; i < parts.size(); ++i) out += (i ? separator : "") + parts[i];
  return out;
}

std::vector<std::string> split(const std::string& text, const std::string& separators) {
  std::vector<std::string> out(1);
  for (const char c : text) {
    if (separators.find(c) != std::string::npos)
      out.emplace_back();
    else
      out.back() += c;
  }
  return out;
}

// What the render command knows about each of its options: how many values
// it takes (0: a flag) and its row of the render-option table (nullptr for
// --renderer), so the sweep accepts exactly what `rastray render` accepts.
struct OptionInfo {
  int arity = 1;
  const RenderOptionSpec* spec = nullptr;
};

const std::map<std::string, OptionInfo>& optionInfo() {
  static const std::map<std::string, OptionInfo> info = [] {
    std::map<std::string, OptionInfo> m;
    m["--renderer"] = {1, nullptr};
    for (const RenderOptionSpec& spec : renderOptionTable()) m[spec.name] = {spec.arity, &spec};
    return m;
  }();
  return info;
}

// An option and its values ("--size", {"160", "120"}; a flag has none).
struct OptionGroup {
  std::string name;
  std::vector<std::string> values;
  int axis = -1;  // index into SweepSpec::vary; -1: given plainly
};

std::vector<OptionGroup> groupPlainArgs(const std::vector<std::string>& args) {
  std::vector<OptionGroup> groups;
  for (size_t i = 0; i < args.size();) {
    const auto it = optionInfo().find(args[i]);
    if (it == optionInfo().end()) bad(args[i], "not a render option");
    OptionGroup g{args[i], {}, -1};
    const size_t arity = size_t(it->second.arity);
    if (i + 1 + arity > args.size()) bad(args[i], "needs " + std::to_string(arity) + " values");
    g.values.assign(args.begin() + long(i) + 1, args.begin() + long(i + 1 + arity));
    groups.push_back(g);
    i += 1 + arity;
  }
  return groups;
}

// The values of one --vary entry as command-line tokens; nullopt-like empty
// name for a flag switched off.
OptionGroup varyGroup(const VaryAxis& axis, int index, const std::string& value) {
  const std::string name = "--" + axis.name;
  const int arity = optionInfo().at(name).arity;
  OptionGroup g{name, {}, index};
  if (arity == 0) {
    if (value == "off")
      g.name.clear();
    else if (value != "on")
      bad("--vary " + axis.name, "'" + value + "': a flag takes on or off");
    return g;
  }
  const std::optional<std::vector<std::string>> values = splitOptionValue(value, arity);
  if (values) g.values = *values;
  if (!values)
    bad("--vary " + axis.name, "'" + value + "': needs " + std::to_string(arity) +
                                   " numbers joined by 'x' or ':' (e.g. " +
                                   (axis.name == "size" ? "160x120" : "1:2:3") + ")");
  return g;
}

void appendGroup(std::vector<std::string>& args, const OptionGroup& g) {
  if (g.name.empty()) return;
  args.push_back(g.name);
  args.insert(args.end(), g.values.begin(), g.values.end());
}

RendererKind rendererKind(const std::string& name, const std::string& element) {
  if (name == "raster") return RendererKind::Raster;
  if (name == "raytrace") return RendererKind::Raytrace;
  if (name == "hybrid") return RendererKind::Hybrid;
  bad(element, "'" + name + "' is not one of raster, raytrace, hybrid");
}

std::string elementOf(const OptionGroup& g) { return g.axis >= 0 ? "--vary " + g.name.substr(2) : g.name; }

// Parses a cell's argument list as `rastray render` does; a failure names
// the --vary entry or plain option at fault.
RenderSettings parseCell(const std::vector<std::string>& args, const std::vector<std::string>& base,
                         const std::vector<OptionGroup>& groups) {
  try {
    return renderSettingsFrom(args);
  } catch (const std::exception& whole) {
    // Find the option that fails on its own beside the renderer.
    for (const OptionGroup& g : groups) {
      std::vector<std::string> alone = base;
      appendGroup(alone, g);
      try {
        renderSettingsFrom(alone);
      } catch (const InputError& e) {
        bad(elementOf(g), e.message());
      } catch (const std::exception& e) {
        bad(elementOf(g), e.what());
      }
    }
    const InputError* input = dynamic_cast<const InputError*>(&whole);
    bad(input ? input->element() : "cell", input ? input->message() : whole.what());
  }
}

// Checks one option's values on their own, with a renderer they apply to,
// so a bad value is refused even where no cell of this sweep would use it.
void validateAlone(const OptionGroup& g) {
  if (g.name.empty()) return;
  std::vector<std::string> args;
  if (g.name != "--renderer") {
    RendererKind kind = RendererKind::Raster;
    if (g.name == "--shadows") {
      kind = g.values[0] == "rays" ? RendererKind::Raytrace : RendererKind::Raster;
    } else {
      const RenderOptionSpec& spec = *optionInfo().at(g.name).spec;
      for (RendererKind k : {RendererKind::Hybrid, RendererKind::Raytrace, RendererKind::Raster})
        if (spec.renderers & rendererBit(k)) kind = k;
      if (spec.condition == OptionCondition::Wireframe) args.push_back("--wireframe");
      if (spec.condition == OptionCondition::ShadowMaps) args.insert(args.end(), {"--shadows", "map"});
    }
    args.insert(args.end(), {"--renderer", toString(kind)});
  }
  appendGroup(args, g);
  try {
    renderSettingsFrom(args);
  } catch (const InputError& e) {
    bad(elementOf(g), e.message());
  } catch (const std::exception& e) {
    bad(elementOf(g), e.what());
  }
}

}  // namespace

VaryAxis parseVary(const std::string& text) {
  const size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0)
    bad("--vary", "'" + text + "': expected NAME=V1,V2,... (e.g. spp=1,4,16)");
  VaryAxis axis;
  axis.name = text.substr(0, eq);
  if (axis.name.rfind("--", 0) == 0) axis.name = axis.name.substr(2);
  axis.values = split(text.substr(eq + 1), ",");
  for (const std::string& v : axis.values)
    if (v.empty()) bad("--vary " + axis.name, "'" + text + "': an empty value");
  return axis;
}

const std::vector<std::string>& autoReferenceArgs() {
  static const std::vector<std::string> args = {
      "--renderer", "raytrace", "--spp", "64", "--max-depth", "16", "--transparency-cutoff", "0"};
  return args;
}

// What the auto reference renders with the cell: the picture's framing
// (the file's camera or the overrides), culling, the pose (an animated
// scene's reference is the same frame), the lights kept and the exposure.
bool definesPicture(const std::string& option) {
  static const std::set<std::string> picture = {"--size",      "--camera", "--eye",     "--target", "--up",
                                                "--yfov",      "--znear",  "--zfar",    "--cull",   "--time",
                                                "--animation", "--lights", "--exposure"};
  return picture.count(option) > 0;
}

std::string describe(const SweepSpec& spec) {
  std::string out = "scenes:";
  for (const std::string& s : spec.scenes) out += " " + s;
  for (const VaryAxis& v : spec.vary) out += "\nvary: " + v.name + "=" + join(v.values, ",");
  out += "\noptions: " + join(spec.plainArgs, " ");
  out += "\nreference: " + spec.reference;
  return out;
}

std::string fingerprint(const SweepSpec& spec) {
  // FNV-1a, 64 bit: a name for the sweep, not a security measure.
  uint64_t h = 1469598103934665603ull;
  for (const unsigned char c : describe(spec)) {
    h ^= c;
    h *= 1099511628211ull;
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

std::vector<Cell> planCells(const SweepSpec& spec) {
  if (spec.scenes.empty()) bad("SCENE", "no scene given");
  const std::vector<OptionGroup> plain = groupPlainArgs(spec.plainArgs);
  std::set<std::string> varied;
  for (const VaryAxis& axis : spec.vary) {
    const std::string name = "--" + axis.name;
    if (!optionInfo().count(name)) {
      std::vector<std::string> names;
      for (const auto& [n, info] : optionInfo()) names.push_back(n.substr(2));
      bad("--vary " + axis.name, "not a render option (one of " + join(names, ", ") + ")");
    }
    if (!varied.insert(name).second) bad("--vary " + axis.name, "varied twice");
    if (axis.values.empty()) bad("--vary " + axis.name, "no values");
    for (const OptionGroup& g : plain)
      if (g.name == name) bad("--vary " + axis.name, "also given plainly as " + name);
  }

  for (const OptionGroup& g : plain) validateAlone(g);
  for (size_t a = 0; a < spec.vary.size(); ++a)
    for (const std::string& value : spec.vary[a].values)
      validateAlone(varyGroup(spec.vary[a], int(a), value));

  std::vector<size_t> counts;
  size_t total = spec.scenes.size();
  for (const VaryAxis& axis : spec.vary) {
    counts.push_back(axis.values.size());
    total *= axis.values.size();
  }

  std::vector<Cell> cells;
  std::set<std::string> seen;
  std::vector<bool> axisApplies(spec.vary.size(), false), plainApplies(plain.size(), false);
  for (size_t combo = 0; combo < total; ++combo) {
    // Mixed-radix digits, the last axis fastest, scenes outermost.
    std::vector<size_t> digit(spec.vary.size());
    size_t rest = combo;
    for (size_t a = spec.vary.size(); a-- > 0;) {
      digit[a] = rest % counts[a];
      rest /= counts[a];
    }
    const std::string& scene = spec.scenes[rest];

    std::vector<OptionGroup> groups = plain;
    for (size_t a = 0; a < spec.vary.size(); ++a)
      groups.push_back(varyGroup(spec.vary[a], int(a), spec.vary[a].values[digit[a]]));

    // The renderer, then what applies to it (the render-option table decides,
    // as it does for `rastray render`).
    std::string rendererName = "raster", rendererElement = "--renderer";
    for (const OptionGroup& g : groups)
      if (g.name == "--renderer") {
        rendererName = g.values[0];
        rendererElement = elementOf(g);
      }
    const RendererKind kind = rendererKind(rendererName, rendererElement);
    const RendererSet rasterized = rendererBit(RendererKind::Raster) | rendererBit(RendererKind::Hybrid);
    const RendererSet traced = rendererBit(RendererKind::Raytrace) | rendererBit(RendererKind::Hybrid);
    std::vector<std::string> base = {"--renderer", rendererName};
    std::vector<bool> applies(groups.size(), true);
    for (size_t i = 0; i < groups.size(); ++i) {
      const OptionGroup& g = groups[i];
      if (g.name == "--shadows") {
        const RendererSet where = g.values[0] == "rays"   ? traced
                                  : g.values[0] == "none" ? kAllRenderers
                                                          : rasterized;
        applies[i] = (where & rendererBit(kind)) != 0;
        if (applies[i]) appendGroup(base, g);
      } else if (g.name == "--wireframe") {
        applies[i] = (rasterized & rendererBit(kind)) != 0;
        if (applies[i]) appendGroup(base, g);
      }
    }
    RenderSettings baseSettings;
    try {
      baseSettings = renderSettingsFrom(base);
    } catch (const InputError& e) {
      for (const OptionGroup& g : groups)
        if (g.name == e.element()) bad(elementOf(g), e.message());
      throw;
    }
    for (size_t i = 0; i < groups.size(); ++i) {
      const OptionGroup& g = groups[i];
      if (g.name.empty() || g.name == "--renderer" || g.name == "--shadows" || g.name == "--wireframe")
        continue;
      applies[i] = baseSettings.applies(*optionInfo().at(g.name).spec, kind);
    }

    Cell cell;
    cell.scene = scene;
    cell.values.resize(spec.vary.size());
    std::vector<OptionGroup> used;
    for (size_t i = 0; i < groups.size(); ++i) {
      const OptionGroup& g = groups[i];
      if (g.axis >= 0) {
        cell.values[size_t(g.axis)] =
            applies[i] ? spec.vary[size_t(g.axis)].values[digit[size_t(g.axis)]] : "n/a";
        if (applies[i]) axisApplies[size_t(g.axis)] = true;
      } else if (applies[i]) {
        plainApplies[i] = true;
      }
      if (applies[i] && g.name != "--renderer") used.push_back(g);
    }
    cell.args = {"--renderer", rendererName};
    for (const OptionGroup& g : used) appendGroup(cell.args, g);
    if (!seen.insert(scene + '\n' + join(cell.args, " ")).second) continue;
    cell.settings = parseCell(cell.args, {"--renderer", rendererName}, used);
    cell.referenceArgs = autoReferenceArgs();
    for (const OptionGroup& g : used)
      if (definesPicture(g.name)) appendGroup(cell.referenceArgs, g);
    cell.index = cells.size();
    cells.push_back(std::move(cell));
  }
  for (size_t a = 0; a < spec.vary.size(); ++a)
    if (!axisApplies[a])
      bad("--vary " + spec.vary[a].name,
          "applies to no cell of this sweep (" +
              describeWhereApplies(*optionInfo().at("--" + spec.vary[a].name).spec) + " only)");
  for (size_t i = 0; i < plain.size(); ++i)
    if (!plainApplies[i] && plain[i].name != "--renderer") {
      const OptionInfo& info = optionInfo().at(plain[i].name);
      bad(plain[i].name, "applies to no cell of this sweep (" + describeWhereApplies(*info.spec) + " only)");
    }
  return cells;
}

Shard parseShard(const std::string& text) {
  Shard s;
  const size_t slash = text.find('/');
  try {
    size_t used = 0;
    if (slash == std::string::npos) throw std::invalid_argument("no slash");
    s.k = std::stoi(text.substr(0, slash), &used);
    if (used != slash) throw std::invalid_argument("trailing");
    s.n = std::stoi(text.substr(slash + 1), &used);
    if (used != text.size() - slash - 1) throw std::invalid_argument("trailing");
  } catch (const std::exception&) {
    bad("--shard", "'" + text + "': expected K/N, e.g. 0/4");
  }
  if (s.n < 1 || s.k < 0 || s.k >= s.n) bad("--shard", "'" + text + "': needs 0 <= K < N");
  return s;
}

TimeStats timeStats(std::vector<double> seconds) {
  TimeStats t;
  if (seconds.empty()) return t;
  std::sort(seconds.begin(), seconds.end());
  const size_t n = seconds.size();
  t.median = n % 2 ? seconds[n / 2] : 0.5 * (seconds[n / 2 - 1] + seconds[n / 2]);
  t.min = seconds.front();
  t.max = seconds.back();
  return t;
}

CellErrors measureErrors(const FlatImage& color, const FlatImage& centre, const Reference& reference,
                         const ClassifierSettings* classifier) {
  RASTRAY_CHECK(color.width == reference.color.width && color.height == reference.color.height &&
                    centre.width == reference.centre.width && centre.height == reference.centre.height,
                "measureErrors: sizes differ");
  CellErrors e;
  e.pixels = uint64_t(color.width) * uint64_t(color.height);
  if (e.pixels == 0) return e;
  const ColorMetrics m = compareColors(color, reference.color);
  e.rms = m.rmsError;
  e.max = m.maxError;
  e.perceptual = double(m.yeeFailingPixels) / double(e.pixels);

  uint64_t differ = 0;
  double sumAbs = 0, sumRel = 0;
  for (size_t i = 0; i < size_t(e.pixels); ++i) {
    const uint32_t inst = centre.instance[i], tri = centre.triangle[i];
    if (inst != reference.centre.instance[i] || tri != reference.centre.triangle[i]) {
      ++differ;
      continue;
    }
    if (inst == kNoId) continue;
    const double z = centre.depth[i], zr = reference.centre.depth[i];
    if (!std::isfinite(z) || !std::isfinite(zr) || zr <= 0) continue;
    const double abs = std::fabs(z - zr), rel = abs / zr;
    sumAbs += abs;
    sumRel += rel;
    e.depthMaxAbs = std::max(e.depthMaxAbs, abs);
    e.depthMaxRel = std::max(e.depthMaxRel, rel);
    ++e.depthPixels;
  }
  uint64_t sharedEdge = 0;
  if (classifier && differ) {
    const VisibilityReport v = compareVisibility(centre, reference.centre, 1, *classifier,
                                                 FrameNames{"cell", reference.description});
    RASTRAY_CHECK(v.samples.mismatching() == differ,
                  "measureErrors: the classification counted another total");
    sharedEdge = v.samples.count(MismatchClass::SharedEdgeTie);
  }
  e.visibility = double(differ - sharedEdge) / double(e.pixels);
  e.visibilitySharedEdge = double(sharedEdge) / double(e.pixels);
  if (e.depthPixels) {
    e.depthMeanAbs = sumAbs / double(e.depthPixels);
    e.depthMeanRel = sumRel / double(e.depthPixels);
  }
  return e;
}

namespace {

// The same options with the sample count set to 1: the pixel centre is the
// only sample (SPEC §3), so Z and IDs are those at the centre.
RenderSettings atCentre(RenderSettings settings) {
  settings.spp = settings.raster.spp = settings.ray.spp = 1;
  return settings;
}

double stageSeconds(const RenderRun& run, const std::string& stage) {
  for (const auto& [name, seconds] : run.output.timings)
    if (name == stage) return seconds;
  return 0.0;
}

}  // namespace

namespace {

// Whether the file's R channel is stored as half: rounded colours no
// render's float colours equal. (Through common/image.h, which opens the
// file as the reader just did: OpenEXR only, after the header checks.)
bool halfColor(const std::string& path) { return exrChannelType(path, "R") == "half"; }

}  // namespace

const Reference& ReferenceSource::referenceFor(const Cell& cell) {
  const bool automatic = reference_ == "auto";
  const std::string key = automatic ? cell.scene + '\n' + join(cell.referenceArgs, " ") : reference_;
  const auto found = cache_.find(key);
  if (found != cache_.end()) return found->second;
  Reference r;
  if (automatic) {
    const RenderSettings settings = renderSettingsFrom(cell.referenceArgs);
    const Scene scene = loadSceneForRender(cell.scene, settings);
    r.color = renderScene(scene, settings).output.image;
    r.centre = renderScene(scene, atCentre(settings)).output.image;
    r.description =
        "auto: " + join(cell.referenceArgs, " ") + " (Z and IDs at the pixel centres: the same at 1 spp)";
  } else {
    r.color = readExr(reference_);
    if (!r.color.hasColor) throw InputError(reference_, "", "a reference needs colour (R G B)");
    r.centre = r.color;
    r.description = reference_ + " (Z and IDs: the file's sample nearest each pixel centre)";
    if (halfColor(reference_))
      r.inexact =
          "its colour is half-float, so no cell scores 0 against it, not even at its own settings: render "
          "the "
          "reference with --float (and --spp 1, so its Z and IDs are the pixel centres the cells are "
          "compared at)";
  }
  return cache_.emplace(key, std::move(r)).first->second;
}

CellResult measureCell(const Cell& cell, int repeat, ReferenceSource& references) {
  std::unique_ptr<tbb::global_control> threads;
  if (cell.settings.threads > 0)
    threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                    size_t(cell.settings.threads));
  CellResult result;
  result.index = cell.index;
  result.scene = cell.scene;
  result.values = cell.values;
  result.args = join(cell.args, " ");
  result.repeat = repeat;

  const Reference& reference = references.referenceFor(cell);
  const int width = cell.settings.camera.width(), height = cell.settings.camera.height();
  if (reference.color.width != width || reference.color.height != height)
    throw InputError(reference.description, "",
                     "reference is " + std::to_string(reference.color.width) + "x" +
                         std::to_string(reference.color.height) + ", the cell renders " +
                         std::to_string(width) + "x" + std::to_string(height) + " (--size)");

  std::vector<double> load, build, frame, time;
  FlatImage image;
  Scene scene;
  for (int k = 0; k < std::max(repeat, 1); ++k) {
    const auto start = std::chrono::steady_clock::now();
    scene = loadSceneForRender(cell.scene, cell.settings);
    load.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    RenderRun run = renderScene(scene, cell.settings);
    const double bvh = stageSeconds(run, "raytrace.bvh_build");
    build.push_back(bvh);
    frame.push_back(run.seconds - bvh);
    time.push_back(run.seconds);
    if (k == 0) image = std::move(run.output.image);
  }
  result.width = image.width;
  result.height = image.height;
  result.load = timeStats(load);
  result.build = timeStats(build);
  result.frame = timeStats(frame);
  result.time = timeStats(time);
  const FlatImage centre =
      cell.settings.spp == 1 ? image : renderScene(scene, atCentre(cell.settings)).output.image;
  // Differences at the centres are classified in the cell's frame, against
  // the depth buffer it rasterized with (the ray caster: float-reversed).
  const Camera camera = makeCamera(scene, cell.settings.camera.overrides(), width, height);
  const ClassifierSettings classifier =
      classifierSettings(scene, camera,
                         cell.settings.renderer != RendererKind::Raytrace ? cell.settings.raster.depthFormat
                                                                          : DepthFormat::FloatReversed);
  result.errors = measureErrors(image, centre, reference, &classifier);
  return result;
}

}  // namespace rastray::sweep
