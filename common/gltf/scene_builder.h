// Step 4 of loading (loader.cpp): a document that check.h accepted, with
// the buffers and images tinygltf loaded for it, becomes the flattened
// Scene of common/scene.h.
#pragma once

#include <string>

#include <nlohmann/json_fwd.hpp>

#include "common/memory_budget.h"
#include "common/scene.h"

namespace tinygltf {
class Model;
}

namespace rastray {

// Throws InputError (file: path) for what only the data can show: NaN or
// infinite values, indices out of range, cycles in the node graph,
// factors outside [0, 1], images that did not decode, and a flattened
// scene (meshes times the nodes instancing them) of 2^32 vertices or
// triangles or beyond `budget`, counted before anything is allocated.
// The scene is flattened at `pose` (common/gltf/animation.h): animation
// data is checked whether or not it plays.
Scene buildScene(const std::string& path, const nlohmann::json& doc, const tinygltf::Model& model,
                 const MemoryBudget& budget, const PoseRequest& pose = {});

}  // namespace rastray
