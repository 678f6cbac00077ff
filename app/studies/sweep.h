// `rastray sweep`: what each render setting costs in time and buys in
// accuracy. A sweep is a set of scenes and named render options, each with
// a list of values (--vary NAME=V1,V2,...); every combination is one cell.
// Each cell is rendered K times (median and spread of the time) and
// compared with a reference: the colour error (RMS, max, Yee's perceptual
// test), how often the visible (instance, triangle) at the pixel centre
// differs, and the depth error where they agree.
//
// Cells are numbered deterministically (scenes outermost, then the --vary
// options in the order given, the last one fastest), so `--shard K/N`
// (every N-th cell starting at K) and `--resume` (skip the cells already in
// the CSV) name the same cells on every machine; a sweep's fingerprint
// (scenes, vary list, plain options, reference) keeps shards of different
// sweeps from being merged.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "app/engine/render_setup.h"
#include "common/image.h"
#include "compare/classify.h"

namespace rastray::sweep {

// One --vary: the option's name without dashes ("spp", "depth-format",
// "renderer") and its values as given. Options with several numbers take
// them joined by 'x' or ':' ("size=160x120", "eye=0:1:5", "polygon-offset=1:1");
// flags (wireframe, halo, no-packets) take on / off.
struct VaryAxis {
  std::string name;
  std::vector<std::string> values;
};

// Parses "NAME=V1,V2,..." (throws InputError naming --vary on bad syntax;
// names are checked by planCells).
VaryAxis parseVary(const std::string& text);

// The settings that make the reference `auto`: the ray caster at 64 spp
// (the 8×8 grid of cell centres, SPEC §3: 4× the largest Direct3D pattern,
// and at positions none of the 1-16 spp patterns uses, so a cell does not
// score an edge error of 0 merely by sharing the reference's samples),
// every transparent layer composited
// (--transparency-cutoff 0) and secondary rays to depth 16, the rest at
// their defaults (shadow rays, the file's texture samplers, origin camera,
// error-bound ray offsets). The cell's image size, camera options,
// culling and pose (--time, --animation) are added: they define the
// picture, not its quality.
const std::vector<std::string>& autoReferenceArgs();
// Options a cell passes on to its `auto` reference (picture, not quality).
bool definesPicture(const std::string& option);

struct SweepSpec {
  std::vector<std::string> scenes;
  std::vector<VaryAxis> vary;
  // Render options given plainly, in `rastray render` syntax ("--spp", "4");
  // they apply to every cell where they apply (as in crossval).
  std::vector<std::string> plainArgs;
  std::string reference = "auto";  // "auto" or a flat EXR file (SPEC §6)
  int repeat = 3;
};

// The sweep's identity: the same scenes, vary list (names and values in
// order), plain options and reference give the same fingerprint (16 hex
// digits of FNV-1a over describe()); K and shards do not change it.
std::string describe(const SweepSpec& spec);
std::string fingerprint(const SweepSpec& spec);

struct Cell {
  size_t index = 0;  // position in the whole sweep, from 0
  std::string scene;
  // One value per SweepSpec::vary entry: as given, or "n/a" where the
  // option does not apply to the cell's renderer (it is then left out).
  std::vector<std::string> values;
  std::vector<std::string> args;           // render syntax, "--renderer X" included
  std::vector<std::string> referenceArgs;  // auto only: autoReferenceArgs + the picture options
  RenderSettings settings;                 // args parsed (renderSettingsFrom)
};

// Every cell of the sweep, in order, each argument list parsed exactly as
// `rastray render` parses it. Combinations that differ only in options
// that do not apply (depth-format with the ray caster) are one cell, listed
// at the first of them. Throws InputError ("command line", "--vary NAME" or
// the option) for an unknown name, a bad value, or an option that applies
// to no cell, before anything renders.
std::vector<Cell> planCells(const SweepSpec& spec);

struct Shard {
  int k = 0, n = 1;  // cells with index % n == k
  bool contains(size_t index) const { return index % size_t(n) == size_t(k); }
};
// "K/N", 0 <= K < N; throws InputError naming --shard.
Shard parseShard(const std::string& text);

// Median, smallest and largest of K measurements (seconds).
struct TimeStats {
  double median = 0, min = 0, max = 0;
};
TimeStats timeStats(std::vector<double> seconds);

// The errors of one cell against its reference (see measureErrors).
struct CellErrors {
  double rms = 0, max = 0;  // colour, linear premultiplied RGBA (ImageBufAlgo compare)
  double perceptual = 0;    // share of pixels Yee's test sees as different
  // Share of pixels whose centre (instance, triangle) differs, not counting
  // shared-edge ties (the centre on the edge two triangles of one surface
  // share: either is right, SPEC §3), which are counted apart.
  double visibility = 0;
  double visibilitySharedEdge = 0;
  double depthMeanAbs = 0, depthMaxAbs = 0, depthMeanRel = 0, depthMaxRel = 0;
  uint64_t pixels = 0;       // width × height
  uint64_t depthPixels = 0;  // pixels both hit with the same IDs (the depth error's support)
};

// The reference of one cell: its resolved colour, and the Z and IDs at each
// pixel centre (a 1-spp render, whose only sample is the centre; a given
// EXR's Z and IDs, which are its sample nearest the centre: exactly the
// centre when it was rendered at 1 spp).
struct Reference {
  FlatImage color;
  FlatImage centre;
  std::string description;  // how it was made
  // Empty, or why no cell can equal the file, with the settings it needs (a
  // half-float colour: render it with --float, at --spp 1).
  std::string inexact;
};

// color: the cell's resolved image; centre: the cell's Z and IDs at the
// pixel centres (its own image at 1 spp, else a 1-spp render with the same
// settings: visibility at a point does not depend on the sample count).
// Both the reference's size (the caller checks). With `classifier` (the
// cell's scene and camera, compare/classify.h), each centre that differs is
// classified and shared-edge ties are counted apart; without, every
// difference counts. RMS and max come from
// compare/color_metrics.h over RGBA; the perceptual error is Yee's count
// over the pixel count (FLIP is not packaged for Debian). Depth: |z − z_ref|
// and |z − z_ref| / z_ref over pixels where both hit the same triangle.
CellErrors measureErrors(const FlatImage& color, const FlatImage& centre, const Reference& reference,
                         const ClassifierSettings* classifier = nullptr);

struct CellResult {
  size_t index = 0;
  std::string scene;
  std::vector<std::string> values;
  std::string args;  // the cell's render options, space-separated
  int width = 0, height = 0;
  int repeat = 0;
  // Per run: load (parse + flatten + rebase), BVH build (the ray caster's
  // Embree scene: raytrace and hybrid; 0 for raster), frame (the rest of
  // the render: raster setup, shadow maps, tiles, rays) and time = build +
  // frame, what a one-off render costs once the scene is loaded.
  TimeStats load, build, frame, time;
  CellErrors errors;
};

// Renders a cell's reference. With an EXR path, reads it once (through
// common/image.h readExr: the file's colour and its Z and IDs; a file
// without colour is refused).
class ReferenceSource {
 public:
  explicit ReferenceSource(std::string reference) : reference_(std::move(reference)) {}
  // Cached by scene and reference arguments: cells sharing size and camera
  // share one reference render.
  const Reference& referenceFor(const Cell& cell);

 private:
  std::string reference_;
  std::map<std::string, Reference> cache_;
};

// Renders the cell `repeat` times (loading the scene each time), measures
// the errors against `reference` (the first run's image; renders are
// deterministic). Throws InputError when the reference's size differs.
CellResult measureCell(const Cell& cell, int repeat, ReferenceSource& references);

}  // namespace rastray::sweep
