// The camera both renderers use (SPEC §2, §3): the file's camera or the
// default one, with the command-line overrides applied, bound to an image
// size.
//
// Image positions are in pixels from the image's top-left corner, y down
// (SPEC §3). NDC: x right, y up, both in [-1, 1] over the image. View space
// is the glTF camera space: looking down −Z, +Y up; view depth (the Z
// output, SPEC §4) is −z_view.
#pragma once

#include <optional>
#include <string>

#include <glm/glm.hpp>

#include "common/scene.h"

namespace rastray {

// Which world point the shared triangle store is rebased on before its
// positions are rounded to float (rebaseScene in common/scene.h).
enum class RenderOrigin {
  Camera,  // the camera's eye: float spacing is finest where the image is made
  World,   // the file's own origin: no rebasing (shows the far-from-origin failure)
};
const char* toString(RenderOrigin origin);

struct CameraOverrides {
  std::optional<size_t> camera;  // Scene::cameras index (--camera N); the others apply on top
  std::optional<glm::dvec3> eye;
  std::optional<glm::dvec3> target;
  std::optional<glm::dvec3> up;
  std::optional<double> yfovDegrees;
  std::optional<double> znear;
  std::optional<double> zfar;  // may be +inf
};

// A ray in world space. direction is unit length. The ray's segment
// [tNear, tFar] lies between the near and far planes, so a ray caster that
// starts at tNear clips exactly where the rasterizer does.
struct Ray {
  glm::dvec3 origin{0.0};
  glm::dvec3 direction{0.0, 0.0, -1.0};
  double tNear = 0.0;
  double tFar = 0.0;
  double depthPerT = 1.0;  // view depth of origin + t·direction is t · depthPerT (+ 0 at origin)
};

struct Camera {
  Projection projection = Projection::Perspective;
  int width = 0, height = 0;
  double yfov = 0.0;               // radians (perspective)
  double aspect = 1.0;             // the file's aspectRatio, else width / height
  double xmag = 1.0, ymag = 1.0;   // orthographic half extents
  double znear = 0.0, zfar = 0.0;  // zfar may be +inf (perspective only)
  // In the scene's rebased frame (Scene::origin): "world" below means that
  // frame; worldOrigin is the file-space point its (0, 0, 0) stands for.
  glm::dmat4 worldFromView{1.0};
  glm::dmat4 viewFromWorld{1.0};
  glm::dvec3 worldOrigin{0.0};
  std::string origin;  // where the camera came from, for `info` and reports

  glm::dvec3 eye() const { return glm::dvec3(worldFromView[3]); }
  glm::dvec3 forward() const { return -glm::normalize(glm::dvec3(worldFromView[2])); }

  // NDC of an image position (pixels from the top-left corner, y down).
  glm::dvec2 ndcFromImage(glm::dvec2 image) const {
    return {2.0 * image.x / width - 1.0, 1.0 - 2.0 * image.y / height};
  }
  glm::dvec2 imageFromNdc(glm::dvec2 ndc) const {
    return {(ndc.x + 1.0) * 0.5 * width, (1.0 - ndc.y) * 0.5 * height};
  }
  // Half extents of the view volume at view depth 1 (perspective) or
  // everywhere (orthographic): x_ndc = x_view / (scale.x · depth) etc.
  glm::dvec2 ndcScale() const;

  // The primary ray through an image position (PrimaryRays, below, for
  // many of them).
  Ray primaryRay(glm::dvec2 image) const;

  // One line, e.g. "perspective yfov 45.0° aspect 1.333 znear 0.01 zfar inf
  // eye (0, 1, 5) forward (0, 0, -1) [node 2 'Camera' (camera 0)]".
  std::string describe() const;
};

// Camera::primaryRay with what depends on the camera alone (the NDC scale,
// a tangent; the eye; the forward direction; the constant half of the
// view-to-world product) computed once: bit-identical rays
// (Camera::primaryRay is this), for loops over many image positions.
// Inline, so that the ray is built in the caller's storage (returned
// through memory, it was written in 8-byte and read back in 16-byte
// pieces: a store-forwarding stall per ray). Holds a reference: the
// camera must outlive it.
class PrimaryRays {
 public:
  explicit PrimaryRays(const Camera& camera);
  // always_inline: GCC's size limit kept it out of line at call sites
  // such as `g.ray = rays(position)`, where the copy stalled.
  [[gnu::always_inline]] Ray operator()(glm::dvec2 image) const {
    if (camera_.projection == Projection::Orthographic) return orthographic(image);
    const glm::dvec2 ndc = camera_.ndcFromImage(image);
    // The point on the view plane at depth 1; its length converts depth to t.
    const glm::dvec3 viewDir(ndc.x * scale_.x, ndc.y * scale_.y, -1.0);
    const double length = glm::length(viewDir);
    // worldFromView · (viewDir, 0) as glm evaluates it, (m0·x + m1·y) +
    // (m2·z + m3·w), with the second sum (z = −1, w = 0 for every ray)
    // taken from constantPart_: the same operations on the same values.
    const glm::dmat4& m = camera_.worldFromView;
    const glm::dvec3 world((m[0].x * viewDir.x + m[1].x * viewDir.y) + constantPart_.x,
                           (m[0].y * viewDir.x + m[1].y * viewDir.y) + constantPart_.y,
                           (m[0].z * viewDir.x + m[1].z * viewDir.y) + constantPart_.z);
    Ray ray;
    ray.origin = eye_;
    ray.direction = glm::normalize(world);
    ray.depthPerT = 1.0 / length;
    ray.tNear = camera_.znear * length;
    ray.tFar = camera_.zfar * length;  // inf stays inf
    return ray;
  }

 private:
  Ray orthographic(glm::dvec2 image) const;

  const Camera& camera_;
  glm::dvec2 scale_;
  glm::dvec3 eye_, forward_;
  glm::dvec3 constantPart_;  // m2·(−1) + m3·0 of worldFromView, per component
};

// Rebases the scene (rebaseScene) on the point `mode` names: the eye of the
// camera makeCamera(scene, overrides, …) makes, or the file's origin. Call
// once after loading, before the camera is made and anything is rendered.
void applyRenderOrigin(Scene& scene, RenderOrigin mode, const CameraOverrides& overrides);

// The default camera of SPEC §2 for a scene (used when it has none).
CameraModel defaultCameraModel(const Scene& scene);

// Binds the scene's camera (or the default; with overrides.camera, that
// camera of Scene::cameras) to an image size and applies the overrides.
// Throws InputError (file "command line") for impossible settings: a camera
// index out of range or with a singular world matrix, znear <= 0, zfar <= znear, yfov outside (0°, 180°), eye
// equal to target, up parallel to the view direction, or a size below 1×1.
Camera makeCamera(const Scene& scene, const CameraOverrides& overrides, int width, int height);

}  // namespace rastray
