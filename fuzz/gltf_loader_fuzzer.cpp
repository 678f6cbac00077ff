// libFuzzer target: bytes → the glTF/GLB loader the command line uses
// (loadSceneFromMemory: the same document, check, resource and scene-
// builder steps as loadScene), then what every render does next with the
// scene before a renderer gets it: the analysis (SPEC §8) with its texture
// decoding and mip chains, the rebase on the camera's eye and the camera;
// a file with animations is loaded again at a time they play.
//
// An InputError is the loader refusing bad input (exit 2 on the command
// line) and is a normal outcome. A crash, a sanitizer report, a failed
// internal check or any other exception escaping is a finding.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "common/analysis.h"
#include "common/camera.h"
#include "common/error.h"
#include "common/gltf/loader.h"
#include "common/memory_budget.h"

namespace {

// The input's name in messages, in a folder that does not exist: a fuzzer
// input is one file, so external buffers and images are never found, which
// keeps every run independent of what lies on the disk.
const std::string kFolder = "/rastray-fuzz-no-such-folder/";

void printCheckFailure(const std::string& message) {
  std::fprintf(stderr, "rastray: %s\n", message.c_str());
  std::fflush(stderr);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  rastray::setCheckFailureHandler(&printCheckFailure);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // The loader tells .glb from .gltf by the magic whatever the name; the
  // name only makes messages read like the command line's.
  const bool glb = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
  const std::string path = kFolder + (glb ? "input.glb" : "input.gltf");
  try {
    // libFuzzer stops at 2 GB of RSS (-rss_limit_mb=2048), of which the
    // process holds about 0.6 GB: the loader's estimates (decoded images,
    // the flattened store) must refuse what would cross it. A refusal is an
    // InputError; an allocation the estimates missed is a finding.
    const rastray::MemoryBudget budget{uint64_t(1) << 30, "the fuzz target's 1 GiB"};
    rastray::Scene scene =
        rastray::loadSceneFromMemory(path, std::vector<uint8_t>(data, data + size), budget);
    const rastray::SceneAnalysis analysis = rastray::analyzeScene(scene);
    analysis.textureSet(scene);
    const rastray::CameraOverrides none;
    rastray::applyRenderOrigin(scene, rastray::RenderOrigin::Camera, none);
    rastray::makeCamera(scene, none, 64, 48);
    // A file with animations is posed too, at a time from its first byte
    // beyond the keys as often as within them (common/gltf/animation.h:
    // sampling, clamping, the pose's joint matrices and morph weights).
    if (!scene.animations.empty()) {
      rastray::PoseRequest pose;
      pose.time = (double(data[0]) - 32.0) / 16.0;
      rastray::loadSceneFromMemory(path, std::vector<uint8_t>(data, data + size), budget, pose);
    }
  } catch (const rastray::InputError&) {
    // Refused with a message: what the loader is for.
  }
  return 0;
}
