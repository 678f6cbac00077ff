// Far from the origin: a lit scene moved by 1e3 .. 1e7 in every
// coordinate, the offset either baked into the float32 vertex data or kept
// exact in the node translations, rendered by each renderer with the
// mitigations on (defaults: --origin camera, --ray-offset error-bound) and
// off (--origin world, --ray-offset float-ulps), and measured against the
// same scene at the origin.
//
// Scene (app/studies/stability_far_scene.h; local units, the offset adds to every
// coordinate): a 12 × 12 floor at y = 0; a 1.5 box and a sphere of radius
// 1.5 (24 × 12 facets, flat normals: no NORMAL attribute) both floating
// 0.01 above the floor, so their contact shadows are a 0.01 gap a ray
// offset must not jump; a mirror (metallic 1, roughness 0) behind them;
// one directional light. The camera looks down at them from (0, 4, 8).
//
// Per row:
// - visibility agreement and genuine mismatches against the origin render
//   of the same renderer (compare/classify.h, the origin scene's geometry);
// - "px off %": pixels whose colour differs from the origin render by more
//   than 0.1 in some RGBA channel (linear);
// - acne and leaks against a double-precision shadow reference
//   (checkShadows in app/studies/stability_measure.h: exact hit points and brute-
//   force double shadow rays in the file's frame).
// Baked data are themselves rounded to float32 (spacing 2^-4 at 1e6, 1 at
// 1e7): that geometry differs from the origin scene's before any renderer
// sees it, hence the looser 1 % target for baked 1e6 and none at 1e7.
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <unistd.h>

#include "app/studies/stability.h"
#include "app/studies/stability_far_scene.h"
#include "app/studies/stability_measure.h"

