#include "app/engine/cli_options.h"

namespace rastray {

namespace {
glm::dvec3 vec3(const std::vector<double>& v) { return {v[0], v[1], v[2]}; }
}  // namespace

CameraOverrides CameraOptions::overrides() const {
  CameraOverrides o;
  if (camera >= 0) o.camera = size_t(camera);
  if (!eye.empty()) o.eye = vec3(eye);
  if (!target.empty()) o.target = vec3(target);
  if (!up.empty()) o.up = vec3(up);
  if (yfov) o.yfovDegrees = *yfov;
  if (znear) o.znear = *znear;
  if (zfar) o.zfar = *zfar;
  return o;
}

}  // namespace rastray
