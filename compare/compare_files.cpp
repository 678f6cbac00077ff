#include "compare/compare_files.h"

#include <cmath>
#include <cstdio>
#include <tuple>

#include "common/error.h"
#include "common/gltf/loader.h"
#include "common/image.h"
#include "common/scene.h"

namespace rastray {

namespace {

// JSON numbers cannot be infinite or NaN: those are written as strings.
nlohmann::json number(double d) {
  if (std::isnan(d)) return "nan";
  if (std::isinf(d)) return d > 0 ? "inf" : "-inf";
  return d;
}

nlohmann::json hitJson(const HitRecord& h) {
  if (!h.isHit()) return nullptr;
  return {{"instance", h.instance}, {"triangle", h.triangle}, {"depth", number(h.depth)}};
}

nlohmann::json countsJson(const AgreementCounts& c) {
  nlohmann::json byClass = nlohmann::json::object();
  for (int i = 0; i < kMismatchClassCount; ++i) {
    const MismatchClass cls = MismatchClass(i);
    byClass[toString(cls)] = {{"count", c.count(cls)}, {"fraction", c.fraction(cls)}};
  }
  return {{"compared", c.compared},         {"agreeing", c.agreeing},     {"bothEmpty", c.bothEmpty},
          {"mismatching", c.mismatching()}, {"agreement", c.agreement()}, {"mismatches", byClass}};
}

std::string hitText(const HitRecord& h) {
  if (!h.isHit()) return "nothing";
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%u, %u) Z %.9g", h.instance, h.triangle, double(h.depth));
  return buf;
}

const char* channelName(int c) {
  static const char* names[] = {"R", "G", "B", "A"};
  return c >= 0 && c < 4 ? names[c] : "?";
}

uint64_t countHits(const FlatImage& f) {
  uint64_t n = 0;
  for (size_t i = 0; i < f.instance.size(); ++i) n += HitRecord{f.instance[i], f.triangle[i]}.isHit();
  return n;
}

// Why the colour metrics cannot be computed (empty: they can): both files
// need R, G and B (the readers' hasColor).
std::string colorSkipReason(const FlatImage& a, const FlatImage& b, const std::string& pathA,
                            const std::string& pathB) {
  if (a.hasColor && b.hasColor) return "";
  const std::string lacking = !a.hasColor && !b.hasColor ? pathA + " and " + pathB + " have"
                              : a.hasColor               ? pathB + " has"
                                                         : pathA + " has";
  return lacking + " no R G B channels: visibility and depth only";
}

uint64_t countHits(const DeepImage& d) {
  uint64_t n = 0;
  for (const DeepSample& s : d.samples) n += HitRecord{s.instance, s.triangle}.isHit();
  return n;
}

// The colour metrics, or {"skipped": why} when a file has no colour.
nlohmann::json colorJson(const CompareResult& r) {
  if (!r.colorSkipped.empty()) return {{"skipped", r.colorSkipped}};
  const ColorMetrics& c = r.color;
  return {{"space", "linear premultiplied RGBA"},
          {"method", "OpenImageIO ImageBufAlgo::compare"},
          {"meanError", number(c.meanError)},
          {"rmsError", number(c.rmsError)},
          {"psnr", number(c.psnr)},
          {"maxError", number(c.maxError)},
          {"maxAt", c.maxX >= 0
                        ? nlohmann::json{{"x", c.maxX}, {"y", c.maxY}, {"channel", channelName(c.maxChannel)}}
                        : nlohmann::json(nullptr)},
          {"pixels", c.pixels},
          {"differingPixels", c.differingPixels},
          {"perceptual",
           {{"metric", "Yee perceptual difference (OpenImageIO ImageBufAlgo::compare_Yee)"},
            {"failingPixels", c.yeeFailingPixels},
            {"luminance", c.yeeLuminance},
            {"fieldOfViewDegrees", c.yeeFieldOfView}}}};
}

}  // namespace

std::string classificationSummary(const VisibilityReport& v, const std::string& scenePath) {
  if (!v.geometric)
    return "image-space only (no --scene): an edge class when each image shows the other's hit in the 3x3 "
           "pixel neighbourhood; depth and plane classes as with a scene";
  char distance[32];
  std::snprintf(distance, sizeof distance, "%.6g", v.edgeDistance);
  return "geometric (scene " + scenePath + ", edges projected with the camera; edge distance " + distance +
         " px)";
}

