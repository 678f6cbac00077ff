// `rastray render SCENE --renderer raster|raytrace|hybrid -o OUT ...`
#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>

#include <tbb/global_control.h>
#include <nlohmann/json.hpp>

#include "app/engine/cli_options.h"
#include "app/engine/memory_estimate.h"
#include "app/engine/render_setup.h"
#include "cli/commands.h"
#include "cli/render_options_cli.h"
#include "common/error.h"
#include "common/image.h"
#include "common/interrupt.h"
#include "common/oiio_module.h"

namespace rastray {

namespace {

struct RenderCommandOptions {
  std::string scenePath;
  std::string output;
  bool deep = false;
  bool floatColor = false;
  bool stats = false;
  bool json = false;
  RenderSettings settings;  // from renderCli, once the command line is parsed
  RenderOptionsCli renderCli;
};

std::string lowerExtension(const std::string& path) {
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos) return "";
  std::string ext = path.substr(dot + 1);
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

int runRender(RenderCommandOptions& opt) {
  opt.settings = opt.renderCli.settings(/*allRenderers=*/false);
  // Check the output before the (possibly long) render.
  const std::string ext = lowerExtension(opt.output);
  if (ext != "png" && ext != "exr")
    throw InputError("command line", "-o", "output '" + opt.output + "' must end in .png or .exr");
  if (opt.deep && ext != "exr") throw InputError("command line", "--deep", "deep output needs an .exr file");

  std::unique_ptr<tbb::global_control> threads;
  if (opt.settings.threads > 0)
    threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                    size_t(opt.settings.threads));

  // Ctrl-C: the renderers stop at their next tile and throw Interrupted
  // (common/interrupt.h); main() says "nothing written".
  installInterruptHandlers();
  const Scene scene = loadSceneForRender(opt.scenePath, opt.settings);
  throwIfInterrupted();
  RenderSettings settings = opt.settings;
  settings.keepSamples = opt.deep;
  // The file -o names is written through OpenImageIO, loaded on first use
  // (common/oiio_module.h): load it before the estimate, so that its
  // libraries count in the estimate's "resident now" and in the peak
  // beside the frame, as when it was linked in.
  oiioModule();
  // Before anything large is allocated: the frame and the encoder's
  // buffers for the file -o names, against --max-memory.
  const MemoryEstimate memory = estimateRenderCommandMemory(scene, settings,
                                                            opt.deep       ? OutputFormat::DeepExr
                                                            : ext == "png" ? OutputFormat::Png
                                                                           : OutputFormat::Exr);
  checkMemory(memory, settings.memory, scene.path, "",
              describeRenderWork(settings, toString(settings.renderer)));
  // What --json and --stats report: the command's whole estimate.
  RenderRun run = renderScene(scene, settings, &memory);
  // The last check: a write that has begun finishes (and renames its
  // temporary file into place) even if a signal arrives during it.
  throwIfInterrupted();

  if (opt.deep)
    writeDeepExr(opt.output, run.output.samples);
  else
    writeImage(opt.output, run.output.image, opt.floatColor ? ColorPrecision::Float : ColorPrecision::Half);

  if (opt.json) {
    std::cout << renderReportJson(scene, settings, run).dump(2) << "\n";
  } else {
    std::printf("%s: %s %dx%d %d spp, %.3f s -> %s\n", scene.path.c_str(), toString(settings.renderer),
                run.camera.width, run.camera.height, settings.spp, run.seconds, opt.output.c_str());
    if (opt.stats) printRenderStats(run);
  }
  return 0;
}

}  // namespace

CommandRunner addRenderCommand(CLI::App& app) {
  auto opt = std::make_shared<RenderCommandOptions>();
  CLI::App* cmd =
      app.add_subcommand("render", "Render a scene with the rasterizer, the ray caster or both (hybrid)");
  cmd->add_option("scene", opt->scenePath, "glTF 2.0 file (.gltf or .glb)")->required();
  cmd->add_option("-o,--output", opt->output, "Output image: .png (sRGB) or .exr (linear, with Z and IDs)")
      ->required();
  cmd->add_flag("--deep", opt->deep, "Write a deep EXR with every sample and transparency layer");
  cmd->add_flag("--float", opt->floatColor, "EXR colour as 32-bit float instead of half");
  cmd->add_flag("--stats", opt->stats, "Print the work counters and timings");
  cmd->add_flag("--json", opt->json, "Print counters, timings and passes as JSON");
  opt->renderCli.add(*cmd, /*withRenderer=*/true);
  return [opt, cmd]() -> int { return cmd->parsed() ? runRender(*opt) : -1; };
}

}  // namespace rastray
