// glTF 2.0 → the flattened scene of common/scene.h.
//
// Four steps, each refusing bad input with the element named:
// 1. read the file; for .glb, check the container (header, chunk lengths),
//    and parse the JSON (document.h);
// 2. check its structure (check.h): types, references, byte ranges;
// 3. let tinygltf load the resources (buffers from data URIs, external
//    files or the BIN chunk; images decoded by stb);
// 4. walk the scene from the checked JSON (scene_builder.h), reading
//    accessors with bounds already proven and rejecting NaN/Inf data.
#include "common/gltf/loader.h"

#include <cstring>
#include <filesystem>
#include <sstream>
#include <utility>

#include <stb/stb_image.h>
#include <tiny_gltf.h>
#include <nlohmann/json.hpp>

#include "common/error.h"
#include "common/gltf/check.h"
#include "common/gltf/document.h"
#include "common/gltf/scene_builder.h"
#include "common/memory_budget.h"

namespace rastray {

namespace {

using json = nlohmann::json;

uint32_t readLittleU32(const std::vector<uint8_t>& bytes, size_t offset) {
  uint32_t v;
  std::memcpy(&v, bytes.data() + offset, 4);
  return v;  // glTF is little-endian, as is every platform we build for
}

std::string firstLine(const std::string& text) {
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line))
    if (!line.empty()) return line;
  return "unknown error";
}

// tinygltf's default ExpandFilePath is a no-op on modern versions; ours
// states it: URIs are file names relative to the glTF file, nothing more.
std::string expandNothing(const std::string& path, void*) { return path; }

// Only regular files count as found: tinygltf would take the seek size of
// a directory (2^63 - 1 on some file systems) as its length. And only those
// beside the glTF file (base/uri, as tinygltf joins them): tinygltf also
// searches the current directory, where a file of the same name is not the
// scene's resource.
struct ResourceFolder {
  std::string prefix;  // the base directory and a slash
};

bool isResourceFile(const std::string& path, void* user) {
  const ResourceFolder& folder = *static_cast<const ResourceFolder*>(user);
  if (path.compare(0, folder.prefix.size(), folder.prefix) != 0) return false;
  std::error_code ec;
  return std::filesystem::is_regular_file(path, ec);
}

// Images are decoded by tinygltf (stb); a small PNG can declare a huge
// canvas. Before each decode, its header's size is added to the decoded
// total and checked against the budget: 8 bytes per pixel for stb's
// buffer (up to 16-bit RGBA) plus 4 for the scene's RGBA8 copy.
struct ImageBudget {
  const MemoryBudget& budget;
  uint64_t decodedBytes = 0;
  int refusedImage = -1;  // the image that would pass the budget
  MemoryEstimate refusal;
};

bool loadImageWithinBudget(tinygltf::Image* image, const int index, std::string* err, std::string* warn,
                           int reqWidth, int reqHeight, const unsigned char* bytes, int size, void* user) {
  ImageBudget& b = *static_cast<ImageBudget*>(user);
  int w = 0, h = 0, components = 0;
  if (stbi_info_from_memory(bytes, size, &w, &h, &components) && w > 0 && h > 0) {
    b.decodedBytes = addSat(b.decodedBytes, mulSat(mulSat(uint64_t(w), uint64_t(h)), 12));
    MemoryEstimate estimate;
    estimate.add("loaded file", currentRssBytes());
    estimate.add("decoded images", b.decodedBytes);
    if (estimate.total() > b.budget.bytes) {
      b.refusedImage = index;
      b.refusal = estimate;
      if (err) *err = "image too large for the memory budget";
      return false;
    }
  }
  return tinygltf::LoadImageData(image, index, err, warn, reqWidth, reqHeight, bytes, size, nullptr);
}

