#include "app/engine/cli_options.h"

namespace rastray {

namespace {
glm::dvec3 vec3(const std::vector<double>& v) { return {v[0], v[1], v[2]}; }
}  // namespace

void CameraOptions::addTo(CLI::App& app) {
  app.add_option("--camera", camera,
                 "The file's camera N (camera nodes in walk order, as `info` lists them; default the "
                 "first); --eye etc. apply on top")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--eye", eye, "Camera position X Y Z (world space)")->expected(3);
  app.add_option("--target", target, "Point the camera looks at, X Y Z")->expected(3);
  app.add_option("--up", up, "Camera up vector X Y Z")->expected(3);
  yfovOption = app.add_option("--yfov", yfov, "Vertical field of view in degrees (perspective)");
  znearOption = app.add_option("--znear", znear, "Near plane distance");
  zfarOption = app.add_option("--zfar", zfar, "Far plane distance ('inf' for none)");
  // Image sizes beyond 16384 on a side are refused: at 16 spp a sample
  // buffer would exceed the memory of the machines we run on.
  app.add_option("--size", size, "Image width and height in pixels")
      ->expected(2)
      ->check(CLI::Range(1, 16384));
}

CameraOverrides CameraOptions::overrides() const {
  CameraOverrides o;
  if (camera >= 0) o.camera = size_t(camera);
  if (!eye.empty()) o.eye = vec3(eye);
  if (!target.empty()) o.target = vec3(target);
  if (!up.empty()) o.up = vec3(up);
  const auto given = [](const CLI::Option* option, bool detached) {
    return option ? option->count() > 0 : detached;
  };
  if (given(yfovOption, yfovGiven)) o.yfovDegrees = yfov;
  if (given(znearOption, znearGiven)) o.znear = znear;
  if (given(zfarOption, zfarGiven)) o.zfar = zfar;
  return o;
}

void CameraOptions::detach() {
  yfovGiven = yfovOption && yfovOption->count() > 0;
  znearGiven = znearOption && znearOption->count() > 0;
  zfarGiven = zfarOption && zfarOption->count() > 0;
  yfovOption = znearOption = zfarOption = nullptr;
}

}  // namespace rastray
