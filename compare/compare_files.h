// `rastray compare` as a library call: two SPEC §6 EXR files (flat or
// deep, from any renderer) in, visibility agreement with classified
// mismatches, depth and colour metrics out; plus thresholds, a readable
// table and a JSON report. Either file may hold any subset of the SPEC §6
// channels: without R, G and B in both (e.g. another renderer's Z + ID
// export) the colour metrics are skipped and the reports say why.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "common/camera.h"
#include "common/image.h"
#include "compare/color_metrics.h"
#include "compare/visibility.h"

namespace rastray {

struct CompareInputs {
  std::string pathA, pathB;
  std::string scenePath;  // empty: image-space classification
  PoseRequest pose;       // the scene's pose (--time, --animation), as the files were rendered
  CameraOverrides
      camera;   // applied to the scene's camera; znear/zfar alone also set the planes without a scene
  int spp = 0;  // 0: not given
  DepthFormat depthFormat = DepthFormat::FloatReversed;
  double edgeDistance = kDefaultEdgeDistance;
  // Each file is refused when reading it would allocate more (readExr).
  uint64_t maxImageBytes = kNoReadLimit;
};

struct CompareResult {
  std::string pathA, pathB, scenePath;
  std::string camera;  // Camera::describe() with a scene; empty otherwise
  bool sppInferred = false;
  VisibilityReport visibility;
  ColorMetrics color;              // all zero when colorSkipped is set
  std::string colorSkipped;        // why the colour metrics were skipped; empty: they were computed
  FlatImage colorA, colorB;        // the colours compared (deep files flattened)
  std::vector<std::string> notes;  // caveats for the reader, e.g. a file without IDs
};

// Throws InputError for unreadable files, kinds or sizes that differ, IDs
// outside the scene, and options the inputs cannot honour.
CompareResult compareFiles(const CompareInputs& inputs);

struct Thresholds {
  std::optional<double> minAgreement;  // layers (flat: pixels) agreeing / compared
  std::optional<uint64_t> maxGenuine;  // genuine mismatching layers (flat: pixels)
  std::optional<double> failRms;       // colour RMS error above this fails
};

// One line per violated threshold (empty: all passed). --fail-rms with the
// colour metrics skipped is a violation: a check that could not be made is
// not a pass.
std::vector<std::string> thresholdViolations(const CompareResult& result, const Thresholds& thresholds);

nlohmann::json toJson(const CompareResult& result, const Thresholds& thresholds,
                      const std::vector<std::string>& violations);
std::string formatTable(const CompareResult& result, const Thresholds& thresholds,
                        const std::vector<std::string>& violations);

// Classification mode in one line, e.g. "geometric (scene s.gltf, edge
// distance 0.0625 px)" or "image-space only (no --scene): ...".
std::string classificationSummary(const VisibilityReport& visibility, const std::string& scenePath);

}  // namespace rastray
