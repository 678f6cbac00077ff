#include "app/studies/stability_measure.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "common/error.h"
#include "common/math_constants.h"
#include "common/sampling.h"
#include "compare/classify.h"
#include "compare/maps.h"
#include "raster/shadow_map.h"

namespace rastray::stability {

Rendered renderVariant(const CaseContext& ctx, const std::string& scenePath,
                       const std::vector<std::string>& args, bool deep, const std::string& label) {
  Rendered r;
  r.settings = renderSettingsFrom(args);
  if (!ctx.shadowMapArgs.empty() && r.settings.shadowModeFor(r.settings.renderer) == ShadowMode::Map) {
    std::vector<std::string> withMapArgs = args;
    withMapArgs.insert(withMapArgs.end(), ctx.shadowMapArgs.begin(), ctx.shadowMapArgs.end());
    r.settings = renderSettingsFrom(withMapArgs);
  }
  r.settings.keepSamples = deep;
  r.scene = loadSceneForRender(scenePath, r.settings);
  r.run = renderScene(r.scene, r.settings);
  if (ctx.progress) {
    char line[256];
    std::snprintf(line, sizeof line, "%s: %.3f s",
                  label.empty() ? toString(r.settings.renderer) : label.c_str(), r.run.seconds);
    ctx.progress(line);
  }
  return r;
}

namespace {

bool finite4(const glm::vec4& c) {
  return std::isfinite(c.r) && std::isfinite(c.g) && std::isfinite(c.b) && std::isfinite(c.a);
}

// A depth is wrong when NaN or −inf anywhere, or +inf on a hit.
bool badDepth(float depth, bool hit) {
  return std::isnan(depth) || depth == -INFINITY || (hit && std::isinf(depth));
}

}  // namespace

uint64_t countNanInf(const RenderOutput& output) {
  uint64_t bad = 0;
  const FlatImage& image = output.image;
  for (size_t i = 0; i < image.color.size(); ++i) {
    if (!finite4(image.color[i])) ++bad;
    if (i < image.depth.size() &&
        badDepth(image.depth[i], i < image.instance.size() && image.instance[i] != kNoId))
      ++bad;
  }
  if (output.hasSamples)
    for (const DeepSample& s : output.samples.samples) {
      if (!finite4(s.color)) ++bad;
      if (badDepth(s.depth, s.instance != kNoId)) ++bad;
    }
  return bad;
}

VisibilityReport visibilityAgainst(const Rendered& a, const Rendered& reference) {
  if (!a.run.output.hasSamples || !reference.run.output.hasSamples)
    throw std::logic_error("visibilityAgainst: both renders need their samples (renderVariant deep = true)");
  const auto rasterizes = [](const Rendered& r) { return r.settings.renderer != RendererKind::Raytrace; };
  const DepthFormat format = rasterizes(a)           ? a.settings.raster.depthFormat
                             : rasterizes(reference) ? reference.settings.raster.depthFormat
                                                     : DepthFormat::FloatReversed;
  const Camera& camera = reference.camera();
  const ClassifierSettings classifier = classifierSettings(reference.scene, camera, format);
  return compareVisibility(a.run.output.samples, reference.run.output.samples, reference.settings.spp,
                           classifier, FrameNames{toString(a.settings.renderer), "reference"});
}

double agreementOf(const VisibilityReport& v) { return v.layers.agreement(); }
int64_t genuineOf(const VisibilityReport& v) { return int64_t(v.layers.count(MismatchClass::Genuine)); }

CrossvalResult crossvalidateVariant(const CaseContext& ctx, const std::string& scenePath,
                                    const std::vector<std::string>& args) {
  const RenderSettings settings = renderSettingsFrom(args, /*allRenderers=*/true);
  const Scene scene = loadSceneForRender(scenePath, settings);
  return crossvalidate(scene, settings, ctx.progress);
}

namespace {

// A stored triangle in double, in the render's frame (worldPositions minus
// the render origin: both double, so this is exact to 2^-53 relative).
struct DoubleTriangle {
  glm::dvec3 a, b, c, n;  // n: unnormalised CCW normal
  bool opaque = true;     // blocks light entirely (opaque, not transmissive)
};

bool diffuseOnly(const Scene& scene, uint32_t instance) {
  const Material& m = scene.materialOf(instance);
  return !m.isReflective() && m.transmission == 0.0f && !m.isTextured() && !m.isEmissive() &&
         m.alphaMode == AlphaMode::Opaque && !scene.instanceOf(instance).hasColors;
}

// Signed distance of q (in the triangle's plane) from the triangle's edges:
// positive inside, the smallest over the three edges.
double insideDistance(const DoubleTriangle& t, const glm::dvec3& q) {
  const glm::dvec3 n = glm::normalize(t.n);
  double d = INFINITY;
  for (const auto& [p0, p1] : {std::pair{t.a, t.b}, {t.b, t.c}, {t.c, t.a}}) {
    const glm::dvec3 e = p1 - p0;
    d = std::min(d, glm::dot(glm::cross(e, q - p0), n) / glm::length(e));
  }
  return d;
}

}  // namespace

ShadowCheck checkShadows(const Rendered& r, double tolerance, double minCosine,
                         const TexelWidth& texelWidth) {
  ShadowCheck out;
  const Scene& scene = r.scene;
  if (scene.lights.empty()) return out;
  for (const Light& light : scene.lights)
    if (light.type != LightType::Directional && light.range > 0.0f) return out;
  if (!r.run.output.hasSamples) throw std::logic_error("checkShadows: the render needs its samples");
  out.acne = out.leaks = 0;
  out.shadowed.assign(scene.lights.size(), 0);
  std::vector<uint8_t> darkLights(scene.lights.size());

  std::vector<DoubleTriangle> triangles(scene.triangles.size());
  for (const Instance& inst : scene.instances)
    for (uint32_t k = 0; k < inst.triangleCount; ++k) {
      const glm::uvec3& v = scene.triangles[inst.firstTriangle + k];
      DoubleTriangle& t = triangles[inst.firstTriangle + k];
      t.a = scene.worldPositions[v.x] - scene.origin;
      t.b = scene.worldPositions[v.y] - scene.origin;
      t.c = scene.worldPositions[v.z] - scene.origin;
      t.n = glm::cross(t.b - t.a, t.c - t.a);
      const Material& m = scene.materials[inst.material];
      t.opaque = m.alphaMode == AlphaMode::Opaque && m.transmission == 0.0f;
    }

  // Whether an opaque triangle other than `own` blocks the segment from q
  // towards the light (farther than `distance`: none); `nearEdge` is set
  // when the segment passes within `tolerance` of an edge it does not
  // clearly cross.
  uint32_t own = 0;
  const auto blocked = [&](const glm::dvec3& q, const glm::dvec3& toLight, double distance, bool* nearEdge) {
    for (size_t j = 0; j < triangles.size(); ++j) {
      if (j == own) continue;
      const DoubleTriangle& o = triangles[j];
      const double d = glm::dot(o.n, toLight);
      if (d == 0.0) continue;  // parallel (or degenerate)
      const double t = glm::dot(o.a - q, o.n) / d;
      if (!(t > 1e-6 && t < distance)) continue;
      const double inside = insideDistance(o, q + toLight * t);
      if (inside > tolerance && o.opaque) return true;
      if (inside > -tolerance) *nearEdge = true;
    }
    return false;
  };
  // Whether the reference visibility of some light changes within one map
  // texel of p: p moved in its plane (normal n) along the light so that
  // its place in the map moves by one texel side, both ways, each side.
  const auto nearShadowEdge = [&](const glm::dvec3& p, const glm::dvec3& n) {
    for (size_t l = 0; l < scene.lights.size(); ++l) {
      const Light& light = scene.lights[l];
      const auto towards = [&](const glm::dvec3& q, double* distance) {
        *distance = INFINITY;
        if (light.type == LightType::Directional) return glm::dvec3(-light.direction);
        const glm::dvec3 v = light.position - q;
        *distance = glm::length(v);
        return v / *distance;
      };
      double distance;
      const glm::dvec3 toLight = towards(p, &distance);
      const double cosine = glm::dot(n, toLight);
      if (cosine <= 0.0) continue;
      bool ignored = false;
      const bool here = blocked(p, toLight, distance, &ignored);
      const std::array<glm::dvec3, 2> sides = texelWidth(int(l), p);
      for (const glm::dvec3& side : sides)
        for (const double sign : {1.0, -1.0}) {
          const glm::dvec3 e = sign * side;
          // Back to the plane along the light: the same place in the map.
          const glm::dvec3 q = p + e - toLight * (glm::dot(n, e) / cosine);
          double d;
          const glm::dvec3 to = towards(q, &d);
          if (blocked(q, to, d, &ignored) != here) return true;
        }
    }
    return false;
  };

  const Camera& camera = r.camera();
  const DeepImage& deep = r.run.output.samples;
  const std::vector<glm::dvec2> offsets = samplePositions(r.settings.spp);
  out.pixels.assign(size_t(deep.width) * size_t(deep.height), NAN);
  for (int y = 0; y < deep.height; ++y)
    for (int x = 0; x < deep.width; ++x) {
      const size_t pixel = size_t(y) * size_t(deep.width) + size_t(x);
      uint32_t lastSample = UINT32_MAX;
      for (uint64_t i = deep.offsets[pixel]; i < deep.offsets[pixel + 1]; ++i) {
        const DeepSample& s = deep.samples[i];
        if (s.sample == lastSample) continue;  // only the front layer
        lastSample = s.sample;
        if (s.instance == kNoId || s.sample >= offsets.size() || !diffuseOnly(scene, s.instance)) continue;
        own = scene.instanceOf(s.instance).firstTriangle + s.triangle;
        const DoubleTriangle& tri = triangles[own];
        const Ray ray = camera.primaryRay(glm::dvec2(x, y) + offsets[s.sample]);
        const double denom = glm::dot(ray.direction, tri.n);
        if (denom == 0.0) continue;
        const glm::dvec3 p = ray.origin + ray.direction * (glm::dot(tri.a - ray.origin, tri.n) / denom);
        glm::dvec3 n = glm::normalize(tri.n);
        if (glm::dot(n, ray.direction) > 0.0) n = -n;  // the side the camera sees
        const glm::vec4& albedo = scene.materialOf(s.instance).baseColorFactor;

        // Each light's unshadowed share of the RGB sum and its reference
        // visibility; the sample is skipped when any light with a share is
        // undecided.
        double reference = 0.0;          // the RGB sum the reference predicts
        double smallestLit = INFINITY;   // the smallest share of a light it says reaches
        double smallestDark = INFINITY;  // ... of a light it says is blocked
        bool ambiguous = false;
        std::fill(darkLights.begin(), darkLights.end(), 0);
        for (size_t l = 0; l < scene.lights.size(); ++l) {
          const Light& light = scene.lights[l];
          glm::dvec3 toLight = -light.direction;
          double distance = INFINITY, irradiance = light.intensity;
          if (light.type != LightType::Directional) {
            toLight = light.position - p;
            distance = glm::length(toLight);
            toLight /= distance;
            irradiance = light.intensity / (distance * distance);
          }
          if (light.type == LightType::Spot) {
            // The cone's smooth falloff, as common/shading.cpp: outside the
            // outer cone no share under any visibility.
            const double cosOuter = std::cos(light.outerConeAngle), cosInner = std::cos(light.innerConeAngle);
            const double cd = glm::dot(light.direction, -toLight);
            const double t = std::clamp((cd - cosOuter) / std::max(1e-6, cosInner - cosOuter), 0.0, 1.0);
            if (t == 0.0) continue;
            irradiance *= t * t;
          }
          const double cosine = glm::dot(n, toLight);
          if (cosine <= 0.0) continue;  // faces away: no share under any visibility
          const double share = irradiance * cosine / kPi *
                               (double(albedo.r) * light.color.r + double(albedo.g) * light.color.g +
                                double(albedo.b) * light.color.b);
          if (cosine < minCosine || share < 1e-3) {
            ambiguous = true;
            break;
          }
          bool nearEdge = false;
          const bool occluded = blocked(p, toLight, distance, &nearEdge);
          if (!occluded && nearEdge) {
            ambiguous = true;
            break;
          }
          if (occluded) {
            darkLights[l] = 1;
            smallestDark = std::min(smallestDark, share);
          } else {
            reference += share;
            smallestLit = std::min(smallestLit, share);
          }
        }
        if (ambiguous) {
          ++out.ambiguous;
          continue;
        }
        if (smallestLit == INFINITY && smallestDark == INFINITY) continue;  // no light reaches this side
        const double sum = double(s.color.r) + double(s.color.g) + double(s.color.b);
        ++out.checked;
        for (size_t l = 0; l < darkLights.size(); ++l) out.shadowed[l] += darkLights[l];
        float& mark = out.pixels[pixel];
        if (std::isnan(mark)) mark = 0.0f;
        const bool acne = sum<reference - 0.5 * smallestLit, leak = sum> reference + 0.5 * smallestDark;
        if ((acne || leak) && texelWidth && nearShadowEdge(p, n)) {
          // The map's resolution, not its bias: counted apart.
          ++(acne ? out.edgeAcne : out.edgeLeaks);
          mark = std::max(mark, 3.0f);
        } else if (acne) {
          ++out.acne;
          mark = std::max(mark, 1.0f);
        } else if (leak) {
          ++out.leaks;
          mark = 2.0f;
        }
      }
    }
  return out;
}

TexelWidth shadowMapTexels(const Rendered& r) {
  const std::vector<std::string>& passes = r.run.output.passesRun;
  const bool maps = std::any_of(passes.begin(), passes.end(),
                                [](const std::string& p) { return p.rfind("shadow maps:", 0) == 0; });
  if (!maps) return {};
  const Scene* scene = &r.scene;
  const int size = r.settings.raster.shadowMapSize;
  return [scene, size](int light, const glm::dvec3& p) {
    const ShadowTexel t = shadowMapTexel(*scene, light, size, p);
    return std::array<glm::dvec3, 2>{t.side[0], t.side[1]};
  };
}

std::vector<float> pixelDifference(const FlatImage& a, const FlatImage& b) {
  if (a.width != b.width || a.height != b.height)
    throw std::logic_error("pixelDifference: images of different sizes");
  std::vector<float> d(a.color.size());
  for (size_t i = 0; i < d.size(); ++i) {
    const glm::vec4 e = glm::abs(a.color[i] - b.color[i]);
    // NaN compares false in max: make it count as maximally different.
    const float m = std::max(std::max(e.r, e.g), std::max(e.b, e.a));
    d[i] = finite4(e) ? m : INFINITY;
  }
  return d;
}

double fractionOff(const FlatImage& a, const FlatImage& b, double threshold) {
  const std::vector<float> d = pixelDifference(a, b);
  if (d.empty()) return 0.0;
  const auto off = std::count_if(d.begin(), d.end(), [&](float v) { return v > threshold; });
  return double(off) / double(d.size());
}

void addImage(Row& row, const ReportImage& image) {
  if (!image.first.empty()) row.images.push_back(image);
}

namespace {

// <reportDir>/<caseName>/<file>, the folder created; "" without a report.
std::string reportPath(const CaseContext& ctx, const std::string& caseName, const std::string& file) {
  if (ctx.reportDir.empty()) return "";
  std::filesystem::create_directories(std::filesystem::path(ctx.reportDir) / caseName);
  return (std::filesystem::path(ctx.reportDir) / caseName / file).string();
}

std::string barCaption(const std::string& caption, const ColorBar& bar) {
  char range[160];
  std::snprintf(range, sizeof range, " (%s: dark 0 .. bright %.3g)", bar.quantity.c_str(), bar.hi);
  return caption + range;
}

}  // namespace

ReportImage writeRenderImage(const CaseContext& ctx, const std::string& caseName, const std::string& file,
                             const FlatImage& image, const std::string& caption) {
  const std::string path = reportPath(ctx, caseName, file);
  if (path.empty()) return {};
  writePng(path, image);
  return {caseName + "/" + file, caption};
}

ReportImage writeDifferenceImage(const CaseContext& ctx, const std::string& caseName, const std::string& file,
                                 const FlatImage& a, const FlatImage& b, const std::string& caption) {
  const std::string path = reportPath(ctx, caseName, file);
  if (path.empty()) return {};
  const ColorBar bar = writeDifferenceHeatMap(path, a, b);
  return {caseName + "/" + file, barCaption(caption, bar)};
}

ReportImage writeMismatchImage(const CaseContext& ctx, const std::string& caseName, const std::string& file,
                               const VisibilityReport& visibility, const std::string& caption) {
  const std::string path = reportPath(ctx, caseName, file);
  if (path.empty()) return {};
  writeMismatchMap(path, visibility);
  return {caseName + "/" + file, caption};
}

ReportImage writeValueImage(const CaseContext& ctx, const std::string& caseName, const std::string& file,
                            int width, int height, const std::vector<float>& values,
                            const std::string& quantity, const std::string& caption) {
  const std::string path = reportPath(ctx, caseName, file);
  if (path.empty()) return {};
  const ColorBar bar = writeHeatMap(path, width, height, values, quantity);
  return {caseName + "/" + file, barCaption(caption, bar)};
}

std::string powerOfTen(double value) {
  const int exponent = int(std::lround(std::log10(std::fabs(value))));
  return std::string(value < 0 ? "-" : "") + "1e" + std::to_string(exponent);
}

}  // namespace rastray::stability
