// glTF 2.0 → the flattened scene of common/scene.h.
//
// Loading refuses bad input in three steps, each naming the element:
// the container (.glb header and chunks), the JSON's structure (check.h:
// types, references, byte ranges), then the resources tinygltf loads
// (buffers, decoded images) and the data read from them (NaN/Inf,
// index ranges, node graph cycles).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common/memory_budget.h"
#include "common/scene.h"

namespace rastray {

// Loads a .gltf (external or data-URI buffers) or .glb file. Throws
// InputError naming the file and the element for every kind of bad input
// (SPEC §7); never returns a partially checked scene. Decoded images and
// the flattened store (meshes times the nodes that instance them) are
// estimated before they are allocated and refused above `budget`.
// `pose`: the animation time and animation the scene is flattened at
// (common/gltf/animation.h); by default none plays (skins and morph
// weights still apply). An --animation index the file does not have is an
// InputError naming the command line's --animation.
Scene loadScene(const std::string& path, const MemoryBudget& budget, const PoseRequest& pose = {});
// With the machine's default budget (MemoryBudget::machineDefault()).
Scene loadScene(const std::string& path);

// The same for a file's bytes already in memory (the fuzz target's entry;
// fuzz/gltf_loader_fuzzer.cpp): `path` names the file in messages, and
// external buffers and images are resolved beside it, as for loadScene.
Scene loadSceneFromMemory(const std::string& path, std::vector<uint8_t> bytes, const MemoryBudget& budget,
                          const PoseRequest& pose = {});
// With the machine's default budget.
Scene loadSceneFromMemory(const std::string& path, std::vector<uint8_t> bytes);

}  // namespace rastray
