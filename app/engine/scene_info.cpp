#include "app/engine/scene_info.h"

#include <cmath>
#include <cstdio>

#include "common/analysis.h"
#include "common/error.h"
#include "common/math_constants.h"

namespace rastray {

namespace {

nlohmann::json vec(const glm::dvec3& v) { return {v.x, v.y, v.z}; }

// JSON numbers cannot be infinite: +inf is written as the string "inf".
nlohmann::json number(double d) {
  if (std::isinf(d)) return d > 0 ? "inf" : "-inf";
  return d;
}

}  // namespace

MaterialCounts countMaterials(const Scene& scene) {
  MaterialCounts c;
  for (const Material& m : scene.materials) {
    c.opaque += m.alphaMode == AlphaMode::Opaque;
    c.mask += m.alphaMode == AlphaMode::Mask;
    c.blend += m.alphaMode == AlphaMode::Blend;
    c.reflective += m.isReflective();
    c.refractive += m.isRefractive();
    c.emissive += m.isEmissive();
    c.textured += m.isTextured();
    c.doubleSided += m.doubleSided;
  }
  return c;
}

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

std::string describeAnimation(const AnimationSummary& a) {
  char keys[96];
  std::snprintf(keys, sizeof keys, "keys %.6g .. %.6g s", a.start, a.end);
  return (a.name.empty() ? std::string("unnamed") : "'" + a.name + "'") + ": " + std::to_string(a.channels) +
         " channel" + (a.channels == 1 ? "" : "s") + ", " + std::to_string(a.samplers) + " sampler" +
         (a.samplers == 1 ? "" : "s") + ", " + keys;
}

nlohmann::json sceneInfoJson(const Scene& scene, const CameraOptions& options) {
  const SceneAnalysis analysis = analyzeScene(scene);
  const Camera camera = makeCamera(scene, options.overrides(), options.width(), options.height());
  const MaterialCounts mc = countMaterials(scene);
  int lightsByType[3] = {0, 0, 0};
  for (const Light& l : scene.lights) ++lightsByType[int(l.type)];
  size_t degenerate = 0;
  for (const Instance& i : scene.instances) degenerate += i.degenerateCount;

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
    ignored.push_back({{"feature", f.feature}, {"unit", f.unit}, {"count", f.count}, {"text", f.describe()}});
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
  // The file's animations (--animation N; --time plays them), with their
  // key ranges in seconds: "duration" is the last key (glTF time starts at 0).
  nlohmann::json animations = nlohmann::json::array();
  for (size_t i = 0; i < scene.animations.size(); ++i) {
    const AnimationSummary& a = scene.animations[i];
    animations.push_back({{"index", i},
                          {"name", a.name},
                          {"channels", a.channels},
                          {"samplers", a.samplers},
                          {"start", a.start},
                          {"duration", a.end},
                          {"text", describeAnimation(a)}});
  }
  j["animations"] = animations;
  j["cameras"] = scene.stats.cameras;
  j["cameraNodes"] = scene.stats.cameraNodes;
  // Every camera node in walk order, as --camera N picks it (no other overrides).
  nlohmann::json cameraList = nlohmann::json::array();
  for (size_t i = 0; i < scene.cameras.size(); ++i) {
    std::string error;
    const std::optional<Camera> c = fileCamera(scene, i, options.width(), options.height(), error);
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
                    {"vertexColors", in.hasColors},
                    // Normal-map tangents: stored only for instances whose material has a normal map.
                    {"tangents", in.firstTangent == kNoId ? "none"
                                 : in.generatedTangents   ? "generated"
                                                          : "file"},
                    {"skinned", in.skinned},
                    {"morphed", in.morphed}});
  }
  j["instanceList"] = inst;
  return j;
}

}  // namespace rastray
