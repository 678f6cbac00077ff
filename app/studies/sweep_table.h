// A sweep's rows as files and as text: sweep.csv and sweep.json (one row
// per cell, every setting, time and error), reading them back (--resume,
// --merge), and the table printed for a person.
//
// Numbers are written with 17 significant digits, so a row read back is
// bit-identical to the row written (non-finite values as inf / -inf / nan in
// CSV, as those strings in JSON).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/studies/sweep.h"

namespace rastray::sweep {

// Schema of sweep.json; bump the version when a field changes meaning.
constexpr const char* kJsonSchema = "rastray.sweep";
constexpr int kJsonVersion = 1;

// What a sweep's files say about the sweep besides its rows.
struct SweepMeta {
  SweepSpec spec;
  std::string fingerprint;  // fingerprint(spec)
  size_t cells = 0;         // cells in the whole sweep (all shards)
  std::string shard;        // "K/N", "all", or "merged"
  std::string reference;    // how the reference was made
};

// The CSV columns, in order: cell, scene, one per --vary option (its name),
// args, width, height, repeat, then the times in seconds (load_s, build_s,
// frame_s, time_s, each a median followed by its _min_s and _max_s) and the
// errors (rms_error max_error perceptual_error visibility_error
// visibility_shared_edge depth_mean_abs depth_max_abs depth_mean_rel
// depth_max_rel depth_pixels pixels).
std::vector<std::string> csvColumns(const std::vector<VaryAxis>& vary);
// The columns that hold times: what may differ between two runs of a cell.
bool isTimeColumn(const std::string& column);

// Header line, then one line per row (RFC 4180 quoting).
std::string toCsv(const std::vector<VaryAxis>& vary, const std::vector<CellResult>& rows);
// Reads rows written by toCsv for the same vary list; throws InputError
// naming the file and line when the header or a field does not fit.
std::vector<CellResult> readCsv(const std::string& path, const std::vector<VaryAxis>& vary);

// {"schema": "rastray.sweep", "version": 1, "fingerprint", "sweep": {scenes,
//  vary: [{name, values}], options, reference, repeat}, "reference": text,
//  "cells", "shard", "rows": [{cell, scene, settings: {name: value}, args,
//  width, height, repeat, seconds: {load, build, frame, time: {median, min,
//  max}}, errors: {rms, max, perceptual, visibility, visibilitySharedEdge,
//  depth: {meanAbsolute,
//  maxAbsolute, meanRelative, maxRelative, pixels}, pixels}}]}
nlohmann::json toJson(const SweepMeta& meta, const std::vector<CellResult>& rows);
// Reads a sweep.json; throws InputError (file: path) on another schema or
// version or a malformed file.
void readJson(const std::string& path, SweepMeta& meta, std::vector<CellResult>& rows);

// The table for a person: one line per row, columns aligned; times in ms
// (median and min–max), errors with 3 significant digits, shares in %.
std::string formatTable(const std::vector<VaryAxis>& vary, const std::vector<CellResult>& rows);

}  // namespace rastray::sweep
