// The geometry cases of the stability study: sub-pixel triangles, slivers
// up to aspect ratio 1e6, pixel-aligned vertices and edges, grazing views
// and scenes 1e-4 and 1e4 units across. Scenes: app/studies/stability_geometry_scenes.h;
// coverage checks: app/studies/stability_coverage.h.
//
// Depth formats are varied only where the scene has surfaces close behind
// each other relative to their distance (the grazing lit plane and its
// box, 571..575 units away with znear 0.01); the other scenes have no
// overlapping surfaces, so the depth format cannot decide anything there.
#include <unistd.h>
#include <cstdio>
#include <filesystem>
#include <string>

#include "app/studies/stability.h"
#include "app/studies/stability_coverage.h"
#include "app/studies/stability_geometry_scenes.h"
#include "app/studies/stability_measure.h"
#include "common/sampling.h"

namespace rastray::stability {

namespace {

std::string fmt(const char* format, double v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

uint64_t nanInfOf(const CrossvalResult& r, const RenderRun& run) {
  return countNanInf(run.output) + countNanInf(r.raytrace.output);
}

// The two rows crossval gives for one variant: raster and hybrid against the
// ray caster (NaN/Inf of the renderer and the ray caster together).
Row crossvalRow(const std::string& caseName, const std::string& variant, const CrossvalResult& r,
                bool hybrid) {
  Row row;
  row.caseName = caseName;
  row.variant =
      (hybrid ? "hybrid vs raytrace" : "raster vs raytrace") + (variant.empty() ? "" : ", " + variant);
  const VisibilityReport& v = hybrid ? r.hybridVsRay : r.rasterVsRay;
  row.agreement = agreementOf(v);
  row.genuine = genuineOf(v);
  row.nanInf = nanInfOf(r, hybrid ? r.hybrid : r.raster);
  row.seconds = (hybrid ? r.hybrid : r.raster).seconds + r.raytrace.seconds;
  row.metricName = "silhouette-edge mismatches";
  row.metric = double(v.layers.count(MismatchClass::SilhouetteEdge));
  row.property = "0 genuine mismatches against the ray caster, no NaN/Inf";
  row.pass = row.genuine == 0 && row.nanInf == 0;
  return row;
}

void addCrossvalImages(const CaseContext& ctx, Row* row, const std::string& caseName, const std::string& tag,
                       const CrossvalResult& r) {
  addImage(*row,
           writeRenderImage(ctx, caseName, tag + "-raster.png", r.raster.output.image, "rasterizer " + tag));
  addImage(*row, writeRenderImage(ctx, caseName, tag + "-raytrace.png", r.raytrace.output.image,
                                  "ray caster " + tag));
  addImage(*row, writeMismatchImage(ctx, caseName, tag + "-mismatch.png", r.rasterVsRay,
                                    "visibility mismatches, rasterizer vs ray caster, by class " + tag));
}

std::vector<std::string> sizeArgs(int w, int h, int spp) {
  return {"--size", std::to_string(w), std::to_string(h), "--spp", std::to_string(spp)};
}

// Crossval of a w × h render at 1 spp, and at 4 too unless --quick: per
// sample count the raster row, then the hybrid row (crossvalRow), the
// 1-spp raster row with the crossval images. `measure(row, result, hybrid,
// spp)` completes each row first and returns the rows to add after it.
template <class Measure>
std::vector<Row> crossvalRowsPerSpp(const std::string& name, const CaseContext& ctx, const std::string& path,
                                    int w, int h, Measure measure) {
  std::vector<Row> rows;
  for (int spp : ctx.quick ? std::vector<int>{1} : std::vector<int>{1, 4}) {
    const CrossvalResult r = crossvalidateVariant(ctx, path, sizeArgs(w, h, spp));
    for (bool hybrid : {false, true}) {
      Row row = crossvalRow(name, "spp " + std::to_string(spp), r, hybrid);
      const std::vector<Row> after = measure(row, r, hybrid, spp);
      if (!hybrid && spp == 1) addCrossvalImages(ctx, &row, name, "spp1", r);
      rows.push_back(row);
      rows.insert(rows.end(), after.begin(), after.end());
    }
  }
  return rows;
}

// ---------------------------------------------------------------------------
// Sub-pixel triangles

std::vector<Row> runSubpixel(const std::string& name, const CaseContext& ctx, const std::string& path) {
  return crossvalRowsPerSpp(name, ctx, path, kSubpixelImageSize, kSubpixelImageSize,
                            [](Row&, const CrossvalResult&, bool, int) { return std::vector<Row>(); });
}

// ---------------------------------------------------------------------------
// Coverage counts of closed meshes (slivers, tiling): BLEND layers per sample

struct CoverageCounts {
  uint64_t holes = 0;    // interior samples covered by no triangle
  uint64_t doubles = 0;  // samples covered by two or more triangles of one instance
  uint64_t interior = 0;
};

// The largest aspect ratio (longest edge / height over it) among the fan's
// triangles as stored (float corners).
double largestAspect(const SliverLayout& L) {
  double worst = 0.0;
  const glm::dvec2 c(glm::vec2(L.fanCentre));
  for (size_t i = 0; i < L.fanBoundary.size(); ++i) {
    const glm::dvec2 a = L.fanBoundary[i], b = L.fanBoundary[(i + 1) % L.fanBoundary.size()];
    const double twiceArea = std::abs((a.x - c.x) * (b.y - c.y) - (a.y - c.y) * (b.x - c.x));
    const double longest = std::max({glm::length(a - c), glm::length(b - c), glm::length(b - a)});
    if (twiceArea > 0.0) worst = std::max(worst, longest * longest / twiceArea);
  }
  return worst;
}

// Fan (instance 0): interior = more than 1/64 pixel inside its outline
// (beyond the rasterizer's 1/256-pixel snapping and float rounding of the
// outline); bands (instances 1..3) have no interior that margin allows at
// their heights, so only double coverage is counted there.
CoverageCounts sliverCoverage(const SliverLayout& L, const DeepImage& deep, int spp) {
  CoverageCounts c;
  const std::vector<glm::dvec2> pattern = samplePositions(spp);
  for (uint32_t instance = 0; instance < 4; ++instance) {
    const auto per = trianglesPerSample(deep, spp, instance);
    for (size_t i = 0; i < per.size(); ++i) {
      if (per[i].size() > 1) ++c.doubles;
      if (instance == 0 && insideDistance(L.fanBoundary, sampleWorld(L.frame, pattern, i)) > 1.0 / 64.0) {
        ++c.interior;
        if (per[i].empty()) ++c.holes;
      }
    }
  }
  return c;
}

std::vector<Row> runSlivers(const std::string& name, const CaseContext& ctx, const std::string& path) {
  SliverLayout layout;
  sliverScene(&layout);  // the layout the written scene was made from
  return crossvalRowsPerSpp(
      name, ctx, path, layout.frame.width, layout.frame.height,
      [&](Row& row, const CrossvalResult& r, bool hybrid, int spp) {
        const CoverageCounts mine =
            sliverCoverage(layout, (hybrid ? r.hybrid : r.raster).output.samples, spp);
        const CoverageCounts ray = sliverCoverage(layout, r.raytrace.output.samples, spp);
        row.metricName = "holes + double-covered samples (this renderer, ray caster)";
        row.metric = double(mine.holes + mine.doubles + ray.holes + ray.doubles);
        row.property = "0 genuine mismatches, 0 holes, 0 double coverage in either renderer, no NaN/Inf";
        row.pass = row.pass && row.metric == 0.0;
        if (ctx.progress)
          ctx.progress(name + " " + row.variant + ": interior " + std::to_string(mine.interior) + ", holes " +
                       std::to_string(mine.holes) + "/" + std::to_string(ray.holes) + ", double " +
                       std::to_string(mine.doubles) + "/" + std::to_string(ray.doubles));
        return std::vector<Row>();
      });
}

// ---------------------------------------------------------------------------
// Pixel-aligned tiling

struct TieCounts {
  // Samples whose layers are not exactly [the top-left owner], strictly
  // inside the rectangle (shared-edge ties) and on its outline.
  uint64_t innerDiffers = 0, outlineDiffers = 0;
  uint64_t ownerDiffers() const { return innerDiffers + outlineDiffers; }
  uint64_t interiorWrong = 0;  // interior samples not covered exactly once
  uint64_t samples = 0;
};

TieCounts tilingTies(const TilingLayout& L, const DeepImage& deep, int spp) {
  TieCounts t;
  const std::vector<glm::dvec2> pattern = samplePositions(spp);
  const auto per = trianglesPerSample(deep, spp, 0);
  for (size_t i = 0; i < per.size(); ++i) {
    const glm::dvec2 p = sampleWorld(L.frame, pattern, i);
    std::vector<uint32_t> owners;
    for (uint32_t k = 0; k < L.triangles.size(); ++k) {
      const auto& tri = L.triangles[k];
      const glm::dvec2 lo = glm::min(tri[0], glm::min(tri[1], tri[2])),
                       hi = glm::max(tri[0], glm::max(tri[1], tri[2]));
      if (p.x < lo.x || p.x > hi.x || p.y < lo.y || p.y > hi.y) continue;
      if (ownsByTopLeft(L.frame, tri, p)) owners.push_back(k);
    }
    ++t.samples;
    const bool interior = p.x > L.lo.x && p.x < L.hi.x && p.y > L.lo.y && p.y < L.hi.y;
    if (per[i] != owners) ++(interior ? t.innerDiffers : t.outlineDiffers);
    if (interior && per[i].size() != 1) ++t.interiorWrong;
  }
  return t;
}

std::vector<Row> runTiling(const std::string& name, const CaseContext& ctx, const std::string& path,
                           uint32_t seed) {
  TilingLayout layout;
  pixelAlignedScene(&layout, seed);
  return crossvalRowsPerSpp(
      name, ctx, path, layout.frame.width, layout.frame.height,
      [&](Row& row, const CrossvalResult& r, bool hybrid, int spp) {
        const TieCounts mine = tilingTies(layout, (hybrid ? r.hybrid : r.raster).output.samples, spp);
        const TieCounts ray = tilingTies(layout, r.raytrace.output.samples, spp);
        row.metricName = "samples not owned by the exact top-left triangle (this renderer)";
        row.metric = double(mine.ownerDiffers());
        row.property =
            "0 genuine mismatches; the rasterizer's owner of every sample is the exact top-left one; "
            "every interior sample covered exactly once in both renderers";
        row.pass = row.pass && mine.ownerDiffers() == 0 && mine.interiorWrong == 0 && ray.interiorWrong == 0;
        row.measures["interior samples not covered once (this renderer)"] = double(mine.interiorWrong);
        row.measures["interior samples not covered once (ray caster)"] = double(ray.interiorWrong);
        if (ctx.progress)
          ctx.progress(name + " " + row.variant + ": owner differs " + std::to_string(mine.ownerDiffers()) +
                       " (ray caster " + std::to_string(ray.innerDiffers) + " inside, " +
                       std::to_string(ray.outlineDiffers) + " on the outline) of " +
                       std::to_string(mine.samples) + ", interior not once " +
                       std::to_string(mine.interiorWrong) + "/" + std::to_string(ray.interiorWrong));
        if (hybrid) return std::vector<Row>();
        // The ray caster's tie decisions, shown (SPEC §3 lets it pick
        // either triangle on a shared edge; outline ties are silhouettes).
        Row tie;
        tie.caseName = name;
        tie.variant = "raytrace ties, spp " + std::to_string(spp);
        tie.nanInf = countNanInf(r.raytrace.output);
        tie.metricName = "samples not owned by the exact top-left triangle (ray caster)";
        tie.metric = double(ray.ownerDiffers());
        tie.seconds = r.raytrace.seconds;
        return std::vector<Row>{tie};
      });
}

// ---------------------------------------------------------------------------
// Grazing views

constexpr int kGrazingW = 160, kGrazingH = 120;
// 10°: the rows run from 84.9° to the horizon (89.9° is 1.2 rows below it)
// and on to the sky, so the picture shows the checker fading into its
// coarsest mip level and the wall receding.
constexpr double kGrazingYfov = 10.0;
// checkShadows' edge tolerance: the far case's 1e-3 world units.
constexpr double kGrazingShadowTolerance = 1e-3;

std::vector<Row> runGrazing(const std::string& name, bool textured, const CaseContext& ctx,
                            const std::string& path) {
  std::vector<Row> rows;
  struct View {
    std::string label;
    std::vector<std::string> args;
  };
  std::vector<View> views = {{"", {}}};
  // Exactly edge-on: the eye in the plane (90°), where both renderers must
  // draw nothing of it and produce no NaN.
  if (!ctx.quick) views.push_back({"edge-on 90°", {"--eye", "0", "0", "0", "--target", "0", "0", "-1"}});
  std::vector<std::string> formats = {""};
  if (!textured && !ctx.quick) formats = {"", "float", "unorm24", "unorm16"};
  for (const View& view : views)
    for (const std::string& format : formats) {
      std::vector<std::string> args = sizeArgs(kGrazingW, kGrazingH, 1);
      args.insert(args.end(), view.args.begin(), view.args.end());
      if (!format.empty()) args.insert(args.end(), {"--depth-format", format});
      std::string variant = view.label;
      if (!format.empty()) variant += (variant.empty() ? "" : ", ") + format;
      const CrossvalResult r = crossvalidateVariant(ctx, path, args);
      for (bool hybrid : {false, true}) {
        if (hybrid && !format.empty()) continue;  // hybrid's depth format is the same story as raster's
        Row row = crossvalRow(name, variant, r, hybrid);
        if (!textured && !hybrid && format.empty()) {
          // Shown, not asserted: the rasterizer's shadow maps against traced
          // shadows under a grazing light.
          row.metricName = "pixels off by > 0.1 against the ray caster (shadow maps vs rays)";
          row.metric = fractionOff(r.raster.output.image, r.raytrace.output.image, 0.1);
        }
        if (!format.empty()) {
          row.metricName = "depth-tie mismatches";
          row.metric = double(r.rasterVsRay.layers.count(MismatchClass::DepthTie));
        }
        if (hybrid) {
          // Identical shading inputs where hits agree: hybrid's colours are
          // the ray caster's (crossval's --max-hybrid-error default 1e-5).
          row.metricName = "largest colour difference where hits agree";
          row.metric = r.hybridWhereAgree.maxError;
          row.property += ", colour = ray caster's within 1e-5 where hits agree";
          row.pass = row.pass && r.hybridWhereAgree.maxError <= 1e-5;
        }
        if (!textured && format.empty() && view.label.empty()) {
          // Acne and leaks of both lights against the double reference.
          // Every normal here is exact (an axis-aligned plane and wall),
          // so samples under the 89.9° light (n·l = 0.0017) count too; the
          // shadow it casts, 286 units wide, must stay: each of its
          // samples the map lit would be a leak.
          Rendered rendered{renderSettingsFrom(args, true), Scene{}, hybrid ? r.hybrid : r.raster};
          rendered.scene = loadSceneForRender(path, rendered.settings);
          const ShadowCheck shadows =
              checkShadows(rendered, kGrazingShadowTolerance, 1e-3, shadowMapTexels(rendered));
          row.acne = shadows.acne;
          row.leaks = shadows.leaks;
          const bool maps = bool(shadowMapTexels(rendered));
          row.property += std::string(", 0 leaks, acne <= 0.1 % of ") + std::to_string(shadows.checked) +
                          " samples checked, >= 1000 of them in the grazing light's shadow" +
                          (maps ? " (" + std::to_string(shadows.edgeAcne + shadows.edgeLeaks) +
                                      " within a map texel of an edge)"
                                : "");
          row.pass = row.pass && shadows.leaks == 0 &&
                     double(shadows.acne) <= 1e-3 * double(shadows.checked) && shadows.shadowed.size() == 2 &&
                     shadows.shadowed[1] >= 1000;
          row.measures["shadow samples checked"] = double(shadows.checked);
          row.measures["lights checked"] = double(shadows.shadowed.size());
          row.measures["samples checked in the grazing light's shadow"] =
              shadows.shadowed.size() == 2 ? double(shadows.shadowed[1]) : 0.0;
          addImage(row, writeValueImage(ctx, name, std::string(hybrid ? "hybrid" : "raster") + "-shadows.png",
                                        rendered.image().width, rendered.image().height, shadows.pixels,
                                        "0 fine, 1 acne, 2 leak, 3 edge",
                                        "against the double-precision shadow reference (dark: not checked)"));
        }
        if (textured && !hybrid) {
          const RenderSettings settings = renderSettingsFrom(args, true);
          const Scene scene = loadSceneForRender(path, settings);
          const LodStats lr = textureLod(scene, r.camera, r.raster.output.samples, 1);
          const LodStats lt = textureLod(scene, r.camera, r.raytrace.output.samples, 1);
          row.metricName = "largest texture LOD (lambda) of a shaded sample";
          row.metric = std::max(lr.maxLod, lt.maxLod);
          row.property += ", every texture LOD finite";
          row.pass = row.pass && lr.nonFinite == 0 && lt.nonFinite == 0;
          row.measures["non-finite texture LODs"] = double(lr.nonFinite + lt.nonFinite);
          if (ctx.progress)
            ctx.progress(name + " " + row.variant + ": textured samples " + std::to_string(lr.samples) + "/" +
                         std::to_string(lt.samples) + ", non-finite LOD " + std::to_string(lr.nonFinite) +
                         "/" + std::to_string(lt.nonFinite) + fmt(", max LOD %.2f", row.metric));
        }
        if (!hybrid && format.empty()) {
          const std::string tag = view.label.empty() ? "view" : "edge-on";
          addCrossvalImages(ctx, &row, name, tag, r);
          addImage(row, writeRenderImage(ctx, name, tag + "-hybrid.png", r.hybrid.output.image,
                                         "hybrid (shadow rays) " + tag));
          addImage(row, writeDifferenceImage(ctx, name, tag + "-raster-vs-ray.png", r.raster.output.image,
                                             r.raytrace.output.image, "|rasterizer − ray caster| " + tag));
        }
        rows.push_back(row);
      }
    }
  return rows;
}

// ---------------------------------------------------------------------------
// Scaled scenes

// A sample flips between the unit scene and a scaled one only when the
// float rounding of the scaled positions (relative 2^-24, ~1e-5 pixel at
// this size) or the 1/256-pixel snap of a vertex that rounding pushes
// across a snap boundary (probability ~1e-5 · 256 · 2 per vertex, moving
// an edge by 1/256 pixel) moves an edge across it: far below one sample in
// 19,200. Shading uses scale-free inputs (directional light, depth-format
// units for shadow-map bias, error bounds for ray offsets). 1e-3 (19
// pixels) leaves room for a few flips along silhouettes and shadow edges
// and still fails on any scale-dependent constant, which moves whole
// regions.
constexpr double kScaleBound = 1e-3;
constexpr int kScaleW = 160, kScaleH = 120;

std::vector<Row> runScale(const std::string& name, double scale, const CaseContext& ctx,
                          const std::string& path) {
  // The reference, the same generator at scale 1, written beside a temp name.
  const std::string refPath = (std::filesystem::temp_directory_path() /
                               ("rastray-stability-" + std::to_string(getpid()) + "-" + name + "-unit.gltf"))
                                  .string();
  scaledScene(1.0).write(refPath);
  struct Variant {
    std::string label;
    std::vector<std::string> args;
    bool asserts;
  };
  std::vector<Variant> variants = {{"raster", {"--renderer", "raster"}, true},
                                   {"raytrace", {"--renderer", "raytrace"}, true}};
  if (!ctx.quick) {
    variants.push_back({"raster unorm24", {"--renderer", "raster", "--depth-format", "unorm24"}, true});
    variants.push_back({"hybrid", {"--renderer", "hybrid"}, true});
    // The RTG ch. 6 offset has absolute constants (origin 1/32, float_scale
    // 1/65536): not scale-free, shown without asserting.
    variants.push_back(
        {"raytrace ray-offset=float-ulps", {"--renderer", "raytrace", "--ray-offset", "float-ulps"}, false});
  }
  std::vector<Row> rows;
  try {
    for (const Variant& v : variants) {
      std::vector<std::string> args = sizeArgs(kScaleW, kScaleH, 1);
      args.insert(args.end(), v.args.begin(), v.args.end());
      const Rendered ref = renderVariant(ctx, refPath, args, true, name + " " + v.label + " (unit scene)");
      const Rendered a = renderVariant(ctx, path, args, true, name + " " + v.label);
      const VisibilityReport vis = visibilityAgainst(a, ref);
      Row row;
      row.caseName = name;
      row.variant = v.label + " vs unit scene";
      row.agreement = agreementOf(vis);
      row.genuine = genuineOf(vis);
      row.nanInf = countNanInf(a.run.output);
      row.seconds = a.seconds();
      row.metricName = "pixels off by > 0.1 (fraction)";
      row.metric = fractionOff(a.image(), ref.image(), 0.1);
      // Acne and leaks against the double reference, its edge tolerance
      // scaled with the scene (1e-3 of the unit scene's ~8 units).
      const TexelWidth texels = shadowMapTexels(a);
      const ShadowCheck shadows = checkShadows(a, 1e-3 * scale, 0.1, texels);
      row.acne = shadows.acne;
      row.leaks = shadows.leaks;
      if (v.asserts) {
        row.property = "renders like the unit scene: < " + fmt("%g", kScaleBound) +
                       " of pixels off by > 0.1, 0 genuine mismatches, no NaN/Inf";
        row.pass = row.metric < kScaleBound && row.genuine == 0 && row.nanInf == 0;
        if (texels) {  // shadow maps (issue 24): the default biases at every scale
          row.property += ", 0 leaks, acne <= 0.1 % of " + std::to_string(shadows.checked) + " samples (" +
                          std::to_string(shadows.edgeAcne + shadows.edgeLeaks) +
                          " within a map texel of an edge)";
          row.pass = row.pass && shadows.leaks == 0 && double(shadows.acne) <= 1e-3 * double(shadows.checked);
          row.measures["shadow samples checked"] = double(shadows.checked);
        }
      }
      const std::string tag = v.label == "raster" || v.label == "raytrace" || !v.asserts ? v.label : "";
      if (!tag.empty()) {
        std::string file = tag;
        for (char& c : file)
          if (c == ' ' || c == '=') c = '-';
        addImage(row, writeRenderImage(ctx, name, file + ".png", a.image(),
                                       v.label + " at scale " + powerOfTen(scale)));
        addImage(row, writeDifferenceImage(ctx, name, file + "-diff.png", a.image(), ref.image(),
                                           "|scaled − unit scene|, " + v.label));
      }
      rows.push_back(row);
    }
  } catch (...) {
    std::filesystem::remove(refPath);
    throw;
  }
  std::filesystem::remove(refPath);
  return rows;
}

}  // namespace

void appendGeometryCases(std::vector<Case>& cases) {
  {
    Case c;
    c.name = "subpixel-sphere-dust";
    c.group = "slivers";
    c.parameters =
        "closed UV sphere of 384x192 quads (edges ~0.5 px), 3000 isolated triangles with edges 1e-3..1 px, "
        "96x96, spp 1 and 4";
    c.quick = true;
    c.build = [] { return subpixelScene(384, 3000, 9); };
    c.run = [name = c.name](const CaseContext& ctx, const std::string& path) {
      return runSubpixel(name, ctx, path);
    };
    cases.push_back(c);
  }
  {
    SliverLayout layout;
    sliverScene(&layout);
    Case c;
    c.name = "sliver-fan-aspect-1e6";
    c.group = "slivers";
    c.parameters =
        "closed fan of " + std::to_string(layout.fanBoundary.size()) +
        " triangles around a pixel centre, radius 36 px, sliver apex angles 1e-2..1e-6 (largest aspect " +
        fmt("%.2g", largestAspect(layout)) +
        " as stored), axes and diagonals through samples; strips of slivers on sample rows, heights "
        "2e-2, 2e-4, 2e-6 px; BLEND alpha 0.5, 160x128 orthographic, spp 1 and 4";
    c.build = [] {
      SliverLayout l;
      return sliverScene(&l);
    };
    c.run = [name = c.name](const CaseContext& ctx, const std::string& path) {
      return runSlivers(name, ctx, path);
    };
    cases.push_back(c);
  }
  {
    constexpr uint32_t kSeed = 3;
    Case c;
    c.name = "pixel-aligned-tiling";
    c.group = "slivers";
    c.parameters =
        "48x48 px rectangle on sample rows and columns, 3-px cells jittered by 1/2 px (vertices on pixel "
        "corners "
        "and centres), alternate triangles clockwise, BLEND alpha 0.5, 64x64 orthographic, spp 1 and 4";
    c.quick = true;
    c.build = [] {
      TilingLayout l;
      return pixelAlignedScene(&l, kSeed);
    };
    c.run = [name = c.name](const CaseContext& ctx, const std::string& path) {
      return runTiling(name, ctx, path, kSeed);
    };
    cases.push_back(c);
  }
  for (bool textured : {true, false}) {
    Case c;
    c.name = textured ? "grazing-textured-89.9" : "grazing-lit-89.9";
    c.group = "grazing";
    c.parameters =
        std::string(textured ? "checker-textured" : "lit (45° and 89.9° lights, a wall casting shadows)") +
        " plane 2e3 x 1e5 units, eye 1 unit above, view axis 89.9° from the normal, yfov 10°, 160x120" +
        (textured ? "" : ", every depth format") + "; and edge-on (90°)";
    c.quick = textured;
    c.build = [textured] { return grazingScene(textured, 89.9, kGrazingYfov); };
    c.run = [name = c.name, textured](const CaseContext& ctx, const std::string& path) {
      return runGrazing(name, textured, ctx, path);
    };
    cases.push_back(c);
  }
  for (double scale : {1e-4, 1e4}) {
    Case c;
    c.name = "scale-" + powerOfTen(scale);
    c.group = "scale";
    c.parameters = "floor, box, sphere and camera ~8 units across scaled by " + powerOfTen(scale) +
                   ", directional light, 160x120, against the same scene at scale 1";
    c.quick = scale > 1.0;
    c.build = [scale] { return scaledScene(scale); };
    c.run = [name = c.name, scale](const CaseContext& ctx, const std::string& path) {
      return runScale(name, scale, ctx, path);
    };
    cases.push_back(c);
  }
}

}  // namespace rastray::stability
