// The render options as one typed value (RenderSettings) and the table
// that is the single source of every option's name, where it applies, its
// help, its parser and its formatter. Every front end reads the table: the
// CLI (cli/render_options_cli.h registers one CLI11 option per row), sweep
// cells and stability cases (renderSettingsFrom), serve's query parser and
// its /api/options (which the explorer draws its controls from), toArgs
// (the copy-ready command line) and docs/OPTIONS.md (checked by a test).
// No CLI11 here: the library parses argument lists itself.
//
// Adding an option: a row in render_options.cpp (its field here or in the
// renderer's options), the renderer that uses it, and docs/OPTIONS.md.
#pragma once

#include <optional>
#include <set>
#include <string>
#include <vector>

#include "app/engine/cli_options.h"
#include "common/memory_budget.h"
#include "common/render_output.h"
#include "common/scene.h"
#include "common/shading.h"
#include "raster/options.h"
#include "raytrace/ray_caster.h"

namespace rastray {

enum class RendererKind { Raster, Raytrace, Hybrid };
// --shadows: how a renderer decides whether a light reaches a point. Map:
// the rasterizer's shadow maps; Rays: shadow rays (the ray caster, and
// hybrid through the rasterizer's RasterShadows::Traced); None: all lit.
enum class ShadowMode { Map, Rays, None };
const char* toString(RendererKind kind);
// "raster", "raytrace", "hybrid"; nullopt for anything else.
std::optional<RendererKind> parseRendererKind(const std::string& name);

// A set of renderers, one bit per RendererKind.
using RendererSet = unsigned;
constexpr RendererSet rendererBit(RendererKind kind) { return 1u << unsigned(kind); }
constexpr RendererSet kAllRenderers = 0b111;

// Within its renderers, when an option applies.
enum class OptionCondition {
  Always,
  ShadowMaps,  // the renderer uses shadow maps (--shadows map)
  Wireframe,   // --wireframe is given
};

struct RenderSettings;

// One row of the render-option table.
struct RenderOptionSpec {
  const char* name;  // "--shadow-map-size"
  RendererSet renderers;
  OptionCondition condition;
  const char* help;
  int arity;            // values the option takes; 0: a flag
  const char* example;  // a value every renderer it applies to accepts ("" for flags)
  // Sets the option's field of `s` from its `arity` values; throws
  // InputError("command line", name, why) for a bad value.
  void (*parse)(RenderSettings& s, const std::vector<std::string>& values);
  // The option's values as parse() reads them back (the same field value);
  // empty for a flag, and for an option whose unset value has no spelling
  // (--shadows' renderer default, --eye taken from the file).
  std::vector<std::string> (*format)(const RenderSettings& s);
};

// The table, in --help order.
const std::vector<RenderOptionSpec>& renderOptionTable();
// The row named `name` ("--spp"), or nullptr.
const RenderOptionSpec* findRenderOption(const std::string& name);
// "raster and hybrid with --shadows map": where an option applies.
std::string describeWhereApplies(const RenderOptionSpec& spec);
// The help line with where the option applies in brackets, as --help shows it.
std::string helpWithWhere(const RenderOptionSpec& spec);
// The default value as one string ("2048", "8 6"); "" when it has no
// spelling (flags, --shadows, --max-memory, camera overrides).
std::string defaultText(const RenderOptionSpec& spec);
// The values of a multi-valued option written as one word: "320x240"
// (the documented form, as `sweep --vary`), "320,240" and "320:240" read
// the same. Returns `arity` non-empty words, or nullopt.
std::optional<std::vector<std::string>> splitOptionValue(const std::string& value, int arity);
// The values --shadows takes ("map", "rays", "none"), as it parses them.
std::vector<std::string> shadowModeNames();

struct RenderSettings {
  RendererKind renderer = RendererKind::Raster;
  int spp = 1;
  // --exposure: the output colour is scaled by 2^exposure (FrameRenderer).
  double exposure = 0.0;
  CameraOptions camera;
  RasterOptions raster;
  RayOptions ray;
  ShadingOptions shading;
  int threads = 0;  // 0: all cores
  bool keepSamples = false;
  std::optional<glm::ivec2> debugPixel;
  RenderOrigin renderOrigin = RenderOrigin::Camera;
  PoseRequest pose;                               // --time, --animation: the pose the scene is loaded at
  // --cull, for every renderer: finish() copies it into raster.cull; the ray
  // caster takes it when its BVH is built (FrameRenderer, serve's shared casters).
  CullMode cull = CullMode::None;
  std::optional<std::vector<size_t>> keptLights;  // --lights: nullopt keeps all; sorted, unique
  // --shadows as given; nullopt: map for the rasterizer, rays for the ray
  // caster and hybrid. finish() turns it into raster.shadows.
  std::optional<ShadowMode> shadows;
  // --max-memory; finish() sets MemoryBudget::machineDefault() when not given.
  MemoryBudget memory;
  // The rows the user gave (table names). An option given must apply to
  // the chosen renderer (with allRenderers: to one of them), even when the
  // value given is its default.
  std::set<std::string> given;
  // The command runs every renderer (crossval, explain) rather than the
  // one --renderer names.
  bool allRenderers = false;

  bool isGiven(const std::string& name) const { return given.count(name) > 0; }

  // Validates combinations and fills the renderer structures from the
  // shared fields (spp, shading, keepSamples); throws InputError("command
  // line", option, message).
  void finish();

  // Whether a table row applies to `kind` under these settings (after
  // finish()). With allRenderers, hybrid traces shadow rays whatever
  // --shadows says: crossval compares its colours with the ray caster's.
  bool applies(const RenderOptionSpec& spec, RendererKind kind) const;
  // The shadow technique `kind` uses under these settings (after finish()).
  ShadowMode shadowModeFor(RendererKind kind) const;
};

// Render options exactly as the command line gives them to `rastray render`
// (allRenderers false; "--renderer X" among them) or `crossval`
// (allRenderers true): each option's values parsed by its row, then
// finish(). How the CLI, the studies, sweep cells and serve's requests
// build settings. Throws InputError (file "command line", the option).
RenderSettings renderSettingsFrom(const std::vector<std::string>& args, bool allRenderers = false);

// The command line that gives these settings back (renderSettingsFrom of
// it is the same value): "--renderer X" unless allRenderers, then every
// option given, in table order, with its formatted values. `leaveOut`
// names options not to write (crossval's records leave out --threads).
std::vector<std::string> toArgs(const RenderSettings& settings, const std::set<std::string>& leaveOut = {});

// The table as Markdown rows (docs/OPTIONS.md holds it; a test checks it).
std::string renderOptionsMarkdown();

// The value of one option as its row formats it, words joined by spaces
// ("exact", "8 6"); for reports.
std::string optionText(const RenderSettings& settings, const std::string& name);

}  // namespace rastray
