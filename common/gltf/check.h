// Structural check of a glTF 2.0 JSON document, run before tinygltf sees
// it (loader.cpp).
//
// tinygltf treats a property of the wrong type as absent and does not
// check references or byte ranges; some of those reach its image loader as
// out-of-bounds reads. This check rejects, with the element named, every
// wrong type, dangling index and out-of-range byte range in the parts of
// glTF that rastray reads, so that tinygltf only ever loads a document
// whose references and ranges are sound.
#pragma once

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

namespace rastray {

struct GltfCheckContext {
  std::string file;         // for messages
  bool isGlb = false;       // buffer 0 may then omit its uri
  uint64_t glbBinSize = 0;  // size of the GLB BIN chunk (0: none)
};

// Throws InputError(file, element, message) on the first problem.
void checkGltfDocument(const nlohmann::json& doc, const GltfCheckContext& context);

// Bytes per component of a glTF componentType (0: not a glTF type), and
// components per element of an accessor type (0: not a glTF type).
int64_t componentSize(int64_t componentType);
int64_t componentCount(const std::string& type);

// Extensions rastray implements; any other name in extensionsRequired is
// an error, names in extensionsUsed only are ignored.
bool isSupportedExtension(const std::string& name);
std::string supportedExtensionList();

// Whether a buffer is an EXT_/KHR_meshopt_compression fallback buffer
// ("fallback": true): only compressed bufferViews name it, its bytes are
// never read, and it may have no uri. False for anything malformed.
bool isMeshoptFallbackBuffer(const nlohmann::json& buffer);

}  // namespace rastray
