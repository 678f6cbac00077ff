// What `rastray info` reports about a scene, shared by the command (its
// table and --json) and the Python module (Scene.info()), so both give the
// same facts from one place.
#pragma once

#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "app/engine/cli_options.h"
#include "common/camera.h"
#include "common/scene.h"

namespace rastray {

struct MaterialCounts {
  int opaque = 0, mask = 0, blend = 0, reflective = 0, refractive = 0, emissive = 0, textured = 0,
      doubleSided = 0;
};
MaterialCounts countMaterials(const Scene& scene);

// Camera node i of the file (--camera i) bound to the image size without
// other overrides; nullopt with the reason when makeCamera refuses it.
std::optional<Camera> fileCamera(const Scene& scene, size_t i, int width, int height, std::string& error);

// "point 'Lamp' node 4": a light as `info` lists it (its index is --lights').
std::string describeLight(const Light& l);

// "'Walk': 3 channels, 3 samplers, keys 0 .. 1.25 s": an animation as
// `info` lists it (its index is --animation's).
std::string describeAnimation(const AnimationSummary& a);

// Schema "rastray.info" version 1, as `rastray info --json` prints it: the
// scene's counts, lights, cameras, bounds, the camera `camera` selects, the
// work analysis and the instances. Throws InputError when the camera
// options cannot be honoured (as makeCamera).
nlohmann::json sceneInfoJson(const Scene& scene, const CameraOptions& camera);

}  // namespace rastray
