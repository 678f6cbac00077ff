// The files of common/image.h: checks, temporary names and text here;
// the OpenImageIO work in the rastray_oiio module, loaded on first use
// (common/oiio_module.h).
#include "common/image.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <new>
#include <stdexcept>

#include "common/error.h"
#include "common/oiio_module.h"
#include "common/rgba8.h"
#include "common/scene.h"

namespace rastray {

namespace {

std::string lowercaseExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

// "<dir>/<stem>.tmp.<pid>.<counter><ext>": beside the target (so the rename
// stays within one file system and is atomic), unique per process and call,
// and still ending in the real extension.
std::string temporaryPathFor(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  const std::filesystem::path target(path);
  const std::string name = target.stem().string() + ".tmp." + std::to_string(::getpid()) + "." +
                           std::to_string(counter++) + target.extension().string();
  return (target.parent_path() / name).string();
}

}  // namespace

void writeTextFile(const std::string& path, const std::string& text) {
  const std::string tmp = temporaryPathFor(path);
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  bool ok = f && std::fwrite(text.data(), 1, text.size(), f) == text.size();
  std::string error = ok ? "" : std::strerror(errno);
  if (f && std::fclose(f) != 0 && ok) {
    ok = false;
    error = std::strerror(errno);
  }
  if (ok && std::rename(tmp.c_str(), path.c_str()) != 0) {
    ok = false;
    error = std::string("cannot rename the temporary file into place: ") + std::strerror(errno);
  }
  if (!ok) {
    std::remove(tmp.c_str());
    throw InputError(path, "", "cannot write: " + error);
  }
}

namespace {

void checkFlat(const FlatImage& image) {
  const size_t n = size_t(image.width) * size_t(image.height);
  RASTRAY_CHECK(image.width >= 0 && image.height >= 0 && image.color.size() == n && image.depth.size() == n &&
                    image.instance.size() == n && image.triangle.size() == n,
                "FlatImage " + std::to_string(image.width) + "x" + std::to_string(image.height) + " with " +
                    std::to_string(image.color.size()) + " colours");
}

}  // namespace

// IEC 61966-2-1 exactly (no gamma-2.2 approximation), evaluated in double:
// the float result is the exact value rounded once to float.
float srgbToLinear(float encoded) {
  const double v = encoded;
  return float(v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4));
}

float linearToSrgb(float linear) {
  const double v = linear;
  return float(v <= 0.0031308 ? v * 12.92 : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055);
}

void writeImage(const std::string& path, const FlatImage& image, ColorPrecision precision) {
  const std::string ext = lowercaseExtension(path);
  if (ext == ".png") {
    writePng(path, image);
  } else if (ext == ".exr") {
    writeExr(path, image, precision);
  } else {
    throw InputError(path, "", "unknown image extension '" + ext + "' (expected .png or .exr)");
  }
}

void writePng(const std::string& path, const FlatImage& image) {
  checkFlat(image);
  // Un-premultiply and encode by hand rather than with ImageBufAlgo::unpremult
  // and colorconvert: OIIO's colour conversion follows whatever OCIO config
  // the environment names, and unpremult keeps the colour where alpha is 0,
  // whereas SPEC §4 wants exact sRGB and black there.
  std::vector<uint8_t> rgba(image.color.size() * 4);
  encodeRgba8(image.color.data(), image.color.size(), rgba.data());
  oiioModule().writeRgba8Png(path, temporaryPathFor(path), image.width, image.height, rgba.data());
}

std::string encodePngQuick(const FlatImage& image) {
  checkFlat(image);
  std::vector<uint8_t> rgba(image.color.size() * 4);
  encodeRgba8(image.color.data(), image.color.size(), rgba.data());
  const std::vector<unsigned char> png =
      oiioModule().encodeRgba8PngQuick(image.width, image.height, rgba.data());
  return std::string(png.begin(), png.end());
}

void writeExr(const std::string& path, const FlatImage& image, ColorPrecision precision) {
  checkFlat(image);
  oiioModule().writeExr(path, temporaryPathFor(path), image, precision);
}

void writeDeepExr(const std::string& path, const DeepImage& image) {
  oiioModule().writeDeepExr(path, temporaryPathFor(path), image);
}

bool isDeepExr(const std::string& path, uint64_t maxBytes) { return oiioModule().isDeepExr(path, maxBytes); }

std::string exrChannelType(const std::string& path, const std::string& channel) {
  return oiioModule().exrChannelType(path, channel);
}

namespace {

// input, not a crash.
template <typename Read>
auto readWithinMemory(const std::string& path, uint64_t maxBytes, Read read)
    -> decltype(read(path, maxBytes)) {
  try {
    return read(path, maxBytes);
  } catch (const std::bad_alloc&) {
    throw InputError(path, "", "image too large to load");
  } catch (const std::length_error&) {
    throw InputError(path, "", "image too large to load");
  }
}

}  // namespace

FlatImage readExr(const std::string& path, uint64_t maxBytes) {
  return readWithinMemory(path, maxBytes, oiioModule().readExr);
}

DeepImage readDeepExr(const std::string& path, uint64_t maxBytes) {
  return readWithinMemory(path, maxBytes, oiioModule().readDeepExr);
}

}  // namespace rastray
