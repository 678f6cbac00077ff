// One pixel explained: both renderers' traces and their hits side by side.
#pragma once

#include <string>

#include "app/render_setup.h"

namespace rastray {

// Renders the scene with the rasterizer and the ray caster (traces on for
// pixel (x, y)) and returns the explanation as text. Settings must have
// been finish()ed.
std::string explainPixel(const Scene& scene, const RenderSettings& settings, int x, int y);

}  // namespace rastray
