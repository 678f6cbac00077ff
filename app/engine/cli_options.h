// The SPEC §2 camera overrides and the image size, as render options give
// them (rows of the render-option table, app/engine/render_options.h);
// info and compare take the same rows.
#pragma once

#include <optional>
#include <vector>

#include "common/camera.h"

namespace rastray {

// Default image size when --size is not given.
constexpr int kDefaultWidth = 640;
constexpr int kDefaultHeight = 480;
// The largest image side --size accepts: at 16 spp a larger sample buffer
// would exceed the memory of the machines we run on.
constexpr int kMaxImageSide = 16384;

struct CameraOptions {
  int camera = -1;                      // --camera N: the file's camera node N (walk order); -1: the first
  std::vector<double> eye, target, up;  // 3 values each when given
  std::optional<double> yfov, znear, zfar;  // yfov in degrees
  std::vector<int> size{kDefaultWidth, kDefaultHeight};

  CameraOverrides overrides() const;
  int width() const { return size[0]; }
  int height() const { return size[1]; }
};

}  // namespace rastray
