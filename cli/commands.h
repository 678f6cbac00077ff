// The rastray subcommands. Each registers its options on the CLI and
// returns the function that runs it (exit status per SPEC §7).
#pragma once

#include <functional>

#include <CLI/CLI.hpp>

namespace rastray {

using CommandRunner = std::function<int()>;

CommandRunner addInfoCommand(CLI::App& app);
CommandRunner addRenderCommand(CLI::App& app);
CommandRunner addCrossvalCommand(CLI::App& app);
CommandRunner addExplainCommand(CLI::App& app);
CommandRunner addCompareCommand(CLI::App& app);
CommandRunner addStabilityCommand(CLI::App& app);
CommandRunner addSweepCommand(CLI::App& app);
CommandRunner addBenchCommand(CLI::App& app);
CommandRunner addServeCommand(CLI::App& app);
CommandRunner addPovrayCommand(CLI::App& app);

}  // namespace rastray
