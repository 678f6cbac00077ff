// The render-option table (app/engine/render_options.h) on a CLI11
// command: one CLI11 option per row, its help and default from the row.
// CLI11 only collects the words the user gave; the rows' own parsers turn
// them into RenderSettings (renderSettingsFrom), as for every other front
// end (sweep cells, serve's queries), so they all accept the same values.
#pragma once

#include <deque>
#include <set>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "app/engine/render_options.h"

namespace rastray {

class RenderOptionsCli {
 public:
  enum class Rows {
    All,
    Camera,  // the SPEC §2 camera options, --size and the pose --time, --animation (info, compare)
  };
  // Registers --renderer (when `withRenderer`) and the rows, but those in `except`.
  void add(CLI::App& cmd, bool withRenderer, Rows rows = Rows::All, const std::set<std::string>& except = {});
  // The options given, as a command line ("--renderer X" first when given).
  std::vector<std::string> args() const;
  // The settings the options given say; throws InputError ("command line").
  RenderSettings settings(bool allRenderers) const { return renderSettingsFrom(args(), allRenderers); }
  bool given(const std::string& name) const;

 private:
  struct Entry {
    const RenderOptionSpec* spec = nullptr;
    CLI::Option* option = nullptr;
    std::vector<std::string> values;  // CLI11 stores the words here
  };
  std::deque<Entry> entries_;  // a deque: CLI11 holds the addresses of `values`
  CLI::Option* renderer_ = nullptr;
  std::string rendererName_;
};

}  // namespace rastray
