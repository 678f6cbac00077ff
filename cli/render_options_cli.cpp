#include "cli/render_options_cli.h"

#include <algorithm>

namespace rastray {

namespace {

// The camera rows and the pose (--time, --animation): what a command that
// looks at the scene without rendering it needs to see the same scene.
bool isCameraRow(const RenderOptionSpec& spec) {
  static const std::set<std::string> kCamera = {"--camera", "--eye",  "--target", "--up",   "--yfov",
                                                "--znear",  "--zfar", "--size",   "--time", "--animation"};
  return kCamera.count(spec.name) > 0;
}

}  // namespace

void RenderOptionsCli::add(CLI::App& cmd, bool withRenderer, Rows rows, const std::set<std::string>& except) {
  if (withRenderer)
    renderer_ = cmd.add_option("--renderer", rendererName_,
                               "raster, raytrace or hybrid (rasterized primary visibility, traced "
                               "shadow/reflection/refraction rays)")
                    ->default_str("raster");
  for (const RenderOptionSpec& spec : renderOptionTable()) {
    if ((rows == Rows::Camera && !isCameraRow(spec)) || except.count(spec.name)) continue;
    Entry& e = entries_.emplace_back();
    e.spec = &spec;
    const std::string help = helpWithWhere(spec);
    if (spec.arity == 0) {
      e.option = cmd.add_flag(spec.name, help);
    } else {
      e.option = cmd.add_option(spec.name, e.values, help)->expected(spec.arity)->allow_extra_args(false);
      const std::string shown = defaultText(spec);
      if (!shown.empty()) e.option->default_str(shown);
    }
  }
}

std::vector<std::string> RenderOptionsCli::args() const {
  std::vector<std::string> args;
  if (renderer_ && renderer_->count() > 0) args = {"--renderer", rendererName_};
  for (const Entry& e : entries_) {
    if (e.option->count() == 0) continue;
    if (e.spec->arity == 0) {
      args.push_back(e.spec->name);  // a flag given twice is on, as CLI11 has it
      continue;
    }
    // Each time given: the name and its values (renderSettingsFrom refuses
    // an option given more than once).
    const size_t arity = size_t(e.spec->arity);
    for (size_t i = 0; i < e.values.size(); i += arity) {
      args.push_back(e.spec->name);
      args.insert(args.end(), e.values.begin() + long(i),
                  e.values.begin() + long(std::min(i + arity, e.values.size())));
    }
  }
  return args;
}

bool RenderOptionsCli::given(const std::string& name) const {
  return std::any_of(entries_.begin(), entries_.end(),
                     [&](const Entry& e) { return e.spec->name == name && e.option->count() > 0; });
}

}  // namespace rastray
