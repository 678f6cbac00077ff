// What a crossval keeps of each scene once it is rendered and compared, and
// the files that let `rastray crossval --report DIR --resume` skip the
// scenes an interrupted run finished.
//
// The summary holds every number the end of a run prints or writes (the
// table, --json, the failures, DIR/index.html), so a resumed run's outputs
// equal those of one uninterrupted run: the JSON below keeps doubles with
// round-trip precision (non-finite values as the strings "inf", "-inf",
// "nan"), so a summary read back is bit-identical to the one written.
//
// Files in the report folder:
// - DIR/crossval-run.json ("rastray.crossval.run", version 1): the render
//   options the scenes are made with (all given ones but --threads and
//   --max-memory, which change no result), their fingerprint, and an id of
//   the run; written when a run starts without --resume (or with --resume
//   into a folder without one).
// - DIR/<scene stem>/crossval-scene.json ("rastray.crossval.scene", version
//   1): the run id, the scene path as given, its file's size and
//   modification time, and the summary (the --json "scenes" element);
//   written after the scene's page, so its presence means the page is
//   complete.
// A resume refuses (exit 2) a folder whose run record has other options;
// it skips a scene whose record has the run's id, the same path and an
// unchanged file, and runs every other scene.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/crossval/crossval.h"

namespace rastray {

struct CrossvalSummary {
  std::string scenePath;
  int width = 0, height = 0;
  int spp = 0;
  // Counts, depth and cut-off statistics only (no examples, no per-pixel maps).
  VisibilityReport rasterVsRay, hybridVsRay;
  ColorMetrics rasterVsRayColor, hybridVsRayColor;        // mean, rms, psnr, max, maxAt, yee
  AgreeingColorStats rasterWhereAgree, hybridWhereAgree;  // layers, max
  double rasterSeconds = 0.0, raytraceSeconds = 0.0, hybridSeconds = 0.0;
};

CrossvalSummary summarize(const CrossvalResult& result, int spp);

// The element of `rastray crossval --json`'s "scenes" array: {scene, width,
// height, spp, rasterVsRaytrace: {visibility, color}, hybridVsRaytrace:
// {visibility, color}, seconds: {raster, raytrace, hybrid}}.
nlohmann::json summaryJson(const CrossvalSummary& summary);
// Reads it back; throws InputError naming `file` when a field is missing.
CrossvalSummary summaryFromJson(const nlohmann::json& j, const std::string& file);

constexpr const char* kCrossvalRunSchema = "rastray.crossval.run";
constexpr const char* kCrossvalSceneSchema = "rastray.crossval.scene";
constexpr int kCrossvalRecordVersion = 1;

struct CrossvalRunRecord {
  std::vector<std::string> options;  // as given on the command line
  std::string fingerprint;           // of `options`
  std::string run;                   // differs between runs started afresh
};

// The render options that decide a scene's results (toArgs): every option
// of renderOptionTable() the user gave but --threads and --max-memory.
std::vector<std::string> crossvalResultOptions(const RenderSettings& settings);
// "--size 64 48 --spp 4", or "(no render option)".
std::string describeOptions(const std::vector<std::string>& options);
// A new run record for these options (a fresh id).
CrossvalRunRecord newCrossvalRun(const std::vector<std::string>& options);

std::string crossvalRunPath(const std::string& reportDir);
std::string crossvalScenePath(const std::string& reportDir, const std::string& scenePath);

void writeRunRecord(const std::string& reportDir, const CrossvalRunRecord& run);
// nullopt when the folder has none; throws InputError on another schema
// or a malformed file.
std::optional<CrossvalRunRecord> readRunRecord(const std::string& reportDir);

void writeSceneRecord(const std::string& reportDir, const CrossvalRunRecord& run,
                      const CrossvalSummary& summary);
// The summary of `scenePath` finished by `run`, or nullopt (no record,
// another run, another path, or the scene file changed since: `why` says
// which when a record exists but does not count). Throws InputError on a
// malformed record.
std::optional<CrossvalSummary> readSceneRecord(const std::string& reportDir, const CrossvalRunRecord& run,
                                               const std::string& scenePath, std::string* why);

}  // namespace rastray
