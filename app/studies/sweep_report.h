// The sweep's report for a person: log–log plots of each error against
// run time and a table of every cell, in one self-contained folder (no
// network resources): DIR/index.html with the plots inline, and each plot
// also as DIR/plots/<scene>-<error>-by-<option>.svg.
#pragma once

#include <string>
#include <vector>

#include "app/report/svg_plot.h"
#include "app/studies/sweep_table.h"

namespace rastray::sweep {

// One plotted error: its column's value in a row, and how the axis reads.
struct ErrorMetric {
  const char* key;       // file-name part: "visibility", "rms", ...
  const char* name;      // short, for the title
  const char* quantity;  // axis label
  const char* unit;      // "" for a share or a dimensionless ratio
  double (*of)(const CellResult&);
};
const std::vector<ErrorMetric>& errorMetrics();

struct SweepPlot {
  std::string file;  // under plots/
  Plot plot;
};

// For each scene, each error metric and each varied option: x = time
// (build + frame, median of K, seconds), y = the error, both log scale; one
// series per value of that option (the cells with that value; joined in
// the other option's order when exactly two options vary), and the Pareto
// front over all of the scene's cells (no other cell is both faster and
// more accurate) as a highlighted step line. Errors of 0 (the reference's
// own setting) cannot sit on a log axis: the plot counts them as skipped.
std::vector<SweepPlot> sweepPlots(const SweepMeta& meta, const std::vector<CellResult>& rows);

// Writes DIR/index.html and DIR/plots/*.svg (each atomically).
void writeSweepReport(const std::string& dir, const SweepMeta& meta, const std::vector<CellResult>& rows);

}  // namespace rastray::sweep
