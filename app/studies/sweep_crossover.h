// `rastray sweep --crossover`: where the rasterizer and the ray caster cross
// over. Generated meshes of 1e2 to 1e7 triangles (app/bench/terrain_scene.h)
// are rendered at 320×240 to 3840×2160, 1 spp, by both renderers, each run in
// its own child process (`rastray render CELL.glb --json`, read back) so
// that each cell's peak memory is its own (app/bench/child_process.h).
//
// Per renderer, triangle count and size (one row):
// - time to primary visibility: the frame of the unlit variant of the scene
//   (emissive material, no light: no shadow map, no shadow ray, the colour
//   is the visible surface's flat colour), BVH build included;
// - time to a shaded frame: the frame of the lit variant (one directional
//   light: shadow map for the rasterizer, shadow rays for the ray caster;
//   diffuse shading), BVH build included;
// - the BVH build alone (ray caster), what a second frame of the same scene
//   would not pay;
// - the child's wall time (load, analysis, render, writing the image);
// - peak resident memory of each variant's process (libraries and the loaded
//   scene included).
// Times are the child's own (renderScene's clock), the fastest of 3 runs
// when a run takes under 5 s, else of 1: other work on the
// machine only ever adds time. A cell that runs out of memory (each
// child's address space is limited to 85% of the memory available when the
// study starts), is killed or times out is recorded as such, and the larger
// cells of that renderer (at least as many triangles and pixels) are then
// skipped and recorded as skipped; a cell that fails otherwise is recorded
// as failed with the child's message.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/report/svg_plot.h"