// tinygltf only loads the buffers and images here (the scene builder reads
// the rest from the checked JSON), but it parses everything and refuses
// two things compressed geometry has: a buffer without data (a meshopt
// fallback buffer, never read: check.cpp lets only compressed bufferViews
// name it, and their bytes come from the decoder) and index accessors
// without a bufferView (a Draco primitive's, decoded from its stream).
// tinygltf is then given a copy of the document in which each fallback
// buffer without a uri is one zero byte and Draco primitives have no
// "indices". Returns false when neither occurs (the document goes to
// tinygltf as it is).
bool documentForTinygltf(const GltfDocument& d, std::vector<uint8_t>& glb, std::string& text) {
  json copy;
  const auto edit = [&]() -> json& {
    if (copy.is_null()) copy = d.json;
    return copy;
  };
  if (const auto buffers = d.json.find("buffers"); buffers != d.json.end())
    for (size_t i = 0; i < buffers->size(); ++i) {
      const json& b = (*buffers)[i];
      if (!isMeshoptFallbackBuffer(b) || b.contains("uri")) continue;
      edit()["buffers"][i]["byteLength"] = 1;
      copy["buffers"][i]["uri"] = "data:application/octet-stream;base64,AA==";
    }
  if (const auto meshes = d.json.find("meshes"); meshes != d.json.end())
    for (size_t m = 0; m < meshes->size(); ++m) {
      const json& prims = (*meshes)[m].at("primitives");
      for (size_t p = 0; p < prims.size(); ++p)
        if (prims[p].contains("extensions") &&
            prims[p].at("extensions").contains("KHR_draco_mesh_compression") && prims[p].contains("indices"))
          edit()["meshes"][m]["primitives"][p].erase("indices");
    }
  if (copy.is_null()) return false;
  text = copy.dump();
  if (!d.context.isGlb) return true;
  // The same container around the new JSON chunk (padded with spaces to
  // 4 bytes, as the format requires) and the original BIN chunk.
  text.append((4 - text.size() % 4) % 4, ' ');
  const size_t binAt = 20 + size_t(readLittleU32(d.bytes, 12));
  const size_t total = 20 + text.size() + (d.bytes.size() - binAt);
  if (total > UINT32_MAX) throw InputError(d.context.file, "", "file is larger than 4 GiB");
  glb.assign(d.bytes.begin(), d.bytes.begin() + 12);
  const uint32_t header[3] = {uint32_t(total), uint32_t(text.size()), 0x4E4F534A};  // length, JSON chunk
  glb.resize(20);
  std::memcpy(glb.data() + 8, header, sizeof header);
  glb.insert(glb.end(), text.begin(), text.end());
  glb.insert(glb.end(), d.bytes.begin() + binAt, d.bytes.end());
  return true;
}

