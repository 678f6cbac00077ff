#include "app/serve/serve_scenes.h"

#include <algorithm>
#include <chrono>
#include <cstdio>

#include "app/engine/memory_estimate.h"
#include "app/engine/render_setup.h"
#include "app/serve/serve_api.h"
#include "common/camera.h"
#include "common/error.h"

namespace rastray::serve {

namespace fs = std::filesystem;

namespace {

bool isGltfName(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext == ".gltf" || ext == ".glb";
}

// Whether canonical path `p` lies inside canonical directory `root`.
bool isInside(const fs::path& p, const fs::path& root) {
  auto r = root.begin(), q = p.begin();
  for (; r != root.end(); ++r, ++q)
    if (q == p.end() || *q != *r) return false;
  return true;
}

std::string joinKey(const std::string& path, const std::vector<std::string>& args) {
  std::string key = path;
  for (const std::string& a : args) key += '\x1f' + a;  // a separator no argument from a URL query holds
  return key;
}

}  // namespace

SceneAccess::SceneAccess(std::vector<std::string> named, const std::string& root) : named_(std::move(named)) {
  for (const std::string& path : named_)
    if (!fs::is_regular_file(path)) throw InputError(path, "", "no such file");
  if (!root.empty()) {
    std::error_code ec;
    if (!fs::is_directory(root, ec))
      throw InputError("command line", "--root", "'" + root + "' is not a directory");
    root_ = fs::canonical(root);
    rootArg_ = root;
  }
}

std::string SceneAccess::resolve(const std::string& requested) const {
  if (std::find(named_.begin(), named_.end(), requested) != named_.end()) return requested;
  if (!root_) throw HttpError(404, "scene '" + requested + "': not a scene this server was started with");
  const fs::path rel(requested);
  if (requested.empty() || rel.is_absolute() || requested.find('\0') != std::string::npos)
    throw HttpError(403, "scene '" + requested + "': only paths relative to the root may be opened");
  for (const fs::path& part : rel)
    if (part == "..") throw HttpError(403, "scene '" + requested + "': '..' may not climb out of the root");
  // The real path, every symbolic link resolved, must stay inside the root.
  std::error_code ec;
  const fs::path real = fs::weakly_canonical(*root_ / rel, ec);
  if (ec || !isInside(real, *root_)) throw HttpError(403, "scene '" + requested + "': lies outside the root");
  if (!fs::is_regular_file(real, ec) || !isGltfName(real))
    throw HttpError(404, "scene '" + requested + "': no .gltf or .glb file of that name under the root");
  return (fs::path(rootArg_) / rel).string();
}

std::vector<std::string> SceneAccess::list() const {
  std::vector<std::string> out = named_;
  if (!root_) return out;
  std::vector<std::string> found;
  std::error_code ec;
  // Directory links are not followed; a file link is listed only when its
  // target lies inside the root (resolve() would refuse it otherwise).
  for (fs::recursive_directory_iterator it(*root_, fs::directory_options::skip_permission_denied, ec), end;
       !ec && it != end && found.size() < kMaxListed; it.increment(ec)) {
    if (!it->is_regular_file(ec) || !isGltfName(it->path())) continue;
    const fs::path real = fs::weakly_canonical(it->path(), ec);
    if (!ec && isInside(real, *root_)) found.push_back(fs::relative(it->path(), *root_).string());
  }
  std::sort(found.begin(), found.end());
  for (const std::string& f : found)
    if (std::find(out.begin(), out.end(), f) == out.end()) out.push_back(f);
  return out;
}

std::shared_ptr<const Scene> SceneCache::loaded(const std::string& path, const PoseRequest& pose) {
  const std::string key = path + poseKey(pose);
  if (auto scene = loaded_.find(key)) return scene;
  // Through the render command's own loader and default settings, in the
  // file's frame (a fresh scene's origin is (0, 0, 0): --origin world
  // rebases nothing).
  RenderSettings world = renderSettingsFrom({"--origin", "world"});
  if (loadBudget) world.memory = *loadBudget;
  world.pose = pose;
  auto scene = std::make_shared<const Scene>(loadSceneForRender(path, world));
  loaded_.insert(key, scene);
  return scene;
}

std::string SceneCache::poseKey(const PoseRequest& pose) {
  if (!pose.time) return "";
  char key[64];
  std::snprintf(key, sizeof key, "\x1ftime %.17g animation %d", *pose.time, pose.animation);
  return key;
}

std::shared_ptr<const Scene> SceneCache::prepared(const std::string& path, const RenderSettings& settings) {
  const std::string key = preparedKey(path, settings);
  if (auto scene = prepared_.find(key)) return scene;
  // A copy of the loaded scene prepared as loadSceneForRender prepares a
  // freshly loaded one: rebaseScene rounds again from worldPositions.
  Scene scene = *loaded(path, settings.pose);
  prepareSceneForRender(scene, settings);
  auto shared = std::make_shared<const Scene>(std::move(scene));
  prepared_.insert(key, shared);
  return shared;
}

std::string SceneCache::preparedKey(const std::string& path, const RenderSettings& settings) {
  // The rebasing point depends only on the origin mode and, for the camera
  // origin, on the eye (given, or the file's chosen camera).
  std::string key = path + (settings.renderOrigin == RenderOrigin::World ? "\x1fworld"
                                                                         : "\x1f"
                                                                           "camera");
  const CameraOverrides overrides = settings.camera.overrides();
  if (settings.renderOrigin == RenderOrigin::Camera && overrides.eye) {
    char eye[96];
    std::snprintf(eye, sizeof eye, "\x1f%.17g,%.17g,%.17g", overrides.eye->x, overrides.eye->y,
                  overrides.eye->z);
    key += eye;
  }
  // The chosen camera moves the eye; the kept lights change the scene.
  if (overrides.camera)
    key +=
        "\x1f"
        "camera " +
        std::to_string(*overrides.camera);
  key += "\x1flights " + optionText(settings, "--lights") + poseKey(settings.pose);
  return key;
}

std::shared_ptr<PreparedFrame> SceneCache::frame(const std::string& path,
                                                 const std::vector<std::string>& args,
                                                 const RenderSettings& settings) {
  const std::string key = joinKey(path, args);
  if (auto frame = frames_.find(key)) {
    frame->reused = true;
    return frame;
  }
  auto frame = std::make_shared<PreparedFrame>();
  frame->scene = prepared(path, settings);
  frame->settings = settings;
  frame->raster = settings.raster;
  frame->ray = settings.ray;
  frame->raster.keepSamples = frame->ray.keepSamples = false;
  // Previews reuse the cache's buffers, whatever their frame (a request
  // that finds them busy, a concurrent one, allocates its own).
  frame->buffers = &buffers_;
  frame->raster.frameBuffers = frame->buffers;
  // A request's token is set for its render alone (renderPrepared's caller).
  frame->settings.raster.cancel = frame->raster.cancel = nullptr;
  frame->settings.ray.cancel = frame->ray.cancel = nullptr;
  frame->memory = estimateRenderMemory(*frame->scene, settings);
  checkMemory(frame->memory, settings.memory, frame->scene->path, "",
              describeRenderWork(settings, toString(settings.renderer)));
  // The BVH depends on the prepared scene and the culling mode alone: a
  // frame of other options or another camera over the same prepared scene
  // (with --origin world, any camera) shares the caster built first.
  std::shared_ptr<RayCaster> caster;
  const std::string casterKey = preparedKey(path, settings) +
                                "\x1f"
                                "cull " +
                                std::to_string(int(settings.cull));
  if (settings.renderer != RendererKind::Raster) {
    if (auto found = casters_.find(casterKey)) {
      if (found->scene == frame->scene) caster = found->caster;
    }
  }
  frame->renderer =
      std::make_unique<FrameRenderer>(*frame->scene, frame->settings, frame->raster, frame->ray, caster);
  frame->builtBvh = frame->renderer->bvhBuildSeconds() >= 0.0;
  if (frame->builtBvh)
    casters_.insert(casterKey,
                    std::make_shared<SharedCaster>(SharedCaster{frame->scene, frame->renderer->caster()}));
  frames_.insert(key, frame);
  return frame;
}

std::shared_ptr<const CrossvalResult> SceneCache::crossval(const std::string& path,
                                                           const std::vector<std::string>& args,
                                                           const RenderSettings& settings) {
  const std::string key = joinKey(path, args);
  if (auto result = crossvals_.find(key)) return result;
  auto result =
      std::make_shared<const CrossvalResult>(crossvalidate(*prepared(path, settings), settings, nullptr));
  crossvals_.insert(key, result);
  return result;
}

RenderRun renderPrepared(PreparedFrame& frame) {
  const auto start = std::chrono::steady_clock::now();
  RenderRun run;
  run.camera = frame.renderer->camera();
  run.analysis = frame.renderer->analysis();
  run.output = frame.renderer->frame();
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  run.memoryEstimate = frame.memory;
  if (!frame.reused && frame.builtBvh) {
    run.output.timings.insert(run.output.timings.begin(),
                              {"raytrace.bvh_build", frame.renderer->bvhBuildSeconds()});
    run.seconds += frame.renderer->bvhBuildSeconds();
  }
  return run;
}

namespace {

// A camera as the page orbits it: eye, target and up (target: the eye
// moved along the view direction to the depth of the bounds' centre).
nlohmann::ordered_json orbitCameraJson(const Scene& scene, const Camera& camera) {
  const glm::dvec3 eye = camera.eye() + scene.origin, forward = camera.forward();
  const glm::dvec3 up = glm::normalize(glm::dvec3(camera.worldFromView[1]));
  // Orbit around the bounds' centre as seen along the view direction.
  const glm::dvec3 centre = scene.bounds.empty() ? eye + forward : (scene.bounds.lo + scene.bounds.hi) * 0.5;
  const double size = scene.bounds.empty() ? 1.0 : glm::length(scene.bounds.hi - scene.bounds.lo);
  double distance = glm::dot(centre + scene.origin - eye, forward);
  if (!(distance > 1e-9 * size)) distance = size > 0.0 ? size : 1.0;
  const glm::dvec3 target = eye + forward * distance;
  auto vec = [](const glm::dvec3& v) { return nlohmann::ordered_json::array({v.x, v.y, v.z}); };
  return {{"origin", camera.origin},
          {"projection", camera.projection == Projection::Perspective ? "perspective" : "orthographic"},
          {"yfovDegrees", camera.yfov * 180.0 / 3.14159265358979323846},
          {"eye", vec(eye)},
          {"target", vec(target)},
          {"up", vec(up)}};
}

}  // namespace

nlohmann::ordered_json sceneInfoJson(const Scene& scene, int width, int height) {
  auto vec = [](const glm::dvec3& v) { return nlohmann::ordered_json::array({v.x, v.y, v.z}); };
  nlohmann::ordered_json bounds = nullptr;
  if (!scene.bounds.empty())
    bounds = {vec(scene.bounds.lo + scene.origin), vec(scene.bounds.hi + scene.origin)};
  // The file's camera nodes in walk order (--camera N); a singular one
  // (makeCamera refuses it) is listed without a view.
  nlohmann::ordered_json cameras = nlohmann::ordered_json::array();
  for (size_t i = 0; i < scene.cameras.size(); ++i) {
    CameraOverrides pick;
    pick.camera = i;
    nlohmann::ordered_json c;
    try {
      c = orbitCameraJson(scene, makeCamera(scene, pick, width, height));
    } catch (const InputError& e) {
      c = {{"origin", scene.cameras[i].origin}, {"error", e.message()}};
    }
    c["index"] = i;
    cameras.push_back(c);
  }
  nlohmann::ordered_json lights = nlohmann::ordered_json::array();
  for (size_t i = 0; i < scene.lights.size(); ++i)
    lights.push_back({{"index", i},
                      {"name", scene.lights[i].name},
                      {"type", toString(scene.lights[i].type)},
                      {"node", scene.lights[i].node}});
  // The explorer's time slider runs over [0, the longest duration].
  nlohmann::ordered_json animations = nlohmann::ordered_json::array();
  double duration = 0.0;
  for (size_t i = 0; i < scene.animations.size(); ++i) {
    const AnimationSummary& a = scene.animations[i];
    animations.push_back({{"index", i}, {"name", a.name}, {"channels", a.channels}, {"duration", a.end}});
    duration = std::max(duration, a.end);
  }
  return {{"schema", "rastray.serve.scene"},
          {"version", 1},
          {"scene", scene.path},
          {"triangles", scene.triangleCount()},
          {"instances", scene.instances.size()},
          {"materials", scene.materials.size()},
          {"lights", scene.lights.size()},
          {"lightList", lights},
          {"bounds", bounds},
          {"size", scene.bounds.empty() ? 1.0 : glm::length(scene.bounds.hi - scene.bounds.lo)},
          {"camera", orbitCameraJson(scene, makeCamera(scene, {}, width, height))},
          {"cameras", cameras},
          {"animations", animations},
          {"duration", duration}};
}

}  // namespace rastray::serve
