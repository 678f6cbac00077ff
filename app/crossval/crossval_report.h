// The cross-validation report: a self-contained folder (index.html, one
// page and its images per scene; no network resources) with the renders
// side by side, the visibility-mismatch map coloured by class with its
// legend, |ΔZ| and colour-difference heat maps with colour bars, the work
// counters, the passes left out and the timings.
#pragma once

#include <string>
#include <vector>

#include "app/crossval/crossval.h"
#include "app/crossval/crossval_record.h"

namespace rastray {

struct ReportExplanation {
  std::string key;   // mismatch class machine name
  std::string file;  // text file in the scene folder
};

// The report is written scene by scene, as each finishes (so an
// interrupted run keeps the pages of its finished scenes), then its index;
// every file atomically.
// DIR/<scene stem>/index.html and its images; `explanations` (may be
// empty) link mismatch classes to `rastray explain` output already written
// into that folder.
void writeCrossvalScenePage(const std::string& dir, const CrossvalResult& result,
                            const std::vector<ReportExplanation>& explanations);
// DIR/index.html: one row per scene, linking to the scene pages.
void writeCrossvalIndex(const std::string& dir, const std::vector<CrossvalSummary>& summaries,
                        const RenderSettings& settings);

}  // namespace rastray