CompareResult compareFiles(const CompareInputs& in) {
  if (!(in.edgeDistance >= 0.0) || std::isinf(in.edgeDistance))
    throw InputError("command line", "--edge-distance", "must be a finite distance >= 0 pixels");
  CompareResult r;
  r.pathA = in.pathA;
  r.pathB = in.pathB;
  r.scenePath = in.scenePath;
  const bool deepA = isDeepExr(in.pathA, in.maxImageBytes), deepB = isDeepExr(in.pathB, in.maxImageBytes);
  if (deepA != deepB)
    throw InputError(in.pathB, "",
                     std::string(deepB ? "deep" : "flat") + " EXR, but " + in.pathA + " is " +
                         (deepA ? "deep" : "flat") + ": compare files of the same kind");

  // Read both first: the size (which the camera needs) comes from the files.
  FlatImage flatA, flatB;
  DeepImage deepImageA, deepImageB;
  int width, height;
  if (deepA) {
    deepImageA = readDeepExr(in.pathA, in.maxImageBytes);
    deepImageB = readDeepExr(in.pathB, in.maxImageBytes);
    width = deepImageA.width;
    height = deepImageA.height;
  } else {
    flatA = readExr(in.pathA, in.maxImageBytes);
    flatB = readExr(in.pathB, in.maxImageBytes);
    width = flatA.width;
    height = flatA.height;
  }

  ClassifierSettings settings;
  settings.depthFormat = in.depthFormat;
  settings.edgeDistance = in.edgeDistance;
  std::optional<Scene> scene;
  std::optional<Camera> camera;
  if (!in.scenePath.empty()) {
    scene = loadScene(in.scenePath, MemoryBudget::machineDefault(), in.pose);
    // As `render` and `crossval` do by default (--origin camera).
    applyRenderOrigin(*scene, RenderOrigin::Camera, in.camera);
    camera = makeCamera(*scene, in.camera, width, height);
    settings.scene = &*scene;
    settings.camera = &*camera;
    settings.planes = {true, camera->projection, camera->znear, camera->zfar};
    r.camera = camera->describe();
  } else if (in.camera.znear) {
    // No scene: the planes the user states, for a perspective camera.
    const double n = *in.camera.znear, f = in.camera.zfar.value_or(std::numeric_limits<double>::infinity());
    if (!(n > 0.0) || !(f > n)) throw InputError("command line", "--znear", "need 0 < znear < zfar");
    settings.planes = {true, Projection::Perspective, n, f};
  } else if (in.camera.zfar) {
    throw InputError("command line", "--zfar", "needs --znear or --scene");
  }
  if (!settings.planes.known && in.depthFormat != DepthFormat::FloatReversed)
    throw InputError("command line", "--depth-format",
                     std::string(toString(in.depthFormat)) +
                         " needs the clipping planes to state its resolution: give --scene or --znear");

  const FrameNames names{in.pathA, in.pathB};
  if (deepA) {
    r.visibility = compareVisibility(deepImageA, deepImageB, in.spp, settings, names);
    r.sppInferred = in.spp <= 0;
    r.colorA = flattenDeepColor(deepImageA, r.visibility.spp);
    r.colorB = flattenDeepColor(deepImageB, r.visibility.spp);
  } else {
    r.visibility = compareVisibility(flatA, flatB, in.spp, settings, names);
    r.colorA = std::move(flatA);
    r.colorB = std::move(flatB);
  }
  r.colorSkipped = colorSkipReason(r.colorA, r.colorB, in.pathA, in.pathB);
  if (r.colorSkipped.empty()) r.color = compareColors(r.colorA, r.colorB);

  // A file without id channels reads as "nothing hit" everywhere (the
  // readers' convention); say so rather than let it pass as plain mismatches.
  const uint64_t hitsA = deepA ? countHits(deepImageA) : countHits(r.colorA),
                 hitsB = deepA ? countHits(deepImageB) : countHits(r.colorB);
  for (const auto& [path, hits, other] :
       {std::tuple{in.pathA, hitsA, hitsB}, std::tuple{in.pathB, hitsB, hitsA}})
    if (hits == 0 && other > 0)
      r.notes.push_back(path +
                        ": no (instance, triangle) hit anywhere: the file may lack id.instance/id.triangle; "
                        "visibility is compared against nothing");
  return r;
}

