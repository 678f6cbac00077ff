// glTF 2.0 → the flattened scene of common/scene.h.
//
// Loading refuses bad input in three steps, each naming the element:
// the container (.glb header and chunks), the JSON's structure (check.h:
// types, references, byte ranges), then the resources tinygltf loads
// (buffers, decoded images) and the data read from them (NaN/Inf,
// index ranges, node graph cycles).
#pragma once

#include <string>

#include "common/scene.h"

namespace rastray {

// Loads a .gltf (external or data-URI buffers) or .glb file. Throws
// InputError naming the file and the element for every kind of bad input
// (SPEC §7); never returns a partially checked scene.
Scene loadScene(const std::string& path);

}  // namespace rastray
