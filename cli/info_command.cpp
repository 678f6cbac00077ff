// `rastray info SCENE [--json]`: what the scene holds, the camera that will
// be used, and which work it needs (SPEC §8).
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>

#include <nlohmann/json.hpp>

#include "app/engine/cli_options.h"
#include "app/engine/scene_info.h"
#include "cli/commands.h"
#include "cli/render_options_cli.h"
#include "common/analysis.h"
#include "common/camera.h"
#include "common/error.h"
#include "common/gltf/loader.h"
#include "common/math_constants.h"
#include "common/scene.h"

namespace rastray {

namespace {

struct InfoOptions {
  std::string scenePath;
  bool json = false;
  CameraOptions camera;  // from renderCli, once the command line is parsed
  RenderOptionsCli renderCli;
};

int runInfo(InfoOptions& opt) {
  const RenderSettings settings = opt.renderCli.settings(/*allRenderers=*/false);
  opt.camera = settings.camera;
  // At --time, the bounds and the default camera are the pose's.
  const Scene scene = loadScene(opt.scenePath, MemoryBudget::machineDefault(), settings.pose);
  const SceneAnalysis analysis = analyzeScene(scene);
  const Camera camera = makeCamera(scene, opt.camera.overrides(), opt.camera.width(), opt.camera.height());
  const MaterialCounts mc = countMaterials(scene);
  int lightsByType[3] = {0, 0, 0};
  for (const Light& l : scene.lights) ++lightsByType[int(l.type)];
  size_t degenerate = 0;
  for (const Instance& i : scene.instances) degenerate += i.degenerateCount;

  if (opt.json) {
    std::cout << sceneInfoJson(scene, opt.camera).dump(2) << "\n";
    return 0;
  }

  std::printf("scene      %s%s\n", scene.path.c_str(),
              scene.stats.sceneIndex >= 0
                  ? (" (scene " + std::to_string(scene.stats.sceneIndex) + ")").c_str()
                  : " (no scenes: all root nodes)");
  std::printf("nodes      %u in file, %u visited; %u meshes\n", scene.stats.nodes, scene.stats.visitedNodes,
              scene.stats.meshes);
  std::printf("instances  %zu (%u point/line primitives skipped)\n", scene.instances.size(),
              scene.stats.skippedPrimitives);
  std::printf("triangles  %zu (%zu degenerate), %zu vertices\n", scene.triangles.size(), degenerate,
              scene.positions.size());
  std::printf(
      "materials  %zu: %d opaque, %d mask, %d blend; %d reflective, %d refractive, %d emissive, "
      "%d textured, %d double-sided\n",
      scene.materials.size(), mc.opaque, mc.mask, mc.blend, mc.reflective, mc.refractive, mc.emissive,
      mc.textured, mc.doubleSided);
  std::printf("textures   %zu (%zu images)\n", scene.textures.size(), scene.images.size());
  std::printf("lights     %zu: %d point, %d spot, %d directional\n", scene.lights.size(), lightsByType[0],
              lightsByType[1], lightsByType[2]);
  for (size_t i = 0; i < scene.lights.size(); ++i)
    std::printf("  light %-4zu %s\n", i, describeLight(scene.lights[i]).c_str());
  std::printf("cameras    %u defined, %u camera nodes\n", scene.stats.cameras, scene.stats.cameraNodes);
  for (size_t i = 0; i < scene.cameras.size(); ++i) {
    std::string error;
    const std::optional<Camera> c = fileCamera(scene, i, opt.camera.width(), opt.camera.height(), error);
    std::printf("  camera %-3zu %s\n", i,
                c ? c->describe().c_str() : (scene.cameras[i].origin + ": " + error).c_str());
  }
  if (!scene.animations.empty())
    std::printf("animations %zu (--time plays them; without it none plays)\n", scene.animations.size());
  for (size_t i = 0; i < scene.animations.size(); ++i)
    std::printf("  animation %-3zu %s\n", i, describeAnimation(scene.animations[i]).c_str());
  if (scene.bounds.empty())
    std::printf("bounds     empty (nothing to render: background only)\n");
  else
    std::printf("bounds     (%.6g, %.6g, %.6g) .. (%.6g, %.6g, %.6g)\n", scene.bounds.lo.x, scene.bounds.lo.y,
                scene.bounds.lo.z, scene.bounds.hi.x, scene.bounds.hi.y, scene.bounds.hi.z);
  std::printf("camera     %dx%d %s\n", camera.width, camera.height, camera.describe().c_str());
  if (!scene.ignored.empty()) {
    std::string list;
    for (const IgnoredFeature& f : scene.ignored) list += (list.empty() ? "" : "; ") + f.describe();
    std::printf("ignored    %s\n", list.c_str());
  }
  std::printf("\nwork the scene needs (SPEC 8):\n");
  for (const WorkDecision& d : analysis.decisions)
    std::printf("  %-9s %-18s %s\n", d.needed ? "needed" : "left out", toString(d.work), d.reason.c_str());
  return 0;
}

}  // namespace

CommandRunner addInfoCommand(CLI::App& app) {
  auto opt = std::make_shared<InfoOptions>();
  CLI::App* cmd = app.add_subcommand("info", "Print what a scene holds, its camera, and the work it needs");
  cmd->add_option("scene", opt->scenePath, "glTF 2.0 file (.gltf or .glb)")->required();
  cmd->add_flag("--json", opt->json, "Print JSON instead of a table");
  opt->renderCli.add(*cmd, /*withRenderer=*/false, RenderOptionsCli::Rows::Camera);
  return [opt, cmd]() -> int { return cmd->parsed() ? runInfo(*opt) : -1; };
}

}  // namespace rastray
