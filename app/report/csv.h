// CSV fields as RFC 4180 writes them: the sweep's, the crossover study's,
// the stability study's and the benchmark's CSV files all quote with
// csvQuote, and the sweep (--resume, --merge) and the tests read them back
// with readCsvRecord.
#pragma once

#include <istream>
#include <string>
#include <vector>

namespace rastray {

// One field, quoted (its quotes doubled) when it holds a comma, a quote or
// a line break; otherwise as it is.
std::string csvQuote(const std::string& field);

// Reads one record (one line, or more where a quoted field holds line
// breaks) into `fields`, unquoted; CRs outside quotes are dropped (CRLF
// line ends read as LF). False at the end of the input.
bool readCsvRecord(std::istream& in, std::vector<std::string>& fields);

}  // namespace rastray