std::vector<std::string> thresholdViolations(const CompareResult& r, const Thresholds& t) {
  std::vector<std::string> out;
  const AgreementCounts& c = r.visibility.layers;
  const char* unit = r.visibility.deep ? "layers" : "pixels";
  char buf[256];
  if (t.minAgreement && c.agreement() < *t.minAgreement) {
    std::snprintf(buf, sizeof buf, "agreement %.6f of %s is below --min-agreement %.6g", c.agreement(), unit,
                  *t.minAgreement);
    out.push_back(buf);
  }
  const uint64_t genuine = c.count(MismatchClass::Genuine);
  if (t.maxGenuine && genuine > *t.maxGenuine) {
    std::snprintf(buf, sizeof buf, "%llu genuine mismatching %s exceed --max-genuine %llu",
                  static_cast<unsigned long long>(genuine), unit,
                  static_cast<unsigned long long>(*t.maxGenuine));
    out.push_back(buf);
  }
  if (t.failRms && !r.colorSkipped.empty()) {
    out.push_back("--fail-rms cannot apply: colour skipped (" + r.colorSkipped + ")");
    return out;
  }
  // NaN RMS (NaN colours) fails too: a comparison that cannot be made is not a pass.
  if (t.failRms && !(r.color.rmsError <= *t.failRms)) {
    std::snprintf(buf, sizeof buf, "colour RMS error %.6g exceeds --fail-rms %.6g", r.color.rmsError,
                  *t.failRms);
    out.push_back(buf);
  }
  return out;
}

nlohmann::json toJson(const CompareResult& r, const Thresholds& t,
                      const std::vector<std::string>& violations) {
  const VisibilityReport& v = r.visibility;
  nlohmann::json j;
  j["schema"] = "rastray.compare";
  j["version"] = 1;
  j["a"] = r.pathA;
  j["b"] = r.pathB;
  j["width"] = v.width;
  j["height"] = v.height;
  j["kind"] = v.deep ? "deep" : "flat";
  j["spp"] = v.spp ? nlohmann::json(v.spp) : nlohmann::json(nullptr);
  j["sppInferred"] = r.sppInferred;
  j["scene"] = r.scenePath.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.scenePath);
  j["camera"] = r.camera.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.camera);
  j["classification"] = {
      {"mode", v.geometric ? "geometric" : "image-space"},
      {"summary", classificationSummary(v, r.scenePath)},
      {"edgeDistancePixels", v.edgeDistance},
      {"depthFormat", toString(v.depthFormat)},
      {"depthFormula", depthFormatFormula(v.depthFormat)},
      {"planes", v.planes.known ? nlohmann::json{{"projection", toString(v.planes.projection)},
                                                 {"znear", number(v.planes.znear)},
                                                 {"zfar", number(v.planes.zfar)}}
                                : nlohmann::json(nullptr)}};
  nlohmann::json vis;
  vis[v.deep ? "samples" : "pixels"] = countsJson(v.samples);
  if (v.deep) {
    vis["layers"] = countsJson(v.layers);
    vis["cutOff"] = {{"layers", v.layers.cutOff},
                     {"samples", v.cutOff.samples},
                     {"meanColor", v.cutOff.meanColor},
                     {"maxColor", v.cutOff.maxColor},
                     {"maxAt", {v.cutOff.maxX, v.cutOff.maxY}}};
  }
  nlohmann::json examples = nlohmann::json::object();
  for (int i = 0; i < kMismatchClassCount; ++i) {
    const auto& e = v.examples[size_t(i)];
    if (!e) continue;
    examples[toString(MismatchClass(i))] = {{"x", e->x},         {"y", e->y},          {"sample", e->sample},
                                            {"layer", e->layer}, {"a", hitJson(e->a)}, {"b", hitJson(e->b)}};
  }
  vis["examples"] = examples;
  j["visibility"] = vis;
  j["depthError"] = {
      {"count", v.depth.count},
      {"meanAbsolute", v.depth.meanAbsolute},
      {"maxAbsolute", v.depth.maxAbsolute},
      {"maxAbsoluteAt", v.depth.maxAbsoluteX >= 0 ? nlohmann::json{v.depth.maxAbsoluteX, v.depth.maxAbsoluteY}
                                                  : nlohmann::json(nullptr)},
      {"meanRelative", v.depth.meanRelative},
      {"maxRelative", v.depth.maxRelative}};
  j["color"] = colorJson(r);
  nlohmann::json th = nlohmann::json::object();
  if (t.minAgreement) th["minAgreement"] = *t.minAgreement;
  if (t.maxGenuine) th["maxGenuine"] = *t.maxGenuine;
  if (t.failRms) th["failRms"] = *t.failRms;
  j["thresholds"] = th;
  j["notes"] = r.notes;
  j["violations"] = violations;
  j["passed"] = violations.empty();
  return j;
}

