// OpenImageIO, loaded the first time it is needed.
//
// Linking OpenImageIO loads about 260 shared libraries (the codecs of its
// format plugins: GDAL, DICOM, FFmpeg, OpenVDB, ...) before main: 0.4 s
// per process on the project machine, more than a small render takes, paid
// by every command, every child of a sweep and every test process. So every
// call into OpenImageIO lives in one module, rastray_oiio.so (common/oiio/),
// which common/ opens with dlopen the first time an image file is read or
// written, a texture is mip-mapped or two images' colours are compared;
// a command that does none of these never loads it.
//
// The module and the programs are built together from one tree; the
// version below refuses a module from another build of the interface.
// Errors cross the boundary as exceptions (InputError, std::runtime_error,
// std::bad_alloc), as they did when this code was linked in.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "common/exr_header.h"
#include "common/image.h"

namespace rastray {

// What OpenImageIO's compare and compare_Yee found (ImageBufAlgo::CompareResults).
struct ImageDifference {
  double meanError = 0.0, rmsError = 0.0, maxError = 0.0;
  int maxX = -1, maxY = -1, maxChannel = -1;
  uint64_t differingPixels = 0;   // any channel differs at all
  uint64_t yeeFailingPixels = 0;  // perceptibly different
};

// The functions the module provides. The writers write to `tmpPath` and
// rename it over `path`; on failure they remove it and throw InputError
// naming `path`. The readers are common/image.h's, without the memory
// guard the caller adds.
struct OiioFunctions {
  int version;
  void (*writeRgba8Png)(const std::string& path, const std::string& tmpPath, int width, int height,
                        const uint8_t* rgba);
  void (*writeExr)(const std::string& path, const std::string& tmpPath, const FlatImage& image,
                   ColorPrecision precision);
  void (*writeDeepExr)(const std::string& path, const std::string& tmpPath, const DeepImage& image);
  bool (*isDeepExr)(const std::string& path, uint64_t maxBytes);
  std::string (*exrChannelType)(const std::string& path, const std::string& channel);
  FlatImage (*readExr)(const std::string& path, uint64_t maxBytes);
  DeepImage (*readDeepExr)(const std::string& path, uint64_t maxBytes);
  // Box-filtered resize of packed RGBA float images (ImageBufAlgo::resize "box").
  void (*resizeBox)(int srcWidth, int srcHeight, const glm::vec4* src, int dstWidth, int dstHeight,
                    glm::vec4* dst);
  // An 8-bit PNG in memory; throws std::runtime_error when it cannot.
  std::vector<unsigned char> (*encodePng)(int width, int height, int channels, const uint8_t* pixels);
  // RGBA float images of one size; Yee's test with the given adaptation
  // luminance (cd/m²) and field of view (degrees). Throws std::runtime_error.
  ImageDifference (*compareColors)(int width, int height, const glm::vec4* a, const glm::vec4* b,
                                   float yeeLuminance, float yeeFieldOfView);
  // writeRgba8Png's pixels and attributes as a PNG in memory, compressed
  // for speed (no row filter, zlib level 1): the explorer's previews.
  std::vector<unsigned char> (*encodeRgba8PngQuick)(int width, int height, const uint8_t* rgba);
};

// What the program lends the module: the functions of common/ it calls,
// so that they are compiled once and keep one state (the check-failure
// handler).
struct OiioHost {
  int version;
  ExrHeaderFacts (*checkExrHeaders)(const std::string& path);
  void (*checkFailed)(const char* expr, const char* file, int line, const std::string& detail);
  std::string (*formatBytes)(uint64_t bytes);
};

constexpr int kOiioModuleVersion = 3;

// Loads the module on the first call (thread-safe) and returns its
// functions. Looks beside the running program, one folder up (test,
// bench and fuzz programs live in subfolders of the build), then at the
// path it was built to. Throws std::runtime_error naming every path tried
// and dlopen's reason when none loads.
const OiioFunctions& oiioModule();

// Whether this process has loaded the module.
bool oiioModuleLoaded();

}  // namespace rastray

// The module's one exported symbol.
extern "C" const rastray::OiioFunctions* rastray_oiio_module(const rastray::OiioHost* host);
