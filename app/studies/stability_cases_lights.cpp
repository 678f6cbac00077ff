// Point and spot lights over the shadow maps' perspective forms: the far
// cases' scene at the origin (a 12 × 12 floor, a 1.5 box and a flat-shaded
// sphere of radius 1.5 floating 0.01 above it: contact shadows a bias must
// not open) lit by one point light low enough that the floor spreads over
// four faces of its cube map, or by one spot light whose cone holds box and
// sphere. The rasterizer (shadow maps) and the ray caster (shadow rays) are
// checked against the double-precision shadow reference (checkShadows):
// the maps must keep issue 24's bounds (0 leaks, acne <= 0.1 % of the
// checked samples, disagreements within one map texel of a shadow edge
// counted apart), the rays 0 acne and 0 leaks.
#include <cstdio>

#include "app/studies/stability.h"
#include "app/studies/stability_far_scene.h"
#include "app/studies/stability_measure.h"
#include "common/math_constants.h"

namespace rastray::stability {

namespace {

constexpr int kWidth = 480, kHeight = 320;
constexpr int kQuickWidth = 240, kQuickHeight = 160;
constexpr double kShadowTolerance = 1e-3;  // world units, as the far cases

GltfScene lightScene(const GltfLight& light) {
  GltfScene s = farScene({glm::dvec3(0.0), false, 0.01, false});
  s.lights = {light};
  return s;
}

std::vector<Row> runLight(const CaseContext& ctx, const std::string& name, const std::string& path) {
  const int w = ctx.quick ? kQuickWidth : kWidth, h = ctx.quick ? kQuickHeight : kHeight;
  std::vector<Row> rows;
  for (const char* renderer : {"raster", "raytrace"}) {
    const bool maps = std::string(renderer) == "raster";
    const Rendered r = renderVariant(
        ctx, path, {"--renderer", renderer, "--size", std::to_string(w), std::to_string(h), "--spp", "1"},
        true, renderer);
    const ShadowCheck shadows = checkShadows(r, kShadowTolerance, 0.1, shadowMapTexels(r));
    Row row;
    row.caseName = name;
    row.variant = maps ? "raster (shadow maps)" : "raytrace (shadow rays)";
    row.nanInf = countNanInf(r.run.output);
    row.acne = shadows.acne;
    row.leaks = shadows.leaks;
    row.metricName = "samples in shadow (checked)";
    row.metric = shadows.shadowed.empty() ? 0.0 : double(shadows.shadowed[0]);
    row.seconds = r.seconds();
    row.measures["shadow samples checked"] = double(shadows.checked);
    // The shadows must be in the picture for the bounds to mean anything.
    row.property = "no NaN/Inf, >= 1000 checked samples in shadow";
    row.pass = row.nanInf == 0 && row.metric >= 1000.0 && shadows.acne >= 0;
    if (maps) {
      row.property += ", 0 leaks, acne <= 0.1 % (" + std::to_string(shadows.checked) + " samples checked; " +
                      std::to_string(shadows.edgeAcne + shadows.edgeLeaks) + " within a texel of an edge)";
      row.pass = row.pass && row.leaks == 0 && double(row.acne) <= 1e-3 * double(shadows.checked);
    } else {
      row.property += ", 0 acne, 0 leaks (" + std::to_string(shadows.checked) + " samples checked)";
      row.pass = row.pass && row.acne == 0 && row.leaks == 0;
    }
    addImage(row, writeRenderImage(ctx, name, std::string(renderer) + ".png", r.image(), row.variant));
    addImage(row, writeValueImage(ctx, name, std::string(renderer) + "-shadows.png", r.image().width,
                                  r.image().height, shadows.pixels, "0 fine, 1 acne, 2 leak, 3 edge",
                                  "against the double-precision shadow reference (dark: not checked)"));
    rows.push_back(row);
  }
  return rows;
}

}  // namespace

void appendLightCases(std::vector<Case>& cases) {
  {
    Case c;
    c.name = "light-point-cube";
    c.group = "lights";
    c.parameters =
        "floor, box and sphere (r 1.5, flat) 0.01 above it; one point light at (-0.5, 3.5, 2.5): the floor "
        "spans four cube-map faces (-y, +x, -x, -z); 480x320 (quick 240x160), 1 spp; raster (maps) and "
        "raytrace vs the double reference";
    c.quick = true;
    c.build = [] {
      GltfLight light;
      light.type = "point";
      light.position = glm::dvec3(-0.5, 3.5, 2.5);
      light.intensity = 15.0f;
      return lightScene(light);
    };
    c.run = [](const CaseContext& ctx, const std::string& path) {
      return runLight(ctx, "light-point-cube", path);
    };
    cases.push_back(std::move(c));
  }
  {
    Case c;
    c.name = "light-spot";
    c.group = "lights";
    c.parameters =
        "floor, box and sphere (r 1.5, flat) 0.01 above it; one spot light at (2, 5, 4) towards (0, 0.5, 0), "
        "cone 25..35 deg; 480x320 (quick 240x160), 1 spp; raster (maps) and raytrace vs the double reference";
    c.quick = true;
    c.build = [] {
      GltfLight light;
      light.type = "spot";
      light.position = glm::dvec3(2.0, 5.0, 4.0);
      light.direction = glm::normalize(glm::dvec3(0.0, 0.5, 0.0) - light.position);
      light.intensity = 60.0f;
      light.innerConeAngle = float(25.0 * kPi / 180.0);
      light.outerConeAngle = float(35.0 * kPi / 180.0);
      return lightScene(light);
    };
    c.run = [](const CaseContext& ctx, const std::string& path) { return runLight(ctx, "light-spot", path); };
    cases.push_back(std::move(c));
  }
}

}  // namespace rastray::stability
