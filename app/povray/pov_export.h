// The flattened scene in POV-Ray 3.7's scene description language (SDL),
// for an independent ray tracer to render what rastray renders: the same
// float triangles, camera rays and lights, with every material opaque and
// diffuse, so that the two renders differ only in which points each finds
// in shadow (docs/SHADOWS.md, "Against POV-Ray").
//
// What is written, and how it matches rastray:
// - Geometry: one mesh2 per instance, its vertices the store's float
//   positions (Scene::positions: world space minus the render origin, the
//   values Embree and the rasterizer consume), printed with 9 significant
//   digits so POV-Ray reads back the same floats. Authored normals become
//   normal_vectors (smooth triangles), flat instances have none.
// - Camera: POV-Ray traces pixel (x, y) along D + x0·R + y0·U with
//   x0 = (x + 0.5)/W − 0.5 and y0 = 0.5 − (y + 0.5)/H (its tracepixel.cpp,
//   no antialiasing): the pixel centre, as SPEC §3's 1-spp sample. With
//   D = −Z, R = 2·sx·X and U = 2·sy·Y of the camera's worldFromView
//   (sx, sy: Camera::ndcScale) the ray is rastray's primary ray through
//   the same NDC point, whatever the handedness (no look_at, no angle:
//   POV-Ray takes the vectors as given). Orthographic: the same vectors
//   move the origin. POV-Ray has no near or far plane: scenes the camera's
//   znear or zfar cut differ there.
// - Materials: pigment = the base colour factor (textures and vertex
//   colours are left out: a mask is a ratio of two renders with the same
//   albedo), finish with diffuse 1 and nothing else (no ambient, specular,
//   phong, reflection, emission); global ambient 0.
// - Lights: without attenuation (POV-Ray's default, fade_power 0); point
//   lights at their position, spot lights with radius and falloff = the
//   inner and outer cone angles, directional lights as `parallel` lights
//   placed outside the scene's bounding sphere. rastray's 1/d², range and
//   cone falloffs scale a light's contribution, which the lit/unlit ratio
//   divides out.
// Rendering the file without shadows is POV-Ray's quality setting +Q3
// (diffuse lighting, no shadow tests) instead of +Q4: one file serves both.
#pragma once

#include <string>
#include <vector>

#include "common/camera.h"
#include "common/scene.h"

namespace rastray {

// POV-Ray's camera vectors for `camera` (see above): a pixel's ray is
// direction + x0·right + y0·up from location (perspective), or direction
// from location + x0·right + y0·up (orthographic).
struct PovCamera {
  bool orthographic = false;
  glm::dvec3 location{0.0}, direction{0.0, 0.0, -1.0}, right{1.0, 0.0, 0.0}, up{0.0, 1.0, 0.0};
};
PovCamera povCamera(const Camera& camera);

// Makes every material opaque and diffuse, as the exported file shows them:
// alpha mode OPAQUE, no mirror weight (metallic 0, roughness 1), no
// transmission, no emission. Base colours, textures and normals stay.
void makeOpaqueDiffuse(Scene& scene);

// The POV-Ray 3.7 SDL of `scene` seen through `camera` (made for the
// scene's current render origin), opaque and diffuse.
std::string povSceneText(const Scene& scene, const Camera& camera);

// POV-Ray's arguments to render `input` to the OpenEXR file `output`
// (linear, no clamping) at the camera's size: no antialiasing, no display,
// no pause, quality 4 (shadows) or 3 (none), one thread. (With several,
// which thread traces which block varies from run to run, and so did a
// shadow-edge pixel of the Cornell box: 6,481 to 6,483 shadowed pixels.
// The trace there takes 0.15 s of CPU; most of a run's 0.8 s is start-up.)
std::vector<std::string> povrayArguments(const std::string& input, const std::string& output, int width,
                                         int height, bool shadows);

}  // namespace rastray
