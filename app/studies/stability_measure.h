// The measurement toolkit every stability case uses: parse render options
// the way `rastray render` / `crossval` do, load and render one variant of a
// case, count NaN / Inf, compare visibility against a reference render or
// the ray caster, measure colour differences, and write the report's images.
// Kept small on purpose: a case reads as "render these variants, measure
// these numbers, assert this property".
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "app/crossval/crossval.h"
#include "app/engine/render_setup.h"
#include "app/studies/stability.h"
#include "common/image.h"
#include "common/render_output.h"
#include "common/scene.h"
#include "compare/visibility.h"

namespace rastray::stability {

// One variant of a case: the scene loaded and rebased for its settings
// (loadSceneForRender: --origin decides the frame), the render, and the
// settings used. run.camera is the camera in the scene's rebased frame;
// run.seconds the frame time (rendering only, not loading).
struct Rendered {
  RenderSettings settings;
  Scene scene;
  RenderRun run;
  const Camera& camera() const { return run.camera; }
  const FlatImage& image() const { return run.output.image; }
  double seconds() const { return run.seconds; }
};

// Loads `scenePath` for the options `args` (render syntax, "--renderer X"
// included; plus ctx.shadowMapArgs when the variant draws shadow maps) and
// renders it; deep = true keeps every sample and layer
// (run.output.samples), which the visibility comparisons need. Reports
// "<label>: <seconds> s" through ctx.progress when it is set.
Rendered renderVariant(const CaseContext& ctx, const std::string& scenePath,
                       const std::vector<std::string>& args, bool deep = true, const std::string& label = "");

// NaN or infinite values in a render: every colour channel of the image and
// of the deep samples, and every depth that is NaN, −inf, or +inf on a hit
// (+inf where nothing was hit is the SPEC §4 background, not an error).
uint64_t countNanInf(const RenderOutput& output);

// Visibility of `a` against `reference`, both deep (renderVariant with deep
// = true), same size and spp, same instance / triangle numbering (the same
// scene, or the same scene moved). Mismatches are classified as crossval
// does (compare/classify.h) against the reference's scene and camera: the
// geometry the reference shows is what `a` should show. The depth format
// deciding a depth tie is a's rasterizer depth format when a rasterizes
// (raster, hybrid), else the reference's, else float-reversed.
VisibilityReport visibilityAgainst(const Rendered& a, const Rendered& reference);

// Shorthands on a report: the fraction of compared layers whose hits agree,
// and the number of genuine mismatching layers.
double agreementOf(const VisibilityReport& v);
int64_t genuineOf(const VisibilityReport& v);

// Every renderer on one scene, as `rastray crossval` runs it (args in
// crossval syntax, no --renderer): raster and hybrid against the ray caster.
// Reports each stage through ctx.progress.
CrossvalResult crossvalidateVariant(const CaseContext& ctx, const std::string& scenePath,
                                    const std::vector<std::string>& args);

// Acne and leaks against a double-precision shadow reference.
//
// For every sample's front layer on a diffuse surface (no mirror weight, no
// transmission, no texture, no emission, opaque: where the shading is
// exactly Σ_l C/π · E_l · V_l · max(0, n·l), common/shading.h) the exact
// hit point is rebuilt in double in the file's world frame
// (Scene::worldPositions): the sample's camera ray, moved from the render's
// rebased frame by Camera::worldOrigin, met with the plane of the triangle
// the render names. A brute-force double shadow ray from there to each
// light is tested against every other triangle of the scene (cases are
// small). Whether the renderer lit the sample is read from its colour
// (the RGB sum), so one render suffices and any renderer (shadow rays or
// shadow maps) can be checked: with R the sum the reference predicts (the
// shares C/π · E_l · (n·l) of the lights it says reach, n the exact face
// normal turned to the viewer),
//   acne: the sum is below R by more than half the smallest share of a
//         light the reference says reaches the point (the renderer
//         darkened it);
//   leak: the sum is above R by more than half the smallest share of a
//         light the reference says is blocked (the renderer lit it).
// With one light this is "lit when the sum exceeds half the unshadowed
// sum". Samples the reference cannot decide are skipped: a light with
// 0 < n·l < `minCosine` (the terminator, where a renderer's float normal
// may legitimately flip; 0.1 by default, lower only where the normals are
// exact, e.g. an axis-aligned plane under a grazing light), or a shadow
// ray passing within `tolerance` (world units) of an occluder's edge, or
// a triangle within 1e-6 along the ray (a coplanar neighbour).
// Needs directional, point or spot lights (point and spot without range;
// a spot's cone falloff scales its share, and outside its outer cone it
// has none); otherwise (ranged lights, no light) acne and leaks are -1
// (not measured).
// With `texelWidth` (a shadow-map render: the two sides of light l's map
// texel near a point as world vectors, raster/shadow_map.h
// shadowMapTexel), a disagreeing sample whose reference visibility changes
// when the point moves in its plane to the next texel (either side, both
// ways) is a shadow edge the map cannot place closer: it counts in
// edgeAcne / edgeLeaks instead (one-texel lookups, no filtering), so acne
// and leaks measure the bias alone. Ray renderers pass none.
using TexelWidth = std::function<std::array<glm::dvec3, 2>(int light, const glm::dvec3& point)>;
struct ShadowCheck {
  int64_t acne = -1, leaks = -1;
  int64_t edgeAcne = 0, edgeLeaks = 0;  // within one map texel of a shadow edge (with texelWidth)
  uint64_t checked = 0;                 // samples decided and compared
  std::vector<uint64_t> shadowed;       // of them, by light: blocked from it by the reference
  uint64_t ambiguous = 0;               // skipped by the rules above
  // Per pixel: 0 fine, 1 acne in some sample, 2 a leak, 3 an edge
  // disagreement (with texelWidth), NaN not checked.
  std::vector<float> pixels;
};
ShadowCheck checkShadows(const Rendered& r, double tolerance, double minCosine = 0.1,
                         const TexelWidth& texelWidth = {});

// The texelWidth for checkShadows of a render that drew shadow maps (its
// passes say so), else empty.
TexelWidth shadowMapTexels(const Rendered& r);

// Colour difference of two same-size flat images: the largest |A − B| over
// the RGBA channels of each pixel (linear, premultiplied, as rendered).
// fractionOff: the share of pixels where it exceeds `threshold`.
std::vector<float> pixelDifference(const FlatImage& a, const FlatImage& b);
double fractionOff(const FlatImage& a, const FlatImage& b, double threshold);

// A report image: (path relative to CaseContext::reportDir, caption), the
// form of Row::images. Every writer below puts its file at
// <reportDir>/<caseName>/<file> (file: a name ending in .png) and returns the
// entry; with an empty reportDir it writes nothing and returns an empty
// path. addImage appends an entry to a row unless its path is empty.
using ReportImage = std::pair<std::string, std::string>;
void addImage(Row& row, const ReportImage& image);

// The render itself (sRGB PNG, common/image.h writePng).
ReportImage writeRenderImage(const CaseContext& ctx, const std::string& caseName, const std::string& file,
                             const FlatImage& image, const std::string& caption);
// Heat map of pixelDifference(a, b) (compare/maps.h); the caption gets the
// colour bar's range appended.
ReportImage writeDifferenceImage(const CaseContext& ctx, const std::string& caseName, const std::string& file,
                                 const FlatImage& a, const FlatImage& b, const std::string& caption);
// The visibility-mismatch map, one colour per class (compare/maps.h legend).
ReportImage writeMismatchImage(const CaseContext& ctx, const std::string& caseName, const std::string& file,
                               const VisibilityReport& visibility, const std::string& caption);
// Heat map of arbitrary per-pixel values (NaN: no value), e.g. acne and leak
// counts per pixel.
ReportImage writeValueImage(const CaseContext& ctx, const std::string& caseName, const std::string& file,
                            int width, int height, const std::vector<float>& values,
                            const std::string& quantity, const std::string& caption);

// "1e-05", "1e+06": how case names and variant labels print a power of ten.
std::string powerOfTen(double value);

}  // namespace rastray::stability
