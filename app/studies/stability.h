// The numerical-stability study behind `rastray stability`: a generated
// family of stiff and extreme scenes (scenes/stiff/), each rendered by each
// renderer under the variants that matter for it (depth formats, the
// far-from-origin mitigations on and off), measured against a reference and
// checked against the property the case exists to show.
//
// A case owns its scene generator (parameters visible in its name and
// `parameters`), its variants and its checks. Cases are grouped in files by
// theme (app/stability_cases_*.cpp), each contributing through one
// append function declared below; the command (cli/stability_command.cpp)
// runs them, prints the table and writes the report.
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "common/gltf/writer.h"

namespace rastray::stability {

// What the command passes to every case.
struct CaseContext {
  std::string sceneDir;   // where the case's generated .gltf files are (scenes/stiff or a temp dir)
  std::string reportDir;  // where to write images for the report; empty: write none
  bool quick = false;     // --quick: the case's cheapest representative variants only
  int threads = 0;        // 0: all cores
  // Render options added to every variant that draws shadow maps (the
  // rasterizer, hybrid with --shadows map), e.g. {"--shadow-bias", "1",
  // "0.25"} (stability --shadow-bias): to sweep the maps' settings over the
  // cases. Empty: the defaults.
  std::vector<std::string> shadowMapArgs;
  // One short line per finished render (may be empty).
  std::function<void(const std::string&)> progress;
};

// One row of the table: one case under one variant.
struct Row {
  std::string caseName;  // "zfight-ratio-1e-5"
  std::string variant;   // "raster unorm24", "raytrace origin=world ray-offset=float-ulps"
  // Visibility against the reference (for most cases the ray caster on the
  // same scene; for far-from-origin cases the same scene at the origin):
  // the fraction of compared samples whose hits agree, and the genuine
  // mismatches (compare/classify). NaN / -1: not measured for this row.
  double agreement = NAN;
  int64_t genuine = -1;
  uint64_t nanInf = 0;  // NaN or Inf values in colour, depth and deep samples
  // Lit samples darkened by their own surface / samples lit where a
  // double-precision reference says shadowed; -1: the case has no lights.
  int64_t acne = -1, leaks = -1;
  // A case-specific measurement, e.g. "TIR band offset (px)" = 0.4.
  std::string metricName;
  double metric = NAN;
  double seconds = 0.0;  // render time (frame only, not load)
  // The property this row asserts, in words, and whether it holds. Rows that
  // only show a failure mode (mitigation off) assert nothing: empty, true.
  std::string property;
  bool pass = true;
  // The quantities `pass` was decided on beyond the fields above, by name
  // ("interior samples not covered once (ray caster)" = 0): the tests hold
  // every row to thresholds of their own over these and the fields. Not
  // written to the table, CSV or JSON.
  std::map<std::string, double> measures;
  // Report images, paths relative to CaseContext::reportDir, each with a
  // caption: side-by-side renders and maps of where it goes wrong.
  std::vector<std::pair<std::string, std::string>> images;
};

struct Case {
  std::string name;        // file stem under scenes/stiff/ and row name
  std::string group;       // "depth", "far", "slivers", "grazing", "glass", "layers", "clip", "scale", "lights"
  std::string parameters;  // the generator's parameters in words: "near/far 1e-5, gap 1e-4 of depth"
  bool quick = false;      // part of the --quick subset (together under a minute on 2 cores)
  std::function<GltfScene()> build;  // the scene; written to <sceneDir>/<name>.gltf
  // Renders every variant of the case from the written file and measures.
  std::function<std::vector<Row>(const CaseContext&, const std::string& scenePath)> run;
};

// Every case, in table order: the groups' append functions in turn.
std::vector<Case> allCases();

// The groups (one file each).
// z-fighting by near/far ratio and depth format
void appendDepthCases(std::vector<Case>& cases);
// offsets 1e3..1e7, baked and node; acne and leaks
void appendFarCases(std::vector<Case>& cases);
// sub-pixel, slivers, pixel-aligned, grazing, scale
void appendGeometryCases(std::vector<Case>& cases);
// TIR band, nested dielectrics, trapped rays
void appendOpticsCases(std::vector<Case>& cases);
// 1,000 layers, extreme alphas, near plane / w = 0, degenerate
void appendLayerCases(std::vector<Case>& cases);
// point (cube map) and spot lights over the shadow maps
void appendLightCases(std::vector<Case>& cases);

}  // namespace rastray::stability