// Step 3: tinygltf loads the buffers and decodes the images. The document
// is sound by now, so its remaining failures are about resources: missing
// files, bad data URIs, undecodable images.
void loadResources(const GltfDocument& d, tinygltf::Model& model, const MemoryBudget& budget) {
  const std::string& path = d.context.file;
  const std::string baseDir = std::filesystem::path(path).parent_path().string();
  ResourceFolder folder{(baseDir.empty() ? std::string(".") : baseDir) +
                        (baseDir.empty() || baseDir.back() != '/' ? "/" : "")};
  tinygltf::TinyGLTF loader;
  tinygltf::FsCallbacks fs{&isResourceFile, &expandNothing, &tinygltf::ReadWholeFile,
                           &tinygltf::WriteWholeFile, &folder};
  loader.SetFsCallbacks(fs);
  ImageBudget images{budget};
  loader.SetImageLoader(&loadImageWithinBudget, &images);
  std::string err, warn;
  if (d.bytes.size() > UINT32_MAX) throw InputError(path, "", "file is larger than 4 GiB");
  std::vector<uint8_t> glb = {};
  std::string text;
  const bool rewritten = documentForTinygltf(d, glb, text);
  const std::vector<uint8_t>& bytes = rewritten ? glb : d.bytes;
  const std::string& jsonText = rewritten ? text : d.jsonText;
  const bool ok =
      d.context.isGlb
          ? loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(), unsigned(bytes.size()),
                                        baseDir.empty() ? "." : baseDir)
          : loader.LoadASCIIFromString(&model, &err, &warn, jsonText.data(), unsigned(jsonText.size()),
                                       baseDir.empty() ? "." : baseDir);
  if (!ok && images.refusedImage >= 0)
    checkMemory(images.refusal, budget, path, "image " + std::to_string(images.refusedImage),
                "decoding the images");
  if (!ok) {
    // tinygltf loads the top-level arrays in this order and appends each
    // entry once it has loaded, so the first array that came up short
    // holds the entry it failed on.
    const std::pair<const char*, size_t> loaded[] = {
        {"buffers", model.buffers.size()},     {"bufferViews", model.bufferViews.size()},
        {"accessors", model.accessors.size()}, {"meshes", model.meshes.size()},
        {"nodes", model.nodes.size()},         {"scenes", model.scenes.size()},
        {"materials", model.materials.size()}, {"images", model.images.size()},
        {"textures", model.textures.size()},   {"animations", model.animations.size()},
        {"skins", model.skins.size()},         {"samplers", model.samplers.size()},
        {"cameras", model.cameras.size()}};
    for (const auto& [key, count] : loaded) {
      const auto it = d.json.find(key);
      if (it == d.json.end() || !it->is_array() || count >= it->size()) continue;
      const json& entry = (*it)[count];
      std::string message = shortened(firstLine(err));
      // tinygltf's message would quote the whole data URI.
      const bool dataUri = entry.value("uri", std::string()).rfind("data:", 0) == 0;
      if (std::string(key) == "buffers" && dataUri)
        message = "data URI is not base64 of exactly byteLength (" +
                  std::to_string(entry.at("byteLength").get<uint64_t>()) +
                  ") bytes with media type application/octet-stream or application/gltf-buffer";
      throw InputError(path, singular(key) + " " + std::to_string(count), message);
    }
    throw InputError(path, "", shortened(firstLine(err)));
  }
  if (model.buffers.size() != d.json.value("buffers", json::array()).size() ||
      model.images.size() != d.json.value("images", json::array()).size())
    throw InputError(path, "", "tinygltf loaded a different number of buffers or images than the file lists");
  for (size_t i = 0; i < model.buffers.size(); ++i)
    if (!isMeshoptFallbackBuffer(d.json.at("buffers")[i]) &&
        model.buffers[i].data.size() < d.json.at("buffers")[i].at("byteLength").get<size_t>())
      throw InputError(path, "buffer " + std::to_string(i), "is shorter than its byteLength");
}

}  // namespace

namespace {

// Steps 2 to 4, the same whichever way the bytes arrived.
Scene loadDocument(const GltfDocument& document, const MemoryBudget& budget, const PoseRequest& pose) {
  checkGltfDocument(document.json, document.context);
  tinygltf::Model model;
  loadResources(document, model, budget);
  return buildScene(document.context.file, document.json, model, budget, pose);
}

}  // namespace

Scene loadScene(const std::string& path, const MemoryBudget& budget, const PoseRequest& pose) {
  return loadDocument(readGltfDocument(path), budget, pose);
}

Scene loadScene(const std::string& path) { return loadScene(path, MemoryBudget::machineDefault()); }

Scene loadSceneFromMemory(const std::string& path, std::vector<uint8_t> bytes, const MemoryBudget& budget,
                          const PoseRequest& pose) {
  return loadDocument(parseGltfDocument(path, std::move(bytes)), budget, pose);
}

Scene loadSceneFromMemory(const std::string& path, std::vector<uint8_t> bytes) {
  return loadSceneFromMemory(path, std::move(bytes), MemoryBudget::machineDefault());
}

}  // namespace rastray
