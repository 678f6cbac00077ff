// What `rastray stability` prints and writes from the cases' rows: the
// table a person reads, the same as CSV and JSON for programs, the HTML
// report, and the README of the generated scene family (scenes/stiff/).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/studies/stability.h"

namespace rastray::stability {

// One case after it ran: its rows, or the error that stopped it (a case
// that throws is a failure of that case, reported like a failed property).
struct CaseResult {
  std::string name, group, parameters;
  bool quick = false;
  std::vector<Row> rows;
  std::string error;  // empty: the case ran
};

// "case / variant: property (measured ...)" for every row whose property
// does not hold, and "case: error" for every case that threw.
std::vector<std::string> failures(const std::vector<CaseResult>& results);

// The table, one line per case × variant, columns aligned: case, variant,
// agree% (visibility against the row's reference), genuine, nan/inf, acne,
// leaks, metric (name = value), time (s), result ("ok", "FAIL", or "-" for a
// row that asserts nothing) and the property. Unmeasured cells print "-".
std::string formatTable(const std::vector<CaseResult>& results);

// The same rows as CSV (RFC 4180 quoting), header line first:
//   case,group,variant,agreement,genuine,nan_inf,acne,leaks,metric_name,metric,seconds,property,pass
// Unmeasured numbers are empty cells; pass is "true" / "false".
std::string tableCsv(const std::vector<CaseResult>& results);

// {"quick": bool, "passed": bool, "failures": [..],
//  "cases": [{"name", "group", "parameters", "quick", "error",
//             "rows": [{"variant", "agreement", "genuine", "nanInf", "acne",
//                       "leaks", "metricName", "metric", "seconds",
//                       "property", "pass", "images": [{"file", "caption"}]}]}]}
// Unmeasured values (NaN, -1) are null.
nlohmann::json tableJson(const std::vector<CaseResult>& results, bool quick);

// DIR/index.html: the table, then per case its parameters and every row's
// images side by side with their captions (files the cases already wrote
// under DIR). Self-contained: no network resources.
void writeStabilityReport(const std::string& dir, const std::vector<CaseResult>& results,
                          const std::string& runLine);

// scenes/stiff/README.md: what the family is, how to regenerate it, and
// every case with its group, parameters and whether --quick runs it.
std::string sceneFamilyReadme(const std::vector<Case>& cases);

}  // namespace rastray::stability
