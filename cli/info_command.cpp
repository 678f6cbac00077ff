// `rastray info SCENE [--json]`: what the scene holds, the camera that will
// be used, and which work it needs (SPEC §8).
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>

#include <nlohmann/json.hpp>

#include "app/engine/cli_options.h"
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

struct MaterialCounts {
  int opaque = 0, mask = 0, blend = 0, reflective = 0, refractive = 0, emissive = 0, textured = 0,
      doubleSided = 0;
};

MaterialCounts countMaterials(const Scene& scene) {
  MaterialCounts c;
  for (const Material& m : scene.materials) {
    c.opaque += m.alphaMode == AlphaMode::Opaque;
    c.mask += m.alphaMode == AlphaMode::Mask;
    c.blend += m.alphaMode == AlphaMode::Blend;
    c.reflective += m.isReflective();
    c.refractive += m.isRefractive();
    c.emissive += m.isEmissive();
    c.textured += m.baseColorTexture >= 0 || m.emissiveTexture >= 0;
    c.doubleSided += m.doubleSided;
  }
  return c;
}

nlohmann::json vec(const glm::dvec3& v) { return {v.x, v.y, v.z}; }

// Camera node i of the file (--camera i) bound to the image size without
// other overrides; nullopt with the reason when makeCamera refuses it.
std::optional<Camera> fileCamera(const Scene& scene, size_t i, int width, int height, std::string& error) {
  CameraOverrides pick;
  pick.camera = i;
  try {
    return makeCamera(scene, pick, width, height);
  } catch (const InputError& e) {
    error = e.message();
    return std::nullopt;
  }
}

// "point 'Lamp' node 4": a light as `info` lists it (its index is --lights').
std::string describeLight(const Light& l) {
  return std::string(toString(l.type)) + (l.name.empty() ? "" : " '" + l.name + "'") + " node " +
         std::to_string(l.node);
}

// JSON numbers cannot be infinite: +inf is written as the string "inf".
nlohmann::json number(double d) {
  if (std::isinf(d)) return d > 0 ? "inf" : "-inf";
  return d;
}

int runInfo(InfoOptions& opt) {
  opt.camera = opt.renderCli.settings(/*allRenderers=*/false).camera;
  const Scene scene = loadScene(opt.scenePath);
  const SceneAnalysis analysis = analyzeScene(scene);
  const Camera camera = makeCamera(scene, opt.camera.overrides(), opt.camera.width(), opt.camera.height());
  const MaterialCounts mc = countMaterials(scene);
  int lightsByType[3] = {0, 0, 0};
  for (const Light& l : scene.lights) ++lightsByType[int(l.type)];
  size_t degenerate = 0;
  for (const Instance& i : scene.instances) degenerate += i.degenerateCount;

  if (opt.json) {
    nlohmann::json j;
    j["schema"] = "rastray.info";
    j["version"] = 1;
    j["scene"] = scene.path;
    j["sceneIndex"] = scene.stats.sceneIndex;
    j["nodes"] = scene.stats.nodes;
    j["visitedNodes"] = scene.stats.visitedNodes;
    j["meshes"] = scene.stats.meshes;
    j["instances"] = scene.instances.size();
    j["triangles"] = scene.triangles.size();
    j["degenerateTriangles"] = degenerate;
    j["vertices"] = scene.positions.size();
    j["skippedPrimitives"] = scene.stats.skippedPrimitives;
    j["materials"] = {{"total", scene.materials.size()},
                      {"opaque", mc.opaque},
                      {"mask", mc.mask},
                      {"blend", mc.blend},
                      {"reflective", mc.reflective},
                      {"refractive", mc.refractive},
                      {"emissive", mc.emissive},
                      {"textured", mc.textured},
                      {"doubleSided", mc.doubleSided}};
    j["textures"] = scene.textures.size();
    j["images"] = scene.images.size();
    j["lights"] = {{"total", scene.lights.size()},
                   {"point", lightsByType[0]},
                   {"spot", lightsByType[1]},
                   {"directional", lightsByType[2]}};
    // What the file uses and nothing renders (empty when nothing is ignored).
    nlohmann::json ignored = nlohmann::json::array();
    for (const IgnoredFeature& f : scene.ignored)
      ignored.push_back(
          {{"feature", f.feature}, {"unit", f.unit}, {"count", f.count}, {"text", f.describe()}});
    j["ignored"] = ignored;
    nlohmann::json lightList = nlohmann::json::array();
    for (size_t i = 0; i < scene.lights.size(); ++i) {
      const Light& l = scene.lights[i];
      nlohmann::json e = {{"index", i}, {"name", l.name}, {"type", toString(l.type)}, {"node", l.node}};
      if (l.type != LightType::Directional) e["position"] = vec(l.position);
      if (l.type != LightType::Point) e["direction"] = vec(l.direction);
      lightList.push_back(e);
    }
    j["lightList"] = lightList;
    j["cameras"] = scene.stats.cameras;
    j["cameraNodes"] = scene.stats.cameraNodes;
    // Every camera node in walk order, as --camera N picks it (no other overrides).
    nlohmann::json cameraList = nlohmann::json::array();
    for (size_t i = 0; i < scene.cameras.size(); ++i) {
      std::string error;
      const std::optional<Camera> c = fileCamera(scene, i, opt.camera.width(), opt.camera.height(), error);
      if (c)
        cameraList.push_back({{"index", i},
                              {"origin", c->origin},
                              {"projection", toString(c->projection)},
                              {"yfovDegrees", c->yfov * 180.0 / kPi},
                              {"eye", vec(c->eye())},
                              {"forward", vec(c->forward())},
                              {"description", c->describe()}});
      else
        cameraList.push_back({{"index", i}, {"origin", scene.cameras[i].origin}, {"error", error}});
    }
    j["cameraList"] = cameraList;
    if (scene.bounds.empty())
      j["bounds"] = nullptr;
    else
      j["bounds"] = {{"min", vec(scene.bounds.lo)}, {"max", vec(scene.bounds.hi)}};
    j["camera"] = {{"origin", camera.origin},
                   {"projection", toString(camera.projection)},
                   {"width", camera.width},
                   {"height", camera.height},
                   {"yfovDegrees", camera.yfov * 180.0 / kPi},
                   {"aspect", camera.aspect},
                   {"xmag", camera.xmag},
                   {"ymag", camera.ymag},
                   {"znear", number(camera.znear)},
                   {"zfar", number(camera.zfar)},
                   {"eye", vec(camera.eye())},
                   {"forward", vec(camera.forward())}};
    nlohmann::json work = nlohmann::json::array();
    for (const WorkDecision& d : analysis.decisions)
      work.push_back({{"work", toString(d.work)}, {"needed", d.needed}, {"reason", d.reason}});
    j["analysis"] = work;
    nlohmann::json inst = nlohmann::json::array();
    for (size_t i = 0; i < scene.instances.size(); ++i) {
      const Instance& in = scene.instances[i];
      inst.push_back({{"instance", i},
                      {"node", in.node},
                      {"mesh", in.mesh},
                      {"primitive", in.primitive},
                      {"mode", in.mode},
                      {"material", in.material},
                      {"triangles", in.triangleCount},
                      {"vertices", in.vertexCount},
                      {"degenerate", in.degenerateCount},
                      {"mirrored", in.mirrored},
                      {"normals", in.normals == NormalSource::Authored ? "authored" : "flat"},
                      {"vertexColors", in.hasColors}});
    }
    j["instanceList"] = inst;
    std::cout << j.dump(2) << "\n";
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
