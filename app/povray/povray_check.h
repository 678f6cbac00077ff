// rastray's shadow masks against POV-Ray 3.7's on the same flattened scene
// (`rastray povray`, docs/SHADOWS.md "Against POV-Ray"): the scene made
// opaque and diffuse (makeOpaqueDiffuse), rendered by the chosen renderer
// with its shadows and with --shadows none, exported (povSceneText) and
// rendered by POV-Ray with shadows (+Q4) and without (+Q3), and the two
// masks (app/povray/shadow_masks.h) compared pixel by pixel.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "app/engine/render_options.h"
#include "app/povray/shadow_masks.h"
#include "common/camera.h"
#include "common/image.h"
#include "common/scene.h"

namespace rastray {

// The `povray` program on PATH (an absolute path), or "" when there is none.
std::string findPovray();

// The line of POV-Ray's stderr `err` that says why it failed, for the one
// error line: the last error-like line other than its user-configuration
// warning (printed on every run), else the last non-empty line.
std::string povrayComplaint(const std::string& err);

struct PovrayCheck {
  Camera camera;
  std::string povSource;  // the SDL POV-Ray rendered
  FlatImage oursLit, oursUnlit, povrayLit, povrayUnlit;
  ShadowMask ours, povray;
  ShadowMaskAgreement agreement;
  double povraySeconds = 0.0;  // wall time of POV-Ray's two runs
};

// The settings `settings` describes with --shadows none (and without the
// options that apply to shadow maps only): the same renderer, camera,
// lights and origin.
RenderSettings withoutShadows(const RenderSettings& settings);

// Runs the check on `scene` as loadSceneForRender(path, settings) left it
// (the materials are made opaque and diffuse here). `settings` must ask for
// 1 spp (POV-Ray traces the pixel centre) and the scene must have a light
// (InputError, file "command line", otherwise). `povray`: the program
// (findPovray()); it runs in a temporary directory, removed afterwards.
// Throws InputError naming POV-Ray when it fails, with its message.
PovrayCheck runPovrayCheck(Scene scene, const RenderSettings& settings, const std::string& povray,
                           const ShadowMaskOptions& options = {});

// The check as JSON (schema rastray.povray, version 1): scene, renderer,
// size, POV-Ray's seconds and the counts of ShadowMaskAgreement.
nlohmann::json povrayCheckJson(const std::string& scenePath, const RenderSettings& settings,
                               const PovrayCheck& check);

}  // namespace rastray
