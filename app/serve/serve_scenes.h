// What `rastray serve` may open, and what it keeps loaded between requests.
//
// SceneAccess confines requests to the scenes named on the command line and
// the glTF files under --root: a requested name is either one of the named
// paths, exactly, or a relative path under the root that stays inside it
// after every symbolic link is resolved.
//
// SceneCache keeps, per scene file, the parsed scene with its decoded
// textures (and their mip chains); per render origin the scene rebased as
// `render` rebases it; per rebased scene and culling mode the ray caster
// with its Embree BVH; per full set of render settings a FrameRenderer
// (analysis and camera, sharing that caster); and per crossval settings
// the comparison behind the maps. The caches are bounded (least
// recently used first out). Not thread-safe: the server renders one
// request at a time and calls it under that lock.
#pragma once

#include <filesystem>
#include <list>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/crossval/crossval.h"
#include "app/engine/render_setup.h"
#include "common/memory_budget.h"
#include "common/scene.h"
#include "raster/frame_buffers.h"

namespace rastray::serve {

class SceneAccess {
 public:
  // `named`: the scene files given on the command line (must exist:
  // InputError otherwise); `root`: the directory under which any glTF file
  // may be opened, or empty for none.
  SceneAccess(std::vector<std::string> named, const std::string& root);

  // The path to load for a requested name. Throws HttpError: 403 for an
  // absolute path, a ".." component or a file whose real path lies outside
  // the root (symbolic links included); 404 for a name that is neither a
  // named scene nor an existing .gltf/.glb file under the root.
  std::string resolve(const std::string& requested) const;

  // The names a request may give: the named scenes, then the glTF files
  // under the root (relative to it, sorted; at most kMaxListed).
  std::vector<std::string> list() const;
  static constexpr size_t kMaxListed = 1000;

 private:
  std::vector<std::string> named_;
  std::optional<std::filesystem::path> root_;  // canonical
  std::string rootArg_;                        // as given, to build paths the user can re-type
};

// A small least-recently-used map from string keys to shared values.
template <typename T>
class LruCache {
 public:
  explicit LruCache(size_t capacity) : capacity_(capacity) {}
  std::shared_ptr<T> find(const std::string& key) {
    for (auto it = entries_.begin(); it != entries_.end(); ++it)
      if (it->first == key) {
        entries_.splice(entries_.begin(), entries_, it);
        return entries_.front().second;
      }
    return nullptr;
  }
  void insert(const std::string& key, std::shared_ptr<T> value) {
    entries_.emplace_front(key, std::move(value));
    if (entries_.size() > capacity_) entries_.pop_back();
  }

 private:
  size_t capacity_;
  std::list<std::pair<std::string, std::shared_ptr<T>>> entries_;
};

// One renderer prepared for one set of settings; the options it renders
// with live here, at stable addresses (FrameRenderer keeps references).
struct PreparedFrame {
  std::shared_ptr<const Scene> scene;
  RenderSettings settings;
  // The rasterizer's depth target and image storage: the cache's pool,
  // shared by every frame (raster.frameBuffers points there; the image
  // comes back through recycle() once encoded).
  RasterFrameBuffers* buffers = nullptr;
  RasterOptions raster;
  RayOptions ray;
  std::unique_ptr<FrameRenderer> renderer;
  MemoryEstimate memory;  // checked against settings.memory (--max-memory) before preparing
  bool reused = false;    // true once a later request found it in the cache
  bool builtBvh = false;  // its renderer built a BVH (else none, or a shared one)
};

// A ray caster (its Embree BVH) with the prepared scene it was built over.
struct SharedCaster {
  std::shared_ptr<const Scene> scene;
  std::shared_ptr<RayCaster> caster;
};

class SceneCache {
 public:
  // The limit scene loads are checked against (serve --max-memory);
  // nullopt: MemoryBudget::machineDefault().
  std::optional<MemoryBudget> loadBudget;
  // The scene as loaded from `path` (its file frame) at `pose`, parsed
  // once per pose (each --time loads the file again).
  std::shared_ptr<const Scene> loaded(const std::string& path, const PoseRequest& pose = {});
  // The scene rebased on the render origin `settings` names, exactly as
  // loadSceneForRender gives it.
  std::shared_ptr<const Scene> prepared(const std::string& path, const RenderSettings& settings);
  // A FrameRenderer for these settings (`args`: their command-line form,
  // the cache key); settings.finish() done. Refused (InputError) when the
  // render's estimated peak memory exceeds --max-memory, as renderScene
  // refuses it.
  std::shared_ptr<PreparedFrame> frame(const std::string& path, const std::vector<std::string>& args,
                                       const RenderSettings& settings);
  // crossvalidate() of the prepared scene under these (all-renderer)
  // settings.
  std::shared_ptr<const CrossvalResult> crossval(const std::string& path,
                                                 const std::vector<std::string>& args,
                                                 const RenderSettings& settings);

 private:
  // One pool for every prepared frame: an orbit prepares a frame per
  // camera, and a pool per frame allocated (and the kernel zeroed) a fresh
  // image for each preview, about a fifth of a 640x480 preview's CPU.
  // Renders are serialised (a busy pool makes a frame allocate its own,
  // so sharing is always safe). Declared before the frames, so it
  // outlives them.
  RasterFrameBuffers buffers_;
  LruCache<const Scene> loaded_{8};
  LruCache<const Scene> prepared_{3};
  // The cache key of prepared(path, settings).
  static std::string preparedKey(const std::string& path, const RenderSettings& settings);
  // The part of a cache key that names the pose ("" for none).
  static std::string poseKey(const PoseRequest& pose);

  LruCache<PreparedFrame> frames_{4};
  LruCache<SharedCaster> casters_{2};            // per prepared scene and culling mode
  LruCache<const CrossvalResult> crossvals_{1};  // deep frames of three renders: the largest entries
};

// One render of a prepared frame, as renderScene reports it: the
// BVH-build timing is listed when this request built the BVH.
RenderRun renderPrepared(PreparedFrame& frame);

// What the page needs to know of a scene before rendering it (schema
// rastray.serve.scene): counts, bounds, and its camera at the given size
// as eye, target and up (target: the eye moved along the view direction
// to the depth of the bounds' centre, the point orbiting turns around);
// likewise every camera node of the file ("cameras", --camera N), and the
// lights by index, name and type ("lightList", --lights).
nlohmann::ordered_json sceneInfoJson(const Scene& scene, int width, int height);

}  // namespace rastray::serve
