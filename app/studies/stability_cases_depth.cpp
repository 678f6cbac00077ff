// Depth-buffer precision: z-fighting by near/far ratio and depth format.
//
// Scene (one per ratio r = znear / zfar, 1e-1 .. 1e-7; zfar = 1000, znear =
// r · zfar): the camera at the origin looks down −Z; the image is cut into
// kColumns vertical strips, strip k holding a pair of quads at view depths
// around d_k, the d_k spaced evenly in log between 1.5 · znear and 0.8 ·
// zfar. The back quad (red) is the front quad (green) scaled about the eye
// by (1 + kGap) and widened by 2 % in the image, so it lies exactly kGap ·
// d behind the front one at every pixel (a relative gap: the same for every
// depth, so only the format decides). Both quads tilt (depth ×(1 ± 0.3)
// from bottom to top) so the stored depth varies across the strip and a
// format that cannot separate them z-fights in stripes, as real scenes do.
// The back quad is drawn first: with the `less` test an equal key keeps it,
// so a tie shows red where the ray caster (double-checked Embree hits, no
// depth buffer) shows green.
//
// Expected, from the resolutions in common/depth_formula.h: the relative
// resolution of float-reversed is ≤ 2^-23 ≈ 1.2e-7 at every depth, so a gap
// of kGap = 1e-5 is 80 steps and it never fights; unorm24 and float resolve
// ≈ (d / znear) · 2^-24 relative, so they fight from d / znear ≈ kGap · 2^24
// ≈ 170, i.e. at ratios of 1e-3 and below on the far strips; unorm16
// (d / znear) · 2^-16 from d / znear ≈ 0.66: everywhere.
//
// Measured per format against the ray caster (crossval's classification,
// compare/classify.h): agreement, genuine mismatches, and the z-fighting
// itself, "z-fight %": the share of samples where the ray caster sees a
// front quad and the rasterizer its back quad. The classifier calls a tie
// within the format's own resolution a depth tie, not genuine, so a format
// that z-fights shows low agreement and many depth ties but 0 genuine; a
// genuine mismatch would be a wrong surface the format's resolution does
// not explain. Asserted per format, from the formula alone: no z-fighting
// where its resolution is below half the gap at every strip, z-fighting
// where it exceeds twice the gap at some strip, and 0 genuine everywhere.
#include <cmath>
#include <cstdio>

#include "app/studies/stability.h"
#include "app/studies/stability_measure.h"
#include "common/depth_formula.h"
#include "raster/depth.h"

