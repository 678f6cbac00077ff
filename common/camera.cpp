#include "common/camera.h"

#include <cmath>
#include <cstdio>
#include <limits>

#include <glm/gtc/matrix_transform.hpp>

#include "common/error.h"
#include "common/math_constants.h"

namespace rastray {

namespace {

[[noreturn]] void badOption(const std::string& option, const std::string& message) {
  throw InputError("command line", option, message);
}

std::string fmt(const glm::dvec3& v) {
  char buf[128];
  // + 0.0 turns -0 into 0 for printing.
  std::snprintf(buf, sizeof buf, "(%.6g, %.6g, %.6g)", v.x + 0.0, v.y + 0.0, v.z + 0.0);
  return buf;
}

bool finite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

}  // namespace

const char* toString(RenderOrigin origin) { return origin == RenderOrigin::Camera ? "camera" : "world"; }

CameraModel defaultCameraModel(const Scene& scene) {
  // Bounding sphere: the centre and half diagonal of the world bounds.
  glm::dvec3 centre(0.0);
  double radius = 1.0;
  if (!scene.bounds.empty()) {
    centre = 0.5 * (scene.bounds.lo + scene.bounds.hi);
    radius = 0.5 * glm::length(scene.bounds.hi - scene.bounds.lo);
    if (!(radius > 0.0)) radius = 1.0;  // a single point: any distance shows it
  }
  CameraModel model;
  model.projection = Projection::Perspective;
  model.yfov = 45.0 * kPi / 180.0;
  // The sphere just fits the vertical field of view at this distance.
  const double distance = radius / std::sin(0.5 * model.yfov);
  model.znear = distance / 1000.0;
  model.zfar = std::numeric_limits<double>::infinity();
  model.worldFromCamera = glm::translate(glm::dmat4(1.0), centre + glm::dvec3(0.0, 0.0, distance));
  model.origin = "default";
  return model;
}

glm::dvec2 Camera::ndcScale() const {
  if (projection == Projection::Orthographic) return {xmag, ymag};
  const double t = std::tan(0.5 * yfov);
  return {t * aspect, t};
}

Ray Camera::primaryRay(glm::dvec2 image) const { return PrimaryRays(*this)(image); }

PrimaryRays::PrimaryRays(const Camera& camera)
    : camera_(camera), scale_(camera.ndcScale()), eye_(camera.eye()), forward_(camera.forward()) {
  // glm's mat4 × vec4 adds m2·v.z + m3·v.w as one term; with v.z = −1 and
  // v.w = 0 for every perspective ray it is this constant (signed zeros
  // included: m3·0 is −0 for a negative eye coordinate).
  const glm::dmat4& m = camera.worldFromView;
  for (int k = 0; k < 3; ++k) constantPart_[k] = m[2][k] * -1.0 + m[3][k] * 0.0;
}

Ray PrimaryRays::orthographic(glm::dvec2 image) const {
  const Camera& camera = camera_;
  const glm::dvec2 ndc = camera.ndcFromImage(image);
  Ray ray;
  ray.origin = glm::dvec3(camera.worldFromView * glm::dvec4(ndc.x * scale_.x, ndc.y * scale_.y, 0.0, 1.0));
  ray.direction = forward_;
  ray.depthPerT = 1.0;
  ray.tNear = camera.znear;
  ray.tFar = camera.zfar;
  return ray;
}

std::string Camera::describe() const {
  char buf[512];
  if (projection == Projection::Perspective)
    std::snprintf(buf, sizeof buf, "perspective yfov %.4g deg aspect %.4g znear %.6g zfar %.6g",
                  yfov * 180.0 / kPi, aspect, znear, zfar);
  else
    std::snprintf(buf, sizeof buf, "orthographic xmag %.6g ymag %.6g znear %.6g zfar %.6g", xmag, ymag, znear,
                  zfar);
  return std::string(buf) + " eye " + fmt(eye() + worldOrigin) + " forward " + fmt(forward()) + " [" +
         origin + "]";
}

void applyRenderOrigin(Scene& scene, RenderOrigin mode, const CameraOverrides& overrides) {
  if (mode == RenderOrigin::World) {
    if (scene.origin != glm::dvec3(0.0)) rebaseScene(scene, glm::dvec3(0.0));
    return;
  }
  // The eye does not depend on the image size; 1×1 binds any camera.
  const Camera camera = makeCamera(scene, overrides, 1, 1);
  rebaseScene(scene, scene.origin + camera.eye());
}

Camera makeCamera(const Scene& scene, const CameraOverrides& overrides, int width, int height) {
  if (width < 1 || height < 1)
    badOption("--size",
              "image size " + std::to_string(width) + "x" + std::to_string(height) + " must be at least 1x1");
  CameraModel model;
  if (overrides.camera) {
    const size_t n = *overrides.camera, count = scene.cameras.size();
    if (n >= count)
      badOption("--camera", "camera " + std::to_string(n) + " does not exist: the scene has " +
                                std::to_string(count) + " camera node" + (count == 1 ? "" : "s"));
    model = scene.cameras[n];
    // The loader checks the first camera only (Scene::cameras).
    const glm::dmat4& w = model.worldFromCamera;
    if (glm::length(glm::cross(glm::dvec3(w[0]), glm::dvec3(w[1]))) == 0.0 ||
        glm::length(glm::dvec3(w[2])) == 0.0)
      badOption("--camera",
                "camera " + std::to_string(n) + " (" + model.origin + "): its world matrix is singular");
  } else {
    model = scene.camera ? *scene.camera : defaultCameraModel(scene);
  }

  Camera camera;
  camera.projection = model.projection;
  camera.width = width;
  camera.height = height;
  camera.yfov = model.yfov;
  camera.aspect = model.aspectRatio > 0.0 ? model.aspectRatio : double(width) / double(height);
  camera.xmag = model.xmag;
  camera.ymag = model.ymag;
  camera.znear = model.znear;
  camera.zfar = model.zfar;
  camera.origin = model.origin;
  camera.worldOrigin = scene.origin;

  // Orientation: the model's, unless eye/target/up say otherwise. The
  // model matrix may carry scale; only its rotation and position are used.
  glm::dvec3 eye(model.worldFromCamera[3]);
  glm::dvec3 forward = -glm::normalize(glm::dvec3(model.worldFromCamera[2]));
  glm::dvec3 up = glm::normalize(glm::dvec3(model.worldFromCamera[1]));
  glm::dvec3 right = glm::normalize(glm::dvec3(model.worldFromCamera[0]));
  bool reorient = false;
  if (overrides.eye) {
    if (!finite(*overrides.eye)) badOption("--eye", "must be finite");
    eye = *overrides.eye - scene.origin;  // the overrides are world points; the scene may be rebased
    camera.origin += ", --eye";
  }
  if (overrides.target) {
    if (!finite(*overrides.target)) badOption("--target", "must be finite");
    const glm::dvec3 d = (*overrides.target - scene.origin) - eye;
    if (!(glm::length(d) > 0.0)) badOption("--target", "equals the eye position " + fmt(eye));
    forward = glm::normalize(d);
    reorient = true;
    camera.origin += ", --target";
  }
  if (overrides.up) {
    if (!finite(*overrides.up) || !(glm::length(*overrides.up) > 0.0))
      badOption("--up", "must be a finite non-zero vector");
    up = glm::normalize(*overrides.up);
    reorient = true;
    camera.origin += ", --up";
  }
  if (reorient) {
    const glm::dvec3 r = glm::cross(forward, up);
    if (!(glm::length(r) > 1e-9)) badOption("--up", "is parallel to the view direction " + fmt(forward));
    right = glm::normalize(r);
    up = glm::cross(right, forward);
  } else {
    // Re-orthonormalise the file's rotation (it may carry scale or shear).
    right = glm::normalize(glm::cross(forward, up));
    up = glm::cross(right, forward);
  }
  camera.worldFromView = glm::dmat4(glm::dvec4(right, 0.0), glm::dvec4(up, 0.0), glm::dvec4(-forward, 0.0),
                                    glm::dvec4(eye, 1.0));
  camera.viewFromWorld = glm::inverse(camera.worldFromView);

  if (overrides.yfovDegrees) {
    if (camera.projection != Projection::Perspective) badOption("--yfov", "the camera is orthographic");
    const double deg = *overrides.yfovDegrees;
    if (!(deg > 0.0 && deg < 180.0)) badOption("--yfov", "must lie in (0, 180) degrees");
    camera.yfov = deg * kPi / 180.0;
    camera.origin += ", --yfov";
  }
  if (overrides.znear) {
    camera.znear = *overrides.znear;
    camera.origin += ", --znear";
  }
  if (overrides.zfar) {
    camera.zfar = *overrides.zfar;
    camera.origin += ", --zfar";
  }
  if (camera.projection == Projection::Perspective && !(camera.znear > 0.0 && std::isfinite(camera.znear)))
    badOption("--znear", "znear " + std::to_string(camera.znear) + " must be finite and > 0");
  if (camera.projection == Projection::Orthographic && !(camera.znear >= 0.0 && std::isfinite(camera.znear)))
    badOption("--znear", "znear must be finite and >= 0 for an orthographic camera");
  if (!(camera.zfar > camera.znear)) badOption("--zfar", "zfar must be greater than znear");
  if (camera.projection == Projection::Orthographic && !std::isfinite(camera.zfar))
    badOption("--zfar", "an orthographic camera needs a finite zfar");
  return camera;
}

}  // namespace rastray