std::string formatTable(const CompareResult& r, const Thresholds& t,
                        const std::vector<std::string>& violations) {
  const VisibilityReport& v = r.visibility;
  std::string s;
  char buf[512];
  auto line = [&](const char* fmt, auto... args) {
    std::snprintf(buf, sizeof buf, fmt, args...);
    s += buf;
  };
  s += "compare     " + r.pathA + "\n   with     " + r.pathB + "\n";
  if (v.deep)
    line("frames      %dx%d deep, %d spp%s\n", v.width, v.height, v.spp, r.sppInferred ? " (inferred)" : "");
  else if (v.spp)
    line("frames      %dx%d flat: the centre sample of %d spp\n", v.width, v.height, v.spp);
  else
    line("frames      %dx%d flat: the centre sample\n", v.width, v.height);
  s += "classify    " + classificationSummary(v, r.scenePath) + "\n";
  if (!r.camera.empty()) s += "camera      " + r.camera + "\n";
  s += "depth tie   " + depthFormatFormula(v.depthFormat) + "\n";
  if (v.planes.known)
    line("planes      %s znear %.6g zfar %.6g\n", toString(v.planes.projection), v.planes.znear,
         v.planes.zfar);
  else
    s += "planes      unknown (no --scene or --znear): no near/far plane class\n";

  s += "\nvisibility (instance, triangle)\n";
  auto counts = [&](const char* unit, const AgreementCounts& c) {
    line("  %-8s %12llu compared %12llu agree (%.6f; %llu both empty) %10llu mismatch\n", unit,
         static_cast<unsigned long long>(c.compared), static_cast<unsigned long long>(c.agreeing),
         c.agreement(), static_cast<unsigned long long>(c.bothEmpty),
         static_cast<unsigned long long>(c.mismatching()));
  };
  counts(v.deep ? "samples" : "pixels", v.samples);
  if (v.deep) counts("layers", v.layers);
  line("  mismatches by class (%s)         count   fraction   first example\n", v.deep ? "layers" : "pixels");
  for (int i = 0; i < kMismatchClassCount; ++i) {
    const MismatchClass cls = MismatchClass(i);
    const auto& e = v.examples[size_t(i)];
    std::string example = "-";
    if (e) {
      example = "pixel (" + std::to_string(e->x) + ", " + std::to_string(e->y) + ")";
      if (v.deep) example += " sample " + std::to_string(e->sample) + " layer " + std::to_string(e->layer);
      example += ": A " + hitText(e->a) + ", B " + hitText(e->b);
    }
    line("    %-30s %10llu   %.6f   %s\n", displayName(cls),
         static_cast<unsigned long long>(v.layers.count(cls)), v.layers.fraction(cls), example.c_str());
  }
  if (v.deep)
    line(
        "  cut off (not compared)  %10llu layers in %llu samples; their colour: mean %.3g, max %.3g per "
        "pixel\n",
        static_cast<unsigned long long>(v.layers.cutOff), static_cast<unsigned long long>(v.cutOff.samples),
        v.cutOff.meanColor, v.cutOff.maxColor);

  const DepthErrorStats& d = v.depth;
  line("\ndepth error on %llu agreeing hits (view depth)\n", static_cast<unsigned long long>(d.count));
  if (d.count) {
    line("  absolute  mean %.6g  max %.6g at pixel (%d, %d)\n", d.meanAbsolute, d.maxAbsolute, d.maxAbsoluteX,
         d.maxAbsoluteY);
    line("  relative  mean %.6g  max %.6g   (|ZA - ZB| / max(ZA, ZB))\n", d.meanRelative, d.maxRelative);
  }

  const ColorMetrics& c = r.color;
  if (!r.colorSkipped.empty()) {
    s += "\ncolour: skipped (" + r.colorSkipped + ")\n";
  } else {
    s += "\ncolour (OpenImageIO ImageBufAlgo::compare on linear premultiplied RGBA";
    s += v.deep ? "; deep layers composited, samples box-averaged)\n" : ")\n";
    line("  mean %.6g  RMS %.6g  PSNR %.4g dB  max %.6g", c.meanError, c.rmsError, c.psnr, c.maxError);
    if (c.maxX >= 0) line(" at pixel (%d, %d) channel %s", c.maxX, c.maxY, channelName(c.maxChannel));
    line("\n  %llu of %llu pixels differ\n", static_cast<unsigned long long>(c.differingPixels),
         static_cast<unsigned long long>(c.pixels));
    line(
        "  perceptual: Yee (ImageBufAlgo::compare_Yee, %.0f cd/m2, %.0f deg): %llu pixels perceptibly "
        "different\n",
        c.yeeLuminance, c.yeeFieldOfView, static_cast<unsigned long long>(c.yeeFailingPixels));
  }

  for (const std::string& note : r.notes) s += "\nnote: " + note + "\n";
  if (t.minAgreement || t.maxGenuine || t.failRms) {
    s += "\nthresholds  ";
    s += violations.empty() ? "passed\n" : "FAILED\n";
    for (const std::string& msg : violations) s += "  " + msg + "\n";
  }
  return s;
}

}  // namespace rastray