namespace rastray::stability {

namespace {

constexpr int kColumns = 8;
constexpr double kZfar = 1000.0;
constexpr double kGap = 1e-5;  // back quad behind the front one, relative to depth
constexpr double kYfov = 0.7;  // radians
constexpr int kWidth = 320, kHeight = 160;
constexpr int kQuickWidth = 160, kQuickHeight = 80;

const char* const kFormats[] = {"float-reversed", "float", "unorm24", "unorm16"};

// View-space point of NDC (x, y) at view depth d (camera at the origin
// looking down −Z, aspect kWidth / kHeight).
glm::dvec3 viewPoint(double x, double y, double d) {
  const double ty = std::tan(kYfov / 2.0), tx = ty * double(kWidth) / double(kHeight);
  return {x * tx * d, y * ty * d, -d};
}

// A planar quad in strip k: NDC x in [x0, x1], y in [-0.8, 0.8], depth
// d·(1 − 0.3 y) (near at the top). `grow` enlarges it about its centre
// within its own plane, `scale` then moves it along the eye rays (the
// plane through the scaled corners is the scaled plane).
GltfMesh stripQuad(double x0, double x1, double d, double scale, double grow, int material) {
  std::vector<glm::dvec3> corners;
  for (const auto& [x, y] : {std::pair{x0, -0.8}, {x1, -0.8}, {x1, 0.8}, {x0, 0.8}})
    corners.push_back(viewPoint(x, y, d * (1.0 - 0.3 * y)));
  const glm::dvec3 centre = 0.25 * (corners[0] + corners[1] + corners[2] + corners[3]);
  GltfMesh m;
  for (const glm::dvec3& p : corners)
    m.positions.push_back(glm::vec3((centre + (p - centre) * grow) * scale));
  m.indices = {0, 1, 2, 0, 2, 3};
  m.material = material;
  return m;
}

GltfScene zfightScene(double ratio) {
  GltfScene s;
  GltfMaterial front, back;
  front.baseColor = back.baseColor = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
  front.emissive = {0.1f, 0.8f, 0.2f};
  back.emissive = {0.9f, 0.1f, 0.1f};
  s.materials = {front, back};
  const double znear = ratio * kZfar;
  const double dMin = 1.5 * znear, dMax = 0.8 * kZfar;
  for (int k = 0; k < kColumns; ++k) {
    const double d = dMin * std::pow(dMax / dMin, double(k) / double(kColumns - 1));
    const double x0 = -1.0 + 2.0 * k / kColumns + 0.02, x1 = -1.0 + 2.0 * (k + 1) / kColumns - 0.02;
    // Back first: an equal depth key keeps what was drawn first.
    s.meshes.push_back(stripQuad(x0, x1, d, 1.0 + kGap, 1.02, 1));
    s.meshes.push_back(stripQuad(x0, x1, d, 1.0, 1.0, 0));
  }
  GltfCamera camera;
  camera.eye = glm::dvec3(0.0);
  camera.target = glm::dvec3(0.0, 0.0, -1.0);
  camera.yfov = kYfov;
  camera.znear = znear;
  camera.zfar = kZfar;
  s.camera = camera;
  return s;
}

// The front layer's instance of every sample, kNoId where nothing is hit.
std::vector<uint32_t> frontInstances(const DeepImage& image, int spp) {
  std::vector<uint32_t> front(size_t(image.width) * size_t(image.height) * size_t(spp), kNoId);
  for (size_t p = 0; p + 1 < image.offsets.size(); ++p)
    for (uint64_t i = image.offsets[p + 1]; i-- > image.offsets[p];) {  // back to front: the first layer wins
      const DeepSample& s = image.samples[i];
      if (s.sample < uint32_t(spp)) front[p * size_t(spp) + s.sample] = s.instance;
    }
  return front;
}

// Z-fighting: the share of the samples where the reference sees a front
// quad (odd instance: each pair is written back first) that show the back
// quad of the same pair instead.
double zfightShare(const Rendered& r, const Rendered& reference) {
  const int spp = reference.settings.spp;
  const std::vector<uint32_t> a = frontInstances(r.run.output.samples, spp),
                              b = frontInstances(reference.run.output.samples, spp);
  uint64_t fronts = 0, fights = 0;
  for (size_t i = 0; i < b.size(); ++i) {
    if (b[i] == kNoId || b[i] % 2 == 0) continue;
    ++fronts;
    if (a[i] == b[i] - 1) ++fights;
  }
  return fronts ? double(fights) / double(fronts) : 0.0;
}

// Whether `format` must z-fight somewhere in the scene (its view-depth
// resolution exceeds twice the gap at some strip's far end), or certainly
// cannot (below half the gap at every strip's near and far end); neither in
// between, where rounding decides sample by sample.
enum class Expect { Fights, Clean, Either };
Expect expectedFighting(DepthFormat format, double ratio) {
  const double znear = ratio * kZfar, dMin = 1.5 * znear, dMax = 0.8 * kZfar;
  double worst = 0.0;  // largest resolution / gap over the strips
  for (int k = 0; k < kColumns; ++k) {
    const double d = dMin * std::pow(dMax / dMin, double(k) / double(kColumns - 1));
    for (const double depth : {d * 0.76, d * 1.24})
      worst = std::max(
          worst, viewDepthResolution(format, Projection::Perspective, znear, kZfar, depth) / (kGap * depth));
  }
  return worst > 2.0 ? Expect::Fights : worst < 0.5 ? Expect::Clean : Expect::Either;
}

std::vector<Row> runZfight(const CaseContext& ctx, const std::string& name, const std::string& path,
                           double ratio) {
  const int w = ctx.quick ? kQuickWidth : kWidth, h = ctx.quick ? kQuickHeight : kHeight;
  const std::vector<std::string> common = {"--size", std::to_string(w), std::to_string(h), "--spp", "4"};
  auto args = [&](const std::string& renderer, std::vector<std::string> extra) {
    std::vector<std::string> a = {"--renderer", renderer};
    a.insert(a.end(), common.begin(), common.end());
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  };
  const Rendered reference = renderVariant(ctx, path, args("raytrace", {}), true, "raytrace");
  std::vector<Row> rows;
  Row ref;
  ref.caseName = name;
  ref.variant = "raytrace (reference)";
  ref.nanInf = countNanInf(reference.run.output);
  ref.seconds = reference.seconds();
  ref.property = "no NaN/Inf";
  ref.pass = ref.nanInf == 0;
  addImage(ref, writeRenderImage(ctx, name, "raytrace.png", reference.image(), "ray caster (reference)"));
  rows.push_back(ref);

  for (const char* format : kFormats) {
    const Rendered r = renderVariant(ctx, path, args("raster", {"--depth-format", format}), true,
                                     std::string("raster ") + format);
    const VisibilityReport v = visibilityAgainst(r, reference);
    Row row;
    row.caseName = name;
    row.variant = std::string("raster ") + format;
    row.agreement = agreementOf(v);
    row.genuine = genuineOf(v);
    row.nanInf = countNanInf(r.run.output);
    row.seconds = r.seconds();
    row.metricName = "z-fight %";
    row.metric = 100.0 * zfightShare(r, reference);
    const Expect expect = expectedFighting(r.settings.raster.depthFormat, ratio);
    row.property = "no NaN/Inf, 0 genuine";
    row.pass = row.nanInf == 0 && row.genuine == 0;
    if (expect == Expect::Clean) {
      row.property += ", no z-fighting (resolution < gap / 2)";
      row.pass = row.pass && row.metric == 0.0;
    } else if (expect == Expect::Fights) {
      row.property += ", z-fights (resolution > 2 gap), every tie a depth tie";
      row.pass = row.pass && row.metric > 0.0;
    }
    const uint64_t ties = v.layers.count(MismatchClass::DepthTie);
    const std::string stem = std::string("raster-") + format;
    addImage(row, writeRenderImage(
                      ctx, name, stem + ".png", r.image(),
                      std::string("rasterizer, ") + format + ": " + std::to_string(ties) + " depth ties"));
    addImage(row, writeMismatchImage(ctx, name, stem + "-mismatch.png", v,
                                     std::string(format) + " vs ray caster: mismatches by class"));
    rows.push_back(row);
  }
  return rows;
}

}  // namespace

void appendDepthCases(std::vector<Case>& cases) {
  for (int e = 1; e <= 7; ++e) {
    const double ratio = std::pow(10.0, -e);
    Case c;
    c.name = "zfight-ratio-" + powerOfTen(ratio);
    c.group = "depth";
    char znear[32];
    std::snprintf(znear, sizeof znear, "%g", ratio * kZfar);
    c.parameters =
        "near/far " + powerOfTen(ratio) + " (znear " + znear +
        ", zfar 1000); 8 quad pairs, depths 1.5 znear .. 0.8 zfar (log), gap 1e-5 of depth, tilt ±30 %; "
        "320x160 (quick 160x80), 4 spp; raster in every depth format vs the ray caster";
    c.quick = e == 3 || e == 6;
    c.build = [ratio] { return zfightScene(ratio); };
    const std::string name = c.name;
    c.run = [name, ratio](const CaseContext& ctx, const std::string& path) {
      return runZfight(ctx, name, path, ratio);
    };
    cases.push_back(std::move(c));
  }
}

}  // namespace rastray::stability
