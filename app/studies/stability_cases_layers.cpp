// Transparency and clipping under stress: 1,000 stacked BLEND layers and
// layers of alpha 1e-6 and 1 − 1e-6 against their analytic composite,
// triangles crossing the near plane and w = 0, and degenerate triangles.
//
// The layer scenes use emissive, unlit layers (base colour black, emissive
// E, no lights: the eye light's diffuse term is 0 · ... = 0), so a layer's
// premultiplied colour is exactly (E·α, α), one float product, whatever the
// view angle; the composite front to back is then
//   Σ_i (E_i α_i, α_i) Π_{j<i} (1 − α_j)
// computed here in double from the float values the file stores.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "app/studies/stability.h"
#include "app/studies/stability_measure.h"
#include "common/hit.h"
#include "common/math_constants.h"

namespace rastray::stability {

namespace {

std::vector<std::string> renderArgs(const CaseContext& ctx, std::vector<std::string> args) {
  if (ctx.threads > 0) args.insert(args.end(), {"--threads", std::to_string(ctx.threads)});
  return args;
}

std::vector<std::string> sizeArgs(int w, int h, int spp) {
  return {"--size", std::to_string(w), std::to_string(h), "--spp", std::to_string(spp)};
}

std::vector<std::string> concat(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

GltfMaterial emissiveMaterial(glm::vec3 emission, float alpha) {
  GltfMaterial m;
  m.baseColor = glm::vec4(0.0f, 0.0f, 0.0f, alpha);
  m.metallic = 0.0f;
  m.alphaMode = alpha < 1.0f ? "BLEND" : "OPAQUE";
  m.emissive = emission;
  return m;
}

GltfMesh quadAt(float z, float half, int material) {
  GltfMesh m;
  m.positions = {{-half, -half, z}, {half, -half, z}, {half, half, z}, {-half, half, z}};
  m.indices = {0, 1, 2, 0, 2, 3};
  m.material = material;
  return m;
}

GltfCamera lookDownZ(double yfov = 0.8) {
  GltfCamera c;
  c.eye = glm::dvec3(0.0);
  c.target = glm::dvec3(0.0, 0.0, -1.0);
  c.yfov = yfov;
  c.znear = 0.1;
  return c;
}

// --- stacked layers ------------------------------------------------------------------

// A stack of full-view quads, layer i at z = −1 − i · spacing with material
// i mod (number of materials), nearest first.
struct Stack {
  int layers = 0;
  std::vector<GltfMaterial> materials;
  float spacing = 0.01f;
};

GltfScene stackScene(const Stack& st) {
  GltfScene s;
  s.materials = st.materials;
  // Wide enough to fill the view at the deepest layer (yfov 0.8: half
  // height 0.42 per unit of depth).
  const float deepest = 1.0f + float(st.layers) * st.spacing;
  for (int i = 0; i < st.layers; ++i)
    s.meshes.push_back(quadAt(-1.0f - float(i) * st.spacing, deepest, i % int(st.materials.size())));
  s.camera = lookDownZ();
  return s;
}

// The composite of the stack, front to back, in double.
glm::dvec4 analyticComposite(const Stack& st) {
  glm::dvec4 sum(0.0);
  double transmittance = 1.0;
  for (int i = 0; i < st.layers; ++i) {
    const GltfMaterial& m = st.materials[size_t(i) % st.materials.size()];
    const double a = m.baseColor.a;
    sum += transmittance * glm::dvec4(glm::dvec3(m.emissive) * a, a);
    transmittance *= 1.0 - a;
  }
  return sum;
}

struct CompositeError {
  double absolute = 0.0;  // largest |rendered − analytic| over pixels and RGBA
  // Largest |Δ| / max(|analytic|, 1e-7) per channel: relative where the
  // channel is resolvable, absolute below 1e-7 (next to an alpha near 1, a
  // float composite has no room for less: ulp(1) = 6e-8).
  double relative = 0.0;
  uint64_t fewerLayers = 0;  // samples listing fewer layers than the stack in the deep output
};

CompositeError compositeError(const RenderOutput& out, const glm::dvec4& expected, int layers) {
  CompositeError e;
  for (const glm::vec4& c : out.image.color)
    for (int k = 0; k < 4; ++k) {
      const double d = std::abs(double(c[k]) - expected[k]);
      e.absolute = std::max(e.absolute, d);
      e.relative = std::max(e.relative, d / std::max(std::abs(expected[k]), 1e-7));
    }
  if (out.hasSamples) {
    // Per pixel, the samples' entries come sample by sample (DeepImage order).
    for (size_t p = 0; p + 1 < out.samples.offsets.size(); ++p) {
      int run = 0;
      uint32_t sample = UINT32_MAX;
      for (uint64_t i = out.samples.offsets[p]; i < out.samples.offsets[p + 1]; ++i) {
        const uint32_t s = out.samples.samples[i].sample;
        if (s != sample) {
          if (sample != UINT32_MAX && run < layers) ++e.fewerLayers;
          sample = s;
          run = 0;
        }
        ++run;
      }
      if (sample == UINT32_MAX || run < layers) ++e.fewerLayers;
    }
  }
  return e;
}

struct StackVariant {
  std::string label;
  std::vector<std::string> args;  // renderer and its options
  bool asserts = true;            // false: shows a failure mode, asserts nothing
};

std::vector<StackVariant> stackVariants(bool quick, bool withDefaultCutoff) {
  std::vector<StackVariant> v = {
      {"raster exact", {"--renderer", "raster", "--transparency", "exact"}},
      {"raytrace cutoff 0", {"--renderer", "raytrace", "--transparency-cutoff", "0"}},
  };
  if (!quick) {
    v.push_back({"raster sorted", {"--renderer", "raster", "--transparency", "sorted"}});
    v.push_back({"hybrid exact cutoff 0",
                 {"--renderer", "hybrid", "--transparency", "exact", "--transparency-cutoff", "0"}});
    if (withDefaultCutoff) v.push_back({"raytrace cutoff 1e-4 (default)", {"--renderer", "raytrace"}, false});
  }
  return v;
}

std::vector<Row> runStack(const CaseContext& ctx, const std::string& name, const std::string& path,
                          const Stack& st, bool relative, double tolerance, const std::string& property) {
  const int w = ctx.quick ? 32 : 64, h = ctx.quick ? 24 : 48;
  const glm::dvec4 expected = analyticComposite(st);
  std::vector<Row> rows;
  for (const StackVariant& v : stackVariants(ctx.quick, relative)) {
    // Sorted (painter's) compositing writes no per-layer deep list.
    const bool deep = v.label != "raster sorted";
    const Rendered r =
        renderVariant(ctx, path, renderArgs(ctx, concat(v.args, sizeArgs(w, h, 1))), deep, v.label);
    const CompositeError e = compositeError(r.run.output, expected, st.layers);
    Row row;
    row.caseName = name;
    row.variant = v.label;
    row.nanInf = countNanInf(r.run.output);
    row.seconds = r.seconds();
    row.metricName = relative ? "max relative error" : "max |composite - analytic|";
    row.metric = relative ? e.relative : e.absolute;
    if (v.asserts) {
      row.property = property;
      row.pass = row.nanInf == 0 && row.metric <= tolerance && e.fewerLayers == 0;
      row.measures["pixels with fewer layers than the stack"] = double(e.fewerLayers);
    }
    if (rows.empty() || !v.asserts)
      addImage(row, writeRenderImage(ctx, name, v.label.substr(0, v.label.find(' ')) + ".png", r.image(),
                                     v.label + " (uniform: every pixel composites the same stack)"));
    rows.push_back(row);
  }
  return rows;
}

Stack thousandLayers() {
  Stack st;
  st.layers = 1000;
  // Four materials in turn, alphas 0.001 .. 0.004: 8 % of the light still
  // passes the whole stack, so every layer counts in the composite.
  const glm::vec3 colours[4] = {
      {1.0f, 0.2f, 0.1f}, {0.1f, 1.0f, 0.3f}, {0.3f, 0.1f, 1.0f}, {0.7f, 0.7f, 0.7f}};
  for (int k = 0; k < 4; ++k) st.materials.push_back(emissiveMaterial(colours[k], 0.001f * float(k + 1)));
  return st;
}

// Sixteen layers of one alpha, emitting red, green and blue in turn, so the
// first three layers each own a channel.
Stack extremeLayers(float alpha) {
  Stack st;
  st.layers = 16;
  st.spacing = 0.05f;
  for (const glm::vec3& c : {glm::vec3(1, 0, 0), glm::vec3(0, 1, 0), glm::vec3(0, 0, 1)})
    st.materials.push_back(emissiveMaterial(c, alpha));
  return st;
}

// One triangle as a mesh (an instance) of its own.
void addTriangle(GltfScene& s, glm::vec3 a, glm::vec3 b, glm::vec3 c, int material) {
  GltfMesh m;
  m.positions = {a, b, c};
  m.indices = {0, 1, 2};
  m.material = material;
  s.meshes.push_back(m);
}

// --- near plane and w = 0 ---------------------------------------------------------------
//
// Camera at the origin looking down −Z (yfov 60°, znear 0.1, infinite far).
// Opaque emissive triangles: one with a vertex 3 behind the eye (a ceiling
// over the top of the view, cut by the near plane); a floor spanning 2e6
// through the eye plane (vertices at z = ±1e6); one with a vertex exactly
// on the eye plane (w = 0) beside the eye; one with a vertex at the eye
// itself (w = 0 and x = y = 0: its plane holds the eye, so it is seen
// edge-on and must cover nothing). The rasterizer clips them in homogeneous
// space; the ray caster intersects the world triangles.
GltfScene clipScene() {
  GltfScene s;
  s.materials = {emissiveMaterial({0.9f, 0.2f, 0.2f}, 1.0f), emissiveMaterial({0.2f, 0.9f, 0.2f}, 1.0f),
                 emissiveMaterial({0.2f, 0.2f, 0.9f}, 1.0f), emissiveMaterial({0.9f, 0.9f, 0.2f}, 1.0f)};
  // vertex behind the eye
  addTriangle(s, {-1.5f, 0.3f, -2.0f}, {1.5f, 0.3f, -2.0f}, {0.0f, 1.5f, 3.0f}, 0);
  // 2e6 across the eye plane
  addTriangle(s, {-1e6f, -0.5f, 1e6f}, {1e6f, -0.5f, 1e6f}, {0.0f, -0.5f, -1e6f}, 1);
  // a vertex at w = 0
  addTriangle(s, {3.0f, 0.3f, 0.0f}, {-0.6f, 0.05f, -1.0f}, {0.2f, 0.3f, -1.0f}, 2);
  // a vertex at the eye
  addTriangle(s, {0.0f, 0.0f, 0.0f}, {-2.0f, 0.5f, -4.0f}, {-1.0f, 1.5f, -4.0f}, 3);
  GltfCamera c = lookDownZ(60.0 * kPi / 180.0);
  s.camera = c;
  return s;
}

std::vector<Row> crossvalRows(const CaseContext& ctx, const std::string& name, const std::string& path, int w,
                              int h, const std::string& property,
                              const std::function<bool(Row&, const RenderRun&)>& extra) {
  const CrossvalResult x = crossvalidateVariant(ctx, path, renderArgs(ctx, sizeArgs(w, h, 4)));
  std::vector<Row> rows;
  struct Entry {
    const char* label;
    const RenderRun* run;
    const VisibilityReport* v;
  } entries[] = {{"raytrace", &x.raytrace, nullptr},
                 {"raster", &x.raster, &x.rasterVsRay},
                 {"hybrid", &x.hybrid, &x.hybridVsRay}};
  for (const Entry& e : entries) {
    Row row;
    row.caseName = name;
    row.variant = e.v ? std::string(e.label) + " vs raytrace" : e.label;
    row.nanInf = countNanInf(e.run->output);
    row.seconds = e.run->seconds;
    if (e.v) {
      row.agreement = agreementOf(*e.v);
      row.genuine = genuineOf(*e.v);
    }
    row.property = property;
    row.pass = row.nanInf == 0 && (!e.v || row.genuine == 0) && extra(row, *e.run);
    addImage(row, writeRenderImage(ctx, name, std::string(e.label) + ".png", e.run->output.image, e.label));
    if (e.v)
      addImage(row, writeMismatchImage(ctx, name, std::string(e.label) + "-mismatch.png", *e.v,
                                       std::string(e.label) + " vs ray caster: mismatches by class"));
    rows.push_back(row);
  }
  return rows;
}

// --- degenerate triangles ----------------------------------------------------------------
//
// An opaque backdrop (instance 0) behind five triangles of exactly zero
// world area (SPEC §1: they keep their IDs and cover nothing): three
// collinear points, three equal points, a needle from x = −1e6 to 1e6
// across the whole view, a needle pointing along the view direction
// (edge-on: it projects onto the pixels it passes), and the collinear one
// again as BLEND (the ray caster's filter path). Float coordinates make the
// zero area exact: collinear points share y and z, or lie on x = y.
constexpr uint32_t kDegenerateCount = 5;

GltfScene degenerateScene() {
  GltfScene s;
  s.materials = {emissiveMaterial({0.5f, 0.5f, 0.5f}, 1.0f), emissiveMaterial({1.0f, 0.0f, 0.0f}, 1.0f),
                 emissiveMaterial({0.0f, 1.0f, 0.0f}, 0.5f)};
  s.meshes.push_back(quadAt(-10.0f, 20.0f, 0));
  // collinear
  addTriangle(s, {0.0f, 0.0f, -5.0f}, {1.0f, 1.0f, -5.0f}, {2.0f, 2.0f, -5.0f}, 1);
  // three equal points
  addTriangle(s, {0.5f, -0.5f, -5.0f}, {0.5f, -0.5f, -5.0f}, {0.5f, -0.5f, -5.0f}, 1);
  // needle 2e6 long
  addTriangle(s, {-1e6f, 0.25f, -5.0f}, {1e6f, 0.25f, -5.0f}, {3.0f, 0.25f, -5.0f}, 1);
  // edge-on, along the view
  addTriangle(s, {0.3f, 0.1f, -2.0f}, {0.3f, 0.1f, -4.0f}, {0.3f, 0.1f, -8.0f}, 1);
  // collinear, BLEND
  addTriangle(s, {0.0f, 0.0f, -4.0f}, {-1.0f, -1.0f, -4.0f}, {-2.0f, -2.0f, -4.0f}, 2);
  s.camera = lookDownZ();
  return s;
}

// Samples (every layer of the deep output) that show anything but the backdrop.
uint64_t degenerateSamples(const RenderOutput& out) {
  uint64_t n = 0;
  for (const DeepSample& s : out.samples.samples)
    if (s.instance != 0) ++n;
  for (uint32_t id : out.image.instance)
    if (id != 0) ++n;
  return n;
}

Case makeCase(
    const std::string& name, const std::string& group, const std::string& parameters, bool quick,
    std::function<GltfScene()> build,
    std::function<std::vector<Row>(const CaseContext&, const std::string&, const std::string&)> run) {
  Case c;
  c.name = name;
  c.group = group;
  c.parameters = parameters;
  c.quick = quick;
  c.build = std::move(build);
  c.run = [name, run](const CaseContext& ctx, const std::string& path) { return run(ctx, name, path); };
  return c;
}

}  // namespace

void appendLayerCases(std::vector<Case>& cases) {
  cases.push_back(makeCase(
      "layers-1000", "layers",
      "1000 full-view emissive BLEND quads 0.01 apart, alphas 0.001..0.004 and four colours in turn (8 % "
      "passes); 64x48 (quick 32x24), 1 spp; raster exact and sorted, raytrace and hybrid with cutoff 0",
      true, [] { return stackScene(thousandLayers()); },
      [](const CaseContext& ctx, const std::string& name, const std::string& path) {
        return runStack(ctx, name, path, thousandLayers(), false, 1e-5,
                        "1,000 layers match the analytic composite to 1e-5");
      }));
  for (const auto& [label, alpha] : {std::pair{"1e-6", 1e-6f}, std::pair{"1-1e-6", 1.0f - 1e-6f}}) {
    const std::string name = std::string("layers-alpha-") + label;
    const float a = alpha;
    cases.push_back(makeCase(
        name, "layers",
        std::string("16 full-view emissive BLEND quads of alpha ") + label +
            ", red, green, blue in turn; 64x48 (quick 32x24), 1 spp; raster exact and sorted, raytrace and "
            "hybrid with cutoff 0, raytrace with the default cutoff (shows its declared cut-off)",
        false, [a] { return stackScene(extremeLayers(a)); },
        [a](const CaseContext& ctx, const std::string& caseName, const std::string& path) {
          return runStack(ctx, caseName, path, extremeLayers(a), true, 1e-4,
                          "composite matches the analytic one (relative 1e-4, floor 1e-7), all 16 layers in "
                          "every sample, no NaN/Inf");
        }));
  }
  cases.push_back(makeCase(
      "clip-near-w0", "clip",
      "camera at the origin, znear 0.1: a triangle with a vertex 3 behind the eye, a floor 2e6 across the "
      "eye plane, vertices at w = 0 and at the eye; 160x120 (quick 80x60), 4 spp; crossval",
      true, clipScene, [](const CaseContext& ctx, const std::string& name, const std::string& path) {
        const int w = ctx.quick ? 80 : 160, h = ctx.quick ? 60 : 120;
        return crossvalRows(ctx, name, path, w, h, "no NaN/Inf, 0 genuine mismatches against the ray caster",
                            [](Row&, const RenderRun&) { return true; });
      }));
  cases.push_back(makeCase(
      "degenerate", "clip",
      "backdrop behind 5 zero-area triangles: collinear, three equal points, a needle from -1e6 to 1e6, an "
      "edge-on needle along the view, a collinear BLEND one; 160x120 (quick 80x60), 4 spp; crossval",
      true, degenerateScene, [](const CaseContext& ctx, const std::string& name, const std::string& path) {
        const int w = ctx.quick ? 80 : 160, h = ctx.quick ? 60 : 120;
        return crossvalRows(
            ctx, name, path, w, h,
            "degenerate triangles cover nothing: no sample shows their IDs; raster.degenerate counts all 5",
            [](Row& row, const RenderRun& run) {
              const auto& values = run.output.counters.values;
              const bool rasterizes = std::any_of(
                  values.begin(), values.end(), [](const auto& v) { return v.first == "raster.degenerate"; });
              row.measures["samples showing a degenerate triangle"] = double(degenerateSamples(run.output));
              if (rasterizes)
                row.measures["raster.degenerate"] = double(run.output.counters.get("raster.degenerate"));
              return degenerateSamples(run.output) == 0 &&
                     (!rasterizes || run.output.counters.get("raster.degenerate") == kDegenerateCount);
            });
      }));
}

}  // namespace rastray::stability
