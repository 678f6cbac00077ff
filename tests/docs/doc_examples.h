// The command examples of README.md and docs/*.md, read back so a test can
// run each one against the built binary. The marker convention (also in
// docs/TESTING.md, "Examples in the docs"):
//
//   ```sh             an example: every command line starts with `rastray `
//                     or `./build/rastray ` (a trailing `\` continues it);
//                     run in order in a scratch directory holding `scenes/`
//   ```sh serve       the first line starts a server (`rastray serve ...`),
//                     the others are `curl` lines run against it
//   ```sh serve pending: WHY  a serve block expected to fail until WHY is fixed
//   ```sh ci          lines that must appear verbatim in .ci/run
//   ```sh not-run: WHY  shown, not run; reported as a skip with WHY
//   ```sh pending: WHY  run, expected to fail until WHY is fixed (a skip);
//                     once it passes the test fails: remove the marker
//   ```text           sample output of the nearest ```sh block before it
//
// A command line may end in a comment of `;`-separated clauses:
//   exits N                 the expected exit status (default 0)
//   writes F [G ...]        files (or folders) it must leave behind
//   slow, tested with OPTS  the test overrides these options' values
//                           (e.g. `--frames 1 --size 160 120`)
#pragma once

#include <ostream>
#include <string>
#include <vector>

namespace rastray::test::docs {

struct Command {
  std::string line;  // continuations joined, comment removed
  int line_number = 0;
  int expected_status = 0;
  std::vector<std::string> writes;
  std::string tested_with;  // "" or the override options of a slow step
};

enum class BlockKind { Run, Serve, Ci, NotRun, Pending };

struct Block {
  std::string file;  // relative to the source tree, e.g. "docs/RENDER.md"
  int line_number = 0;
  BlockKind kind = BlockKind::Run;
  std::string reason;    // not-run and pending
  bool pending = false;  // a `sh serve pending:` block
  std::vector<Command> commands;
  std::vector<std::string> sample;  // lines of the ```text block(s) after it
  std::string error;                // a malformed block: the test fails with this
  std::string name() const;         // a test name: file and line, e.g. docs_RENDER_md_L40
};

// How gtest names a block in messages and test listings: "file:line".
void PrintTo(const Block& block, std::ostream* os);

// Every example block of one Markdown file (`relative` names it in messages).
std::vector<Block> parseMarkdown(const std::string& text, const std::string& relative);
// README.md and docs/*.md under `source_dir`, in file order.
std::vector<Block> loadBlocks(const std::string& source_dir);

// A command line with the options of `tested_with` given their values there
// (replacing the values the line gives, or appended when it has none).
std::string applyOverrides(const std::string& line, const std::string& tested_with);

// Output shape: numbers become `#` and runs of blanks one space, so a
// sample taken on another day (other times, other counts) still matches.
std::string normalise(const std::string& line);
// Whether every non-empty sample line (`...` lines excepted) occurs, in
// order, among the lines of `out` or, failing that, of `err` (each stream
// keeps its own order). `missing` gets the first line that did not.
bool matchesSample(const std::vector<std::string>& sample, const std::string& out, const std::string& err,
                   std::string* missing);

}  // namespace rastray::test::docs
