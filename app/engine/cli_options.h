// Command-line options shared by the subcommands: the SPEC §2 camera
// overrides and the image size.
#pragma once

#include <vector>

#include <CLI/CLI.hpp>

#include "common/camera.h"

namespace rastray {

// Default image size when --size is not given.
constexpr int kDefaultWidth = 640;
constexpr int kDefaultHeight = 480;

struct CameraOptions {
  int camera = -1;                      // --camera N: the file's camera node N (walk order); -1: the first
  std::vector<double> eye, target, up;  // 3 values each when given
  double yfov = 0, znear = 0, zfar = 0;
  CLI::Option* yfovOption = nullptr;
  CLI::Option* znearOption = nullptr;
  CLI::Option* zfarOption = nullptr;
  // Whether each was given, once detach() has read it from the parser.
  bool yfovGiven = false, znearGiven = false, zfarGiven = false;
  std::vector<int> size{kDefaultWidth, kDefaultHeight};

  void addTo(CLI::App& app);
  CameraOverrides overrides() const;
  // Records which options were given and forgets the parser's options (the
  // pointers above), so these settings stay valid after the CLI::App that
  // parsed them is gone (settings built in process, app/studies/stability_measure.h).
  void detach();
  int width() const { return size[0]; }
  int height() const { return size[1]; }
};

}  // namespace rastray
