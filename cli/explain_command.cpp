// `rastray explain SCENE X Y`: its options and what it prints (the
// explanation itself is app/crossval/explain.h).
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include "app/crossval/explain.h"
#include "cli/commands.h"
#include "cli/render_options_cli.h"
#include "common/error.h"

namespace rastray {

namespace {

struct ExplainOptions {
  std::string scenePath;
  int x = 0, y = 0;
  bool json = false;
  RenderSettings settings;  // from renderCli, once the command line is parsed
  RenderOptionsCli renderCli;
};

int runExplain(ExplainOptions& opt) {
  opt.settings = opt.renderCli.settings(/*allRenderers=*/true);
  const Scene scene = loadSceneForRender(opt.scenePath, opt.settings);
  if (opt.x < 0 || opt.y < 0 || opt.x >= opt.settings.camera.width() || opt.y >= opt.settings.camera.height())
    throw InputError(
        "command line", "X Y",
        "pixel (" + std::to_string(opt.x) + ", " + std::to_string(opt.y) + ") lies outside the image");
  const PixelExplanation e = explainPixel(scene, opt.settings, opt.x, opt.y);
  if (opt.json)
    std::cout << explanationJson(e).dump(2) << "\n";
  else
    std::fputs(explanationText(e).c_str(), stdout);
  return 0;
}

}  // namespace

CommandRunner addExplainCommand(CLI::App& app) {
  auto opt = std::make_shared<ExplainOptions>();
  CLI::App* cmd = app.add_subcommand(
      "explain",
      "Show every sample of one pixel as the rasterizer and the ray caster saw it, and why they differ");
  cmd->add_option("scene", opt->scenePath, "glTF 2.0 file")->required();
  cmd->add_option("x", opt->x, "Pixel column (0 = left)")->required();
  cmd->add_option("y", opt->y, "Pixel row (0 = top)")->required();
  cmd->add_flag("--json", opt->json,
                "Print the hits and every trace event as JSON (schema rastray.explain) for programs");
  opt->renderCli.add(*cmd, /*withRenderer=*/false);
  return [opt, cmd]() -> int { return cmd->parsed() ? runExplain(*opt) : -1; };
}

}  // namespace rastray
