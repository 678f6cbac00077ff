// rastray: one glTF scene, two renderers, and where they differ.
//
// Exit status (SPEC §7): 0 success; 1 a comparison fell below its
// threshold; 2 bad usage or bad input, with one line on stderr naming the
// file and the offending element; 128 + the signal's number (130, 143)
// when Ctrl-C or SIGTERM stopped a render, crossval, sweep, bench or
// stability run (common/interrupt.h, cli/exit_status.h), after a line
// saying what it finished.
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli/commands.h"
#include "cli/exit_status.h"
#include "common/error.h"
#include "common/interrupt.h"
#include "common/one_line.h"

namespace {

// SPEC §7 promises one line: a message may quote the file's own strings
// (or a file name) with line breaks or other control characters in them.
void printErrorLine(const std::string& message) {
  std::fprintf(stderr, "%s\n", rastray::oneLine(message).c_str());
}

// An internal check failed (common/error.h): the library aborts after this.
void printCheckFailure(const std::string& message) {
  std::fprintf(stderr, "rastray: %s\n", message.c_str());
  std::fflush(stderr);
}

}  // namespace

int main(int argc, char** argv) {
  using namespace rastray;
  setCheckFailureHandler(&printCheckFailure);
  CLI::App app{
      "rastray: render one glTF scene with a z-buffer rasterizer and an Embree ray caster, "
      "and compare them sample by sample"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "rastray 0.1");
  std::vector<CommandRunner> commands;
  commands.push_back(addInfoCommand(app));
#ifdef RASTRAY_HAVE_RENDERERS
  commands.push_back(addRenderCommand(app));
  commands.push_back(addCrossvalCommand(app));
  commands.push_back(addExplainCommand(app));
  commands.push_back(addStabilityCommand(app));
  commands.push_back(addSweepCommand(app));
  commands.push_back(addBenchCommand(app));
  commands.push_back(addServeCommand(app));
  commands.push_back(addPovrayCommand(app));
#endif
  commands.push_back(addCompareCommand(app));

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp&) {
    std::printf("%s", app.help().c_str());
    return 0;
  } catch (const CLI::CallForAllHelp&) {
    std::printf("%s", app.help("", CLI::AppFormatMode::All).c_str());
    return 0;
  } catch (const CLI::CallForVersion&) {
    std::printf("rastray 0.1\n");
    return 0;
  } catch (const CLI::ParseError& e) {
    printErrorLine(std::string("rastray: ") + e.what() + " (see rastray --help)");
    return 2;
  }

  try {
    for (const CommandRunner& run : commands) {
      const int status = run();
      if (status >= 0) return status;
    }
    return 2;
  } catch (const Interrupted& e) {
    printErrorLine("rastray: " + e.message());
    return interruptedExitStatus(e.signal());
  } catch (const InputError& e) {
    printErrorLine(e.what());
    return 2;
  } catch (const std::bad_alloc&) {
    printErrorLine("rastray: out of memory");
    return 2;
  } catch (const std::exception& e) {
    printErrorLine(std::string("rastray: ") + e.what());
    return 2;
  }
}
