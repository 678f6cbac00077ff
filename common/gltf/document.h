// The first steps of loading (loader.cpp): the file's bytes, the .glb
// container around the JSON, and the JSON parsed with positions in its
// messages. Nothing here knows what the JSON means; check.h checks that.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/gltf/check.h"

namespace rastray {

struct GltfDocument {
  std::vector<uint8_t> bytes;  // the whole file
  std::string jsonText;        // the JSON: the whole file, or a .glb's JSON chunk
  nlohmann::json json;
  GltfCheckContext context;  // file name, .glb or not, the BIN chunk's size
};

// Reads `path` (a .glb is recognised by its magic, whatever its name),
// checks the container and parses the JSON. Throws InputError naming the
// file and the element ("GLB chunk 1", "node 3" for a syntax error inside
// "nodes"[3], with line and column) on the first problem.
GltfDocument readGltfDocument(const std::string& path);

// The same for bytes already in memory: `path` is only the name messages
// use (and, later, the folder resources are resolved in); nothing is read
// from it here.
GltfDocument parseGltfDocument(const std::string& path, std::vector<uint8_t> bytes);

// The element name messages use for an entry of a top-level glTF array:
// "nodes" -> "node", "meshes" -> "mesh"; empty for any other key.
std::string singular(const std::string& key);

// A message from tinygltf kept readable on one line: data URIs can be
// megabytes long.
std::string shortened(std::string text);

}  // namespace rastray
