// `rastray povray SCENE --renderer R ...`: rastray's shadow masks against
// POV-Ray 3.7's on the same flattened, opaque and diffuse scene
// (app/povray/povray_check.h), or the scene exported for POV-Ray alone.
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "app/engine/render_setup.h"
#include "app/povray/pov_export.h"
#include "app/povray/povray_check.h"
#include "cli/commands.h"
#include "cli/render_options_cli.h"
#include "common/error.h"
#include "common/image.h"
#include "common/interrupt.h"

namespace rastray {

namespace {

struct PovrayOptions {
  std::string scenePath;
  std::string povPath;    // --pov
  std::string masksPath;  // --masks
  bool exportOnly = false;
  bool json = false;
  double maxDisagreement = -1.0;  // percent of the lit pixels; < 0: not checked
  RenderSettings settings;
  RenderOptionsCli renderCli;
};

int runPovray(PovrayOptions& opt) {
  opt.settings = opt.renderCli.settings(/*allRenderers=*/false);
  if (opt.exportOnly && opt.povPath.empty())
    throw InputError("command line", "--export-only", "needs --pov FILE to write the scene to");
  const std::string& masks = opt.masksPath;
  if (!masks.empty() && (masks.size() < 4 || masks.compare(masks.size() - 4, 4, ".png") != 0))
    throw InputError("command line", "--masks", "'" + opt.masksPath + "' must end in .png");
  if (!opt.exportOnly && opt.settings.spp != 1)
    throw InputError(
        "command line", "--spp",
        "the POV-Ray check compares one sample per pixel (POV-Ray traces the pixel centre): give "
        "--spp 1");
  installInterruptHandlers();
  Scene scene = loadSceneForRender(opt.scenePath, opt.settings);
  if (!opt.exportOnly && scene.lights.empty())
    throw InputError(scene.path, "lights",
                     "the scene has no light (lit by the eye light): no shadows to compare");
  std::string povray;
  if (!opt.exportOnly) {
    povray = findPovray();
    if (povray.empty())
      throw InputError("povray", "",
                       "not found on PATH: install POV-Ray 3.7 (Debian package povray), or write the scene "
                       "alone with --export-only --pov FILE");
  }

  if (opt.exportOnly) {
    makeOpaqueDiffuse(scene);
    const Camera camera = makeCamera(scene, opt.settings.camera.overrides(), opt.settings.camera.width(),
                                     opt.settings.camera.height());
    writeTextFile(opt.povPath, povSceneText(scene, camera));
    std::printf("%s: %dx%d, every material opaque and diffuse -> %s\n", scene.path.c_str(), camera.width,
                camera.height, opt.povPath.c_str());
    return 0;
  }

  const PovrayCheck check = runPovrayCheck(std::move(scene), opt.settings, povray);
  if (!opt.povPath.empty()) writeTextFile(opt.povPath, check.povSource);
  if (!opt.masksPath.empty()) writeImage(opt.masksPath, shadowMaskPicture(check.ours, check.povray));

  const ShadowMaskAgreement& a = check.agreement;
  const double percent = 100.0 * a.disagreeingFraction();
  if (opt.json) {
    std::cout << povrayCheckJson(opt.scenePath, opt.settings, check).dump(2) << "\n";
  } else {
    std::printf(
        "%s: %s %dx%d, shadow masks against POV-Ray (every material opaque and diffuse): %zu of %zu lit "
        "pixels "
        "differ (%.3f %%)\n"
        "  shadowed: %zu here, %zu in POV-Ray; shadowed here and lit there %zu, lit here and shadowed there "
        "%zu, "
        "light reaches one only %zu (POV-Ray %.1f s)\n",
        opt.scenePath.c_str(), toString(opt.settings.renderer), check.camera.width, check.camera.height,
        a.disagreeing(), a.litReference, percent, a.shadowedOurs, a.shadowedReference, a.oursShadowedRefLit,
        a.oursLitRefShadowed, a.litInOneOnly, check.povraySeconds);
  }
  if (opt.maxDisagreement >= 0.0 && percent > opt.maxDisagreement) {
    std::fprintf(stderr, "%s: %.3f %% of the lit pixels differ, above --max-disagreement %g %%\n",
                 opt.scenePath.c_str(), percent, opt.maxDisagreement);
    return 1;
  }
  return 0;
}

}  // namespace

CommandRunner addPovrayCommand(CLI::App& app) {
  auto opt = std::make_shared<PovrayOptions>();
  CLI::App* cmd = app.add_subcommand("povray",
                                     "Compare a renderer's shadow masks with POV-Ray 3.7's on the same scene "
                                     "made opaque and diffuse, or export "
                                     "that scene for POV-Ray");
  cmd->add_option("scene", opt->scenePath, "glTF 2.0 file")->required();
  cmd->add_option("--pov", opt->povPath, "Write the POV-Ray scene (SDL) rendered to this file");
  cmd->add_flag("--export-only", opt->exportOnly, "Write the scene with --pov and stop (POV-Ray is not run)");
  cmd->add_option("--masks", opt->masksPath,
                  "Write a PNG: our mask, POV-Ray's and their difference side by side");
  cmd->add_option("--max-disagreement", opt->maxDisagreement,
                  "Exit 1 when more than this percentage of the lit pixels differ")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--json", opt->json, "Print the counts as JSON (schema rastray.povray)");
  cmd->get_option("--export-only")->excludes("--masks")->excludes("--max-disagreement")->excludes("--json");
  opt->renderCli.add(*cmd, /*withRenderer=*/true);
  return [opt, cmd]() -> int { return cmd->parsed() ? runPovray(*opt) : -1; };
}

}  // namespace rastray
