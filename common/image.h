// Images and per-sample AOVs, and their files (SPEC §4, §6).
//
// Inside rastray colour is linear RGB with premultiplied alpha. Files:
// - PNG: sRGB-encoded, un-premultiplied, 8 bit, RGBA. Colour is divided by
//   alpha (black where alpha is 0), clamped to [0, 1], encoded with the
//   exact sRGB curve and rounded to the nearest byte.
// - EXR (flat): channels R G B A (half by default, float on request), Z
//   (float, view depth, +inf where nothing was hit), id.instance and
//   id.triangle (uint, 0xFFFFFFFF where nothing was hit). Zip compression:
//   lossless, so Z and IDs come back bit for bit.
// - Deep EXR: every sample of every pixel and, with transparency, every
//   layer, front to back; the same channels plus id.sample (uint, the
//   sample's index in the SPEC §3 pattern) so a reader can tell samples
//   and layers apart, and cutoff (uint: 1 on the layer after which the
//   renderer stopped looking, DeepSample::cutOff; 0 elsewhere). Colour is
//   float here (deep files are for sample-exact analysis). Deep data are
//   stored as OpenEXR deep scanlines, zips compression.
// - Files from other renderers may carry any subset of these channels
//   (SPEC §6), e.g. only Z and the IDs: see the readers below.
// Every file is written to a temporary name beside its target and renamed
// into place, so an interrupted run never leaves a half-written output.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "common/error.h"
#include "common/scene.h"

namespace rastray {

// A flat frame: one colour per pixel plus the Z and IDs of the sample
// nearest the pixel centre (SPEC §6). Row 0 is the top row.
struct FlatImage {
  int width = 0, height = 0;
  std::vector<glm::vec4> color;    // linear, premultiplied
  std::vector<float> depth;        // view depth; +inf: nothing hit
  std::vector<uint32_t> instance;  // kNoId: nothing hit
  std::vector<uint32_t> triangle;
  // False when read from a file without all of R, G and B (a visibility
  // export): `color` then holds no colour (RGB 0, A as the file has it)
  // and colour metrics must be skipped. Writers ignore it.
  bool hasColor = true;

  FlatImage() = default;
  // Transparent black, +inf depth, kNoId ids. Inline: the OpenImageIO
  // module (common/oiio_module.h) makes them too.
  FlatImage(int w, int h)
      : width(w),
        height(h),
        color(checkedPixels(w, h), glm::vec4(0.0f)),
        depth(color.size(), std::numeric_limits<float>::infinity()),
        instance(color.size(), kNoId),
        triangle(color.size(), kNoId) {}
  size_t index(int x, int y) const { return size_t(y) * size_t(width) + size_t(x); }

 private:
  static size_t checkedPixels(int w, int h) {
    RASTRAY_CHECK(w >= 0 && h >= 0, std::to_string(w) + "x" + std::to_string(h));
    return size_t(w) * size_t(h);
  }
};

struct DeepSample {
  glm::vec4 color{0.0f};  // linear, premultiplied: this layer's own contribution
  float depth = 0.0f;     // view depth
  uint32_t instance = 0, triangle = 0;
  uint32_t sample = 0;  // index in the SPEC §3 sample pattern
  // The renderer stopped after this layer (a transmittance cut-off or a
  // layer limit) and did not look for the surfaces behind it (SPEC §6):
  // another renderer's layers there are "cut off", not mismatches.
  bool cutOff = false;
};

// Deep frame: pixel i owns samples[offsets[i], offsets[i + 1]), sorted by
// (sample, depth, instance, triangle): front to back within each sample.
// Offsets are 64-bit: a large image at many spp with many layers exceeds
// 2^32 entries, which a 32-bit offset would wrap silently.
struct DeepImage {
  int width = 0, height = 0;
  std::vector<uint64_t> offsets;  // width·height + 1 entries
  std::vector<DeepSample> samples;
  bool hasColor = true;  // as FlatImage::hasColor
};

enum class ColorPrecision { Half, Float };

// Writes by extension: .png, or .exr (flat), in any letter case. Throws
// InputError (file: the output path) when the extension is unknown (before
// anything is written) or the file cannot be written; nothing is left at
// the target then, neither a partial file nor the temporary one
// ("<stem>.tmp.<pid>.<n><ext>" beside the target). writePng, writeExr and
// writeDeepExr write their format whatever the extension.
void writeImage(const std::string& path, const FlatImage& image,
                ColorPrecision precision = ColorPrecision::Half);
void writePng(const std::string& path, const FlatImage& image);
// The PNG writePng writes (the same pixels), in memory and compressed for
// speed rather than size (no row filter, zlib level 1): about 5 ms instead
// of 35-40 ms at 640x480, a file about twice as large. The explorer's
// previews.
std::string encodePngQuick(const FlatImage& image);
void writeExr(const std::string& path, const FlatImage& image,
              ColorPrecision precision = ColorPrecision::Half);
void writeDeepExr(const std::string& path, const DeepImage& image);

// Readers for the compare tool; accept files from other renderers with any
// subset of the SPEC §6 channels: missing Z or IDs read as +inf and kNoId,
// missing A as 1, a missing cutoff as false; without all of R, G and B the
// image has hasColor = false (a visibility export: Z and IDs only). A file
// with none of R G B A Z id.instance id.triangle is refused: it is not a
// rastray-style file at all, and comparing it would report "nothing hit"
// everywhere. Throw InputError naming the file and the channel or element
// at fault (element "" when the file as a whole cannot be read: missing,
// not OpenEXR, truncated or corrupt).
// - Only the first part (subimage) of a multi-part file is read.
// - The image covers the display window; pixels outside a smaller data
//   window read as transparent black, +inf depth, kNoId (no samples, deep).
// - IDs stored as uint are read bit for bit; IDs stored as half or float
//   are accepted when integral (float 2^32, the float rounding of
//   0xFFFFFFFF, reads as kNoId); anything else is an error.
// - readExr refuses a deep file (flattening needs the sample pattern, which
//   the caller knows: use isDeepExr and readDeepExr), readDeepExr a flat one.
// - readDeepExr returns each pixel's samples in the DeepImage order, sorting
//   if the file had another (NaN depths last); a missing id.sample reads as
//   0, i.e. all layers of a pixel belong to one sample.
// - Before decoding, the bytes the read will allocate are estimated from
//   the header (data and display windows, channels; for a deep file not
//   its samples, whose counts OpenImageIO reads and allocates in one call)
//   and the file is refused above `maxBytes`: a header can claim any size.
//   Allocation failures past the estimate are InputErrors too.
constexpr uint64_t kNoReadLimit = UINT64_MAX;
FlatImage readExr(const std::string& path, uint64_t maxBytes = kNoReadLimit);
DeepImage readDeepExr(const std::string& path, uint64_t maxBytes = kNoReadLimit);
// Throws InputError like the readers when the file cannot be opened as EXR
// (or its data window alone needs more than maxBytes to open).
bool isDeepExr(const std::string& path, uint64_t maxBytes = kNoReadLimit);
// The type an EXR file stores `channel` in, as OpenImageIO names it
// ("half", "float", "uint"); "" when the file has no such channel. Opens
// the file as the readers do (same checks, same InputErrors).
std::string exrChannelType(const std::string& path, const std::string& channel);

// Writes a text file (HTML, CSV, JSON) the same atomic way as images.
// Throws InputError (file: path) when it cannot.
void writeTextFile(const std::string& path, const std::string& text);

// sRGB transfer functions (IEC 61966-2-1), per channel.
float srgbToLinear(float encoded);
float linearToSrgb(float linear);

}  // namespace rastray