namespace rastray::crossover {

// Schema of crossover.json; bump the version when a field changes meaning.
constexpr const char* kJsonSchema = "rastray.crossover";
constexpr int kJsonVersion = 1;

struct ImageSize {
  int width = 0, height = 0;
};

struct CrossoverOptions {
  std::string reportDir;  // empty: ./crossover-report
  bool quick = false;     // at most 1e5 triangles and 640×480
  int threads = 0;        // each child's --threads (0: all cores)
  // Empty: the defaults for quick or the full study.
  std::vector<uint64_t> triangles;
  std::vector<ImageSize> sizes;
  std::string rastray;  // the binary each cell runs; empty: this process's own
  int maxRuns = 3;      // runs per scene variant when a run is short
  double cellTimeoutSeconds = 900;
  // Each child's address space; 0: 85% of the memory available at the start
  // (none in an AddressSanitizer build, whose shadow memory needs terabytes
  // of address space).
  uint64_t childMemoryLimitBytes = 0;
  bool progress = true;  // cells done and elapsed time to stderr when it is a terminal
  // Keep the cells an earlier, interrupted run of the same study left in
  // reportDir/crossover.json and measure only the rest.
  bool resume = false;
};

// 1e2, 1e3, ..., 1e7 (quick: to 1e5).
std::vector<uint64_t> defaultTriangles(bool quick);
// 320×240, 640×480, 1280×720, 1920×1080, 3840×2160 (quick: the first two).
std::vector<ImageSize> defaultSizes(bool quick);

struct CellResult {
  uint64_t triangles = 0;
  int width = 0, height = 0;
  std::string renderer;  // "raster" or "raytrace"
  std::string status;    // "ok", "out of memory", "killed", "timeout", "failed", "skipped"
  std::string detail;    // why, when not ok
  int runs = 0;          // runs per scene variant the fastest was taken from (the fewer of the two)
  double visibilitySeconds, shadedSeconds, bvhBuildSeconds, processSeconds;  // NaN: not measured
  // Peak resident memory of the visibility and of the shaded frame's
  // processes (the largest over their runs); 0: not measured.
  uint64_t visibilityPeakRssBytes = 0, shadedPeakRssBytes = 0;
  CellResult();
  bool ok() const { return status == "ok"; }
};

// What the rows were measured on, for the files and the report.
struct StudyMeta {
  bool quick = false;
  int threads = 0;  // as used: hardware threads when the option was 0
  std::string cpu;
  int hardwareThreads = 0;
  uint64_t memoryBytes = 0;       // MemTotal
  uint64_t childMemoryLimit = 0;  // RLIMIT_AS of each child; 0: none
  std::vector<uint64_t> triangles;
  std::vector<ImageSize> sizes;
  double seconds = 0;  // the whole study's wall time
  // The machine's 1-minute load average at the start and the end (NaN:
  // unknown): other work on the machine slows the cells down.
  double loadStart, loadEnd;
  StudyMeta();
};

// For one triangle count and size: which renderer is faster and by how much
// (slower / faster time, >= 1); renderer empty when either was not measured.
struct Winner {
  std::string renderer;
  double ratio = 0;
};
Winner winner(const std::vector<CellResult>& rows, uint64_t triangles, int width, int height, bool shaded);

// crossover.csv: header, then one line per row (RFC 4180 quoting); times in
// seconds, memory in bytes, unmeasured values empty. The columns, in order:
//   triangles,width,height,pixels,renderer,status,runs,visibility_s,shaded_s,
//   bvh_build_s,process_s,visibility_peak_rss_bytes,shaded_peak_rss_bytes,detail
std::vector<std::string> csvColumns();
std::string toCsv(const std::vector<CellResult>& rows);

// {"schema": "rastray.crossover", "version": 1, "quick", "threads",
//  "machine": {"cpu", "hardwareThreads", "memoryBytes", "loadAverage": {"start", "end"}},
//  "childMemoryLimitBytes",
//  "spp": 1, "scene": text, "triangles": [..], "sizes": [[w, h], ..], "seconds",
//  "rows": [{"triangles", "width", "height", "pixels", "renderer", "status",
//            "detail", "runs", "seconds": {"visibility", "shaded", "bvhBuild",
//            "process"}, "peakRssBytes": {"visibility", "shaded"}}],
//  "winners": [{"triangles", "width", "height",
//               "visibility": {"faster", "ratio"}, "shaded": {"faster", "ratio"}}]}
// Unmeasured values are null.
nlohmann::json toJson(const StudyMeta& meta, const std::vector<CellResult>& rows);
// Reads crossover.json back (the rows and what they were measured on), e.g.
// to write the report again; throws InputError (file: path) on another
// schema or version or a malformed file.
void readJson(const std::string& path, StudyMeta& meta, std::vector<CellResult>& rows);

// The plots: where each renderer wins (x triangles, y pixels, both log; one
// marker per cell in the faster renderer's series, labelled with the ratio)
// for the shaded frame and for primary visibility; the shaded frame's time
// and the peak memory against triangles at the smallest and largest size.
struct NamedPlot {
  std::string file;  // crossover-*.svg
  Plot plot;
};
std::vector<NamedPlot> crossoverPlots(const StudyMeta& meta, const std::vector<CellResult>& rows);

// The table printed for a person: one line per triangle count and size.
std::string formatTable(const std::vector<CellResult>& rows);

// What the options ask for: triangle counts, sizes, threads, the machine
// (InputError on counts or sizes out of range).
StudyMeta studyMeta(const CrossoverOptions& options);

// Measures every cell, in order (triangle count, size, renderer); `onCell`
// (may be empty) sees each row as it is done. A cell found in `finished`
// (same count, size and renderer) is taken from there, not measured. On a
// stop request (common/interrupt.h) the running child is stopped, the
// generated meshes are removed and Interrupted is thrown.
std::vector<CellResult> measureCells(
    const CrossoverOptions& options, StudyMeta& meta,
    const std::function<void(const CellResult&, size_t done, size_t total)>& onCell,
    const std::vector<CellResult>& finished = {});

// Writes DIR/crossover.csv and DIR/crossover.json (each atomically).
void writeCrossoverTables(const std::string& dir, const StudyMeta& meta, const std::vector<CellResult>& rows);
// The tables, DIR/crossover-*.svg and DIR/index.html (each atomically).
void writeCrossoverReport(const std::string& dir, const StudyMeta& meta, const std::vector<CellResult>& rows);

// The whole study: measures, prints the table, writes the report; the
// tables are written after every cell as well, so an interrupted study
// (exit 130/143, saying which cells finished) can be resumed. Exit status
// 0 when every cell ran or was recorded; 2 on bad options or a report
// folder holding another study (with resume).
int runCrossover(const CrossoverOptions& options);

}  // namespace rastray::crossover