namespace rastray::stability {

namespace {

constexpr int kWidth = 480, kHeight = 320;
constexpr int kQuickWidth = 240, kQuickHeight = 160;
constexpr double kLift = 0.01;             // occluders float this far above the floor
constexpr double kShadowTolerance = 1e-3;  // world units, about 1/16 pixel here (checkShadows)
constexpr double kOffThreshold = 0.1;      // colour difference that makes a pixel "off"

// The study's scene: box and sphere kLift above the floor, mirror behind.
GltfScene caseScene(double offset, bool baked) { return farScene({glm::dvec3(offset), baked, kLift, true}); }

// The origin scene, written for the run beside nothing the user owns: a
// temporary file removed when the run ends.
class OriginScene {
 public:
  OriginScene() {
    static int counter = 0;
    path_ = (std::filesystem::temp_directory_path() /
             ("rastray-far-origin-" + std::to_string(getpid()) + "-" + std::to_string(counter++) + ".gltf"))
                .string();
    caseScene(0.0, false).write(path_);
  }
  ~OriginScene() {
    std::error_code ec;
    std::filesystem::remove(path_, ec);
  }
  OriginScene(const OriginScene&) = delete;
  OriginScene& operator=(const OriginScene&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

struct Variant {
  const char* renderer;
  bool mitigations;
};

std::vector<std::string> variantArgs(const Variant& v, int w, int h) {
  std::vector<std::string> a = {"--renderer",      v.renderer, "--size", std::to_string(w),
                                std::to_string(h), "--spp",    "1"};
  if (!v.mitigations) {
    a.insert(a.end(), {"--origin", "world"});
    if (std::string(v.renderer) != "raster") a.insert(a.end(), {"--ray-offset", "float-ulps"});
  }
  return a;
}

std::string variantName(const Variant& v) {
  const bool rays = std::string(v.renderer) != "raster";
  if (v.mitigations)
    return std::string(v.renderer) + " on (origin camera" + (rays ? ", ray-offset error-bound)" : ")");
  return std::string(v.renderer) + " off (origin world" + (rays ? ", ray-offset float-ulps)" : ")");
}

std::vector<Row> runFar(const CaseContext& ctx, const std::string& name, const std::string& path,
                        double offset, bool baked) {
  const int w = ctx.quick ? kQuickWidth : kWidth, h = ctx.quick ? kQuickHeight : kHeight;
  const OriginScene origin;
  std::vector<Row> rows;
  for (const char* renderer : {"raster", "raytrace", "hybrid"}) {
    const Rendered reference = renderVariant(ctx, origin.path(), variantArgs({renderer, true}, w, h), true,
                                             std::string(renderer) + " at the origin");
    const ShadowCheck referenceShadows =
        checkShadows(reference, kShadowTolerance, 0.1, shadowMapTexels(reference));
    for (const bool on : {true, false}) {
      const Variant v{renderer, on};
      const Rendered r = renderVariant(ctx, path, variantArgs(v, w, h), true, variantName(v));
      const VisibilityReport vis = visibilityAgainst(r, reference);
      const ShadowCheck shadows = checkShadows(r, kShadowTolerance, 0.1, shadowMapTexels(r));
      Row row;
      row.caseName = name;
      row.variant = variantName(v);
      row.agreement = agreementOf(vis);
      row.genuine = genuineOf(vis);
      row.nanInf = countNanInf(r.run.output);
      row.acne = shadows.acne;
      row.leaks = shadows.leaks;
      row.metricName = "px off %";
      row.metric = 100.0 * fractionOff(r.image(), reference.image(), kOffThreshold);
      row.seconds = r.seconds();
      row.measures["shadow samples checked"] = double(shadows.checked);

      // What this row asserts (mitigations off assert only "no NaN/Inf":
      // they exist to show the failure).
      std::string property = "no NaN/Inf";
      bool pass = row.nanInf == 0;
      const bool rayShadows = std::string(renderer) != "raster";
      if (on && !baked) {
        property += ", < 0.1 % px off";
        pass = pass && row.metric < 0.1;
      }
      if (on && baked && offset <= 1e6) {
        property += ", < 1 % px off";
        pass = pass && row.metric < 1.0;
      }
      if (on && rayShadows && offset <= 1e6) {
        property += ", 0 acne, 0 leaks";
        pass = pass && row.acne == 0 && row.leaks == 0;
      }
      // Shadow maps (issue 24): the default biases leave no leak and at
      // most 0.1 % acne; disagreements within a texel of a shadow edge are
      // the maps' resolution, counted apart and shown in the property.
      if (on && !rayShadows && (!baked || offset <= 1e6)) {
        property += ", 0 leaks, acne <= 0.1 % (" + std::to_string(shadows.checked) + " samples checked; " +
                    std::to_string(shadows.edgeAcne + shadows.edgeLeaks) + " within a texel of an edge)";
        pass = pass && row.leaks == 0 && double(row.acne) <= 1e-3 * double(shadows.checked);
      }
      row.property = property;
      row.pass = pass;

      const std::string stem = std::string(renderer) + (on ? "-on" : "-off");
      if (on)
        addImage(row, writeRenderImage(ctx, name, std::string(renderer) + "-origin.png", reference.image(),
                                       std::string(renderer) +
                                           ", the same scene at the origin (reference); shadow "
                                           "check there: acne " +
                                           std::to_string(referenceShadows.acne) + ", leaks " +
                                           std::to_string(referenceShadows.leaks)));
      addImage(row, writeRenderImage(ctx, name, stem + ".png", r.image(), variantName(v)));
      addImage(row, writeDifferenceImage(ctx, name, stem + "-diff.png", r.image(), reference.image(),
                                         "colour difference from the origin render"));
      addImage(row, writeMismatchImage(ctx, name, stem + "-mismatch.png", vis,
                                       "visibility against the origin render, by mismatch class"));
      addImage(row, writeValueImage(ctx, name, stem + "-shadows.png", r.image().width, r.image().height,
                                    shadows.pixels, "0 fine, 1 acne, 2 leak",
                                    "against the double-precision shadow reference (dark: not checked)"));
      rows.push_back(row);
    }
  }
  return rows;
}

}  // namespace

void appendFarCases(std::vector<Case>& cases) {
  for (const bool baked : {false, true})
    for (int e = 3; e <= 7; ++e) {
      const double offset = std::pow(10.0, e);
      Case c;
      c.name = std::string(baked ? "far-baked-" : "far-node-") + powerOfTen(offset);
      c.group = "far";
      c.parameters =
          std::string("floor, box and sphere (r 1.5, flat) 0.01 above it, mirror, one directional light; +") +
          powerOfTen(offset) + " on every coordinate " +
          (baked ? "baked into float32 vertex data" : "in node translations (local data exact)") +
          "; 480x320 (quick 240x160), 1 spp; each renderer, mitigations on and off, vs the origin scene";
      c.quick = e == 6;
      c.build = [offset, baked] { return caseScene(offset, baked); };
      const std::string name = c.name;
      c.run = [name, offset, baked](const CaseContext& ctx, const std::string& path) {
        return runFar(ctx, name, path, offset, baked);
      };
      cases.push_back(std::move(c));
    }
}

}  // namespace rastray::stability
