// The image files of common/image.h, written and read with OpenImageIO,
// inside the rastray_oiio module (common/oiio_module.h). The callers in
// common/image.cpp check the images and choose the temporary file names;
// these functions do the OpenImageIO work.
#include "common/oiio/image_files.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <memory>
#include <new>
#include <stdexcept>

#include <OpenImageIO/deepdata.h>
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include "common/error.h"
#include "common/exr_header.h"
#include "common/memory_budget.h"
#include "common/scene.h"

namespace rastray::oiio {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// The channel layout of every EXR we write (SPEC §6).
const char* const kR = "R";
const char* const kG = "G";
const char* const kB = "B";
const char* const kA = "A";
const char* const kZ = "Z";
const char* const kInstance = "id.instance";
const char* const kTriangle = "id.triangle";
const char* const kSample = "id.sample";
const char* const kCutoff = "cutoff";

// Opens the temporary file `tmp` with the OIIO plugin `format`, lets
// `writePixels` fill it, closes it and renames it over `path`. On any
// failure the temporary file is removed and InputError names `path`.
void writeAtomically(const std::string& path, const std::string& tmp, const char* format,
                     const OIIO::ImageSpec& spec,
                     const std::function<bool(OIIO::ImageOutput&)>& writePixels) {
  bool ok = false;
  std::string error;
  try {
    std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create(format);
    if (!out) {
      error = OIIO::geterror();
    } else {
      ok = out->open(tmp, spec) && writePixels(*out) && out->close();
      if (!ok) error = out->geterror();
    }
  } catch (...) {
    std::remove(tmp.c_str());
    throw;
  }
  // The ImageOutput is gone (and its file closed) before we rename or remove.
  if (ok && std::rename(tmp.c_str(), path.c_str()) != 0) {
    ok = false;
    error = std::string("cannot rename the temporary file into place: ") + std::strerror(errno);
  }
  if (!ok) {
    std::remove(tmp.c_str());
    throw InputError(path, "", "cannot write: " + (error.empty() ? "OpenImageIO failed" : error));
  }
}

// Only OpenImageIO's OpenEXR reader sees the file: ImageInput::open would
// offer a file that is not EXR to every format plugin it has (DICOM, RAW,
// movies, ...), each a large decoder run for nothing but a refusal.
// Opening a deep file, OpenEXR allocates a sample count (4 bytes) per
// pixel of the data window, and reading it OpenImageIO a pointer per pixel
// and channel: refused before either happens when the file cannot hold
// that many pixels, or when it exceeds `maxBytes`. A deep file stores each
// pixel's count (4 bytes) compressed with zlib, RLE or not at all; zlib's
// best ratio is 1032:1 (a deflate block of repeated bytes), so a file holds
// at most 258 deep pixels per byte. (A 1.5 KB file declaring 50 million
// deep pixels had OpenImageIO allocate 3.6 GB; tests/data/fuzz-regressions.)
constexpr uint64_t kMaxDeepPixelsPerByte = 1032 / 4;

std::unique_ptr<OIIO::ImageInput> openExr(const std::string& path, uint64_t maxBytes) {
  const ExrHeaderFacts facts = checkExrHeaders(path);
  if (facts.deep && facts.dataPixels / kMaxDeepPixelsPerByte > facts.fileSize)
    throw InputError(path, "header",
                     "deep data window of " + std::to_string(facts.dataPixels) +
                         " pixels cannot be stored in " + std::to_string(facts.fileSize) +
                         " bytes (at most " + std::to_string(kMaxDeepPixelsPerByte) + " pixels a byte)");
  // OpenEXR allocates whole tiles for a tiled file, however small the
  // image: a 497-byte file with 4 x 16,776,964-pixel tiles had it allocate
  // 1.4 GB. Tiles larger than the image are legal (64 x 64 tiles on a
  // smaller image are common), so the bound is the larger of the data
  // window and 2^20 pixels.
  if (facts.tilePixels > std::max(facts.dataPixels, uint64_t(1) << 20))
    throw InputError(path, "header",
                     "tiles of " + std::to_string(facts.tilePixels) +
                         " pixels are larger than the data window (" + std::to_string(facts.dataPixels) +
                         " pixels) and 2^20 pixels");
  if (facts.dataPixels > maxBytes / 4)
    throw InputError(path, "",
                     "reading it needs more than " + std::to_string(facts.dataPixels) + " x 4 bytes (its " +
                         "data window is too large), above the limit of " + std::to_string(maxBytes));
  std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::create("openexr");
  if (!in) throw InputError(path, "", "cannot read: OpenImageIO has no OpenEXR reader: " + OIIO::geterror());
  OIIO::ImageSpec opened;
  if (!in->open(path, opened)) throw InputError(path, "", "cannot read: " + in->geterror());
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.depth != 1 || spec.width <= 0 || spec.height <= 0) {
    throw InputError(path, "", "unsupported data window (volume or empty)");
  }
  return in;
}

// Where R, G, B and A are (-1: absent). Colour is all of R, G and B or
// none: a partial set (say R and B) cannot be compared without guessing the
// missing channel, so it counts as no colour, like a visibility export.
struct ColorChannels {
  int r, g, b, a;
  bool complete() const { return r >= 0 && g >= 0 && b >= 0; }
};

// Any subset of the SPEC §6 channels is a file we can compare, but a file
// with none of them (say only "Y", or layers named "beauty.R") would
// compare as "nothing hit" everywhere: refuse it and list what it has.
ColorChannels colorChannelsOf(const std::string& path, const OIIO::ImageSpec& spec) {
  const ColorChannels c{spec.channelindex(kR), spec.channelindex(kG), spec.channelindex(kB),
                        spec.channelindex(kA)};
  for (const char* name : {kR, kG, kB, kA, kZ, kInstance, kTriangle})
    if (spec.channelindex(name) >= 0) return c;
  std::string have;
  for (const std::string& n : spec.channelnames) have += (have.empty() ? "" : " ") + n;
  throw InputError(path, "channels",
                   "none of R G B A Z id.instance id.triangle (the file has: " + have + ")");
}

// Where the data window lies in the display window. Our own files have
// them equal; other renderers may crop (e.g. to the non-empty region). The
// image we return covers the display window; pixels outside the data
// window read as "nothing here".
struct Windows {
  int width, height;  // display window
  int dataX, dataY;   // data window origin relative to the display window
  int dataWidth, dataHeight;
};

Windows windowsOf(const OIIO::ImageSpec& spec) {
  Windows w;
  w.dataWidth = spec.width;
  w.dataHeight = spec.height;
  if (spec.full_width > 0 && spec.full_height > 0) {
    w.width = spec.full_width;
    w.height = spec.full_height;
    w.dataX = spec.x - spec.full_x;
    w.dataY = spec.y - spec.full_y;
  } else {
    w.width = spec.width;
    w.height = spec.height;
    w.dataX = w.dataY = 0;
  }
  return w;
}

std::string pixelName(int x, int y) { return "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ")"; }

// Other renderers may store IDs as half or float. We take them when the
// value is an integer in uint32 range; 2^32 is what 0xFFFFFFFF rounds to in
// float, so it reads as kNoId. (Float is exact only up to 2^24: larger IDs
// may already have been rounded by the writer, which we cannot detect.)
bool idFromReal(double v, uint32_t& id) {
  if (v == 4294967296.0) {
    id = kNoId;
    return true;
  }
  if (!(v >= 0.0 && v <= 4294967295.0) || v != std::floor(v)) return false;
  id = uint32_t(v);
  return true;
}

[[noreturn]] void badId(const std::string& path, const char* channel, double v, int x, int y) {
  char value[64];
  std::snprintf(value, sizeof value, "%.17g", v);
  throw InputError(path, std::string("channel ") + channel,
                   std::string("value ") + value + " at " + pixelName(x, y) + " is not an integer id");
}

// Reads one channel of the native pixel buffer into `dst` (one value every
// dstStride bytes), converting with OIIO.
void convertChannel(const OIIO::ImageSpec& spec, const std::vector<char>& native, int c,
                    OIIO::TypeDesc dstType, void* dst, OIIO::stride_t dstStride) {
  size_t offset = 0;
  for (int k = 0; k < c; ++k) offset += spec.channelformat(k).size();
  const OIIO::stride_t pixelBytes = OIIO::stride_t(spec.pixel_bytes(true));
  OIIO::convert_image(1, spec.width, spec.height, 1, native.data() + offset, spec.channelformat(c),
                      pixelBytes, pixelBytes * spec.width, OIIO::AutoStride, dst, dstType, dstStride,
                      dstStride * spec.width, OIIO::AutoStride);
}

// IDs: UINT channels are copied bit for bit (OIIO would otherwise scale
// integers as normalized values); half/float go through idFromReal.
void readIdChannel(const std::string& path, const OIIO::ImageSpec& spec, const std::vector<char>& native,
                   const char* name, std::vector<uint32_t>& ids) {
  const int c = spec.channelindex(name);
  if (c < 0) return;  // stays kNoId
  const OIIO::TypeDesc type = spec.channelformat(c);
  if (type.basetype == OIIO::TypeDesc::UINT32) {
    convertChannel(spec, native, c, OIIO::TypeUInt32, ids.data(), sizeof(uint32_t));
    return;
  }
  if (type.basetype != OIIO::TypeDesc::HALF && type.basetype != OIIO::TypeDesc::FLOAT &&
      type.basetype != OIIO::TypeDesc::DOUBLE) {
    throw InputError(path, std::string("channel ") + name,
                     std::string("stored as ") + type.c_str() + "; expected uint, half or float");
  }
  std::vector<double> real(ids.size());
  convertChannel(spec, native, c, OIIO::TypeDesc::DOUBLE, real.data(), sizeof(double));
  const Windows w = windowsOf(spec);
  for (size_t i = 0; i < ids.size(); ++i) {
    if (!idFromReal(real[i], ids[i])) {
      badId(path, name, real[i], int(i % size_t(spec.width)) + w.dataX,
            int(i / size_t(spec.width)) + w.dataY);
    }
  }
}

// One ID of a deep sample; `missing` when the file has no such channel.
uint32_t deepId(const std::string& path, const OIIO::DeepData& deep, int c, const char* name,
                uint32_t missing, int64_t pixel, int sample, int x, int y) {
  if (c < 0) return missing;
  if (deep.channeltype(c).basetype == OIIO::TypeDesc::UINT32) {
    return deep.deep_value_uint(pixel, c, sample);
  }
  // deep_value is exact for half and float (and would scale a uint).
  const double v = deep.deep_value(pixel, c, sample);
  uint32_t id = 0;
  if (!idFromReal(v, id)) badId(path, name, v, x, y);
  return id;
}

// Depth order with NaN last, so that sorting is well defined for any file.
bool depthBefore(float a, float b) {
  const bool nanA = std::isnan(a), nanB = std::isnan(b);
  if (nanA || nanB) return !nanA && nanB;
  return a < b;
}

bool deepSampleBefore(const DeepSample& a, const DeepSample& b) {
  if (a.sample != b.sample) return a.sample < b.sample;
  if (depthBefore(a.depth, b.depth)) return true;
  if (depthBefore(b.depth, a.depth)) return false;
  if (a.instance != b.instance) return a.instance < b.instance;
  return a.triangle < b.triangle;
}

}  // namespace

void writeRgba8Png(const std::string& path, const std::string& tmp, int width, int height,
                   const uint8_t* rgba) {
  OIIO::ImageSpec spec(width, height, 4, OIIO::TypeUInt8);
  spec.attribute("oiio:ColorSpace", "sRGB");
  // The bytes are already straight: without this OIIO would un-premultiply
  // them a second time.
  spec.attribute("oiio:UnassociatedAlpha", 1);
  writeAtomically(path, tmp, "png", spec,
                  [&](OIIO::ImageOutput& out) { return out.write_image(OIIO::TypeUInt8, rgba); });
}

std::vector<unsigned char> encodeRgba8PngQuick(int width, int height, const uint8_t* rgba) {
  std::vector<unsigned char> png;
  OIIO::Filesystem::IOVecOutput proxy(png);
  std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create("preview.png", &proxy);
  OIIO::ImageSpec spec(width, height, 4, OIIO::TypeUInt8);
  spec.attribute("oiio:ColorSpace", "sRGB");
  spec.attribute("oiio:UnassociatedAlpha", 1);
  // libpng's default tries all five row filters on every row and zlib's
  // default level searches hard: 35-40 ms for a 640x480 frame. No filter
  // and level 1 take about 5 ms for a file about twice the size.
  spec.attribute("png:filter", 8);  // PNG_FILTER_NONE
  spec.attribute("png:compressionLevel", 1);
  if (!out || !out->open("preview.png", spec) || !out->write_image(OIIO::TypeUInt8, rgba) || !out->close())
    throw std::runtime_error("cannot encode an image as PNG: " + (out ? out->geterror() : OIIO::geterror()));
  return png;
}

// OIIO's OpenEXR writer stamps the current time as DateTime unless the
// spec sets one; an empty string makes it write none, so the same render
// gives the same bytes (issue 13: no varying metadata in headers).
namespace {
void omitTimestamp(OIIO::ImageSpec& spec) { spec.attribute("DateTime", ""); }
}  // namespace

void writeExr(const std::string& path, const std::string& tmp, const FlatImage& image,
              ColorPrecision precision) {
  const OIIO::TypeDesc colorType = precision == ColorPrecision::Float ? OIIO::TypeFloat : OIIO::TypeHalf;
  OIIO::ImageSpec spec(image.width, image.height, 7, OIIO::TypeFloat);
  spec.channelnames = {kR, kG, kB, kA, kZ, kInstance, kTriangle};
  spec.channelformats = {colorType,       colorType,        colorType,       colorType,
                         OIIO::TypeFloat, OIIO::TypeUInt32, OIIO::TypeUInt32};
  spec.alpha_channel = 3;
  spec.z_channel = 4;
  // Lossless (not pxr24 or dwa), so Z and the IDs survive bit for bit.
  spec.attribute("compression", "zip");
  omitTimestamp(spec);

  // The file's native layout: per pixel, each channel in its own format,
  // packed. OIIO converts colour to half (round to nearest even) and copies
  // float and uint exactly.
  const OIIO::stride_t pixelBytes = OIIO::stride_t(spec.pixel_bytes(true));
  const OIIO::stride_t rowBytes = pixelBytes * image.width;
  std::vector<char> native(size_t(rowBytes) * size_t(image.height));
  char* p = native.data();
  const auto convert = [&](int nchannels, const void* src, OIIO::TypeDesc type, OIIO::stride_t srcStride,
                           OIIO::TypeDesc dstType) {
    OIIO::convert_image(nchannels, image.width, image.height, 1, src, type, srcStride,
                        srcStride * image.width, OIIO::AutoStride, p, dstType, pixelBytes, rowBytes,
                        OIIO::AutoStride);
    p += nchannels * dstType.size();
  };
  convert(4, image.color.data(), OIIO::TypeFloat, sizeof(glm::vec4), colorType);
  convert(1, image.depth.data(), OIIO::TypeFloat, sizeof(float), OIIO::TypeFloat);
  convert(1, image.instance.data(), OIIO::TypeUInt32, sizeof(uint32_t), OIIO::TypeUInt32);
  convert(1, image.triangle.data(), OIIO::TypeUInt32, sizeof(uint32_t), OIIO::TypeUInt32);

  writeAtomically(path, tmp, "openexr", spec,
                  [&](OIIO::ImageOutput& out) { return out.write_image(OIIO::TypeUnknown, native.data()); });
}

void writeDeepExr(const std::string& path, const std::string& tmp, const DeepImage& image) {
  const size_t pixels = size_t(image.width) * size_t(image.height);
  RASTRAY_CHECK(image.width >= 0 && image.height >= 0 && image.offsets.size() == pixels + 1 &&
                    image.offsets.front() == 0 && image.offsets.back() == image.samples.size(),
                "DeepImage " + std::to_string(image.width) + "x" + std::to_string(image.height) + " with " +
                    std::to_string(image.offsets.size()) + " offsets and " +
                    std::to_string(image.samples.size()) + " samples");

  // Colour is float, not half: deep files are for sample-exact analysis.
  OIIO::ImageSpec spec(image.width, image.height, 9, OIIO::TypeFloat);
  spec.channelnames = {kR, kG, kB, kA, kZ, kInstance, kTriangle, kSample, kCutoff};
  spec.channelformats = {OIIO::TypeFloat,  OIIO::TypeFloat,  OIIO::TypeFloat,
                         OIIO::TypeFloat,  OIIO::TypeFloat,  OIIO::TypeUInt32,
                         OIIO::TypeUInt32, OIIO::TypeUInt32, OIIO::TypeUInt32};
  spec.alpha_channel = 3;
  spec.z_channel = 4;
  spec.deep = true;
  spec.attribute("compression", "zips");  // lossless; deep files allow none, rle, zips
  omitTimestamp(spec);

  OIIO::DeepData deep(spec);
  std::vector<unsigned int> counts(pixels);
  for (size_t i = 0; i < pixels; ++i) {
    RASTRAY_CHECK(image.offsets[i] <= image.offsets[i + 1], "offsets[" + std::to_string(i) + "] decreases");
    // OpenEXR counts one pixel's samples in 32 bits (the file's total may exceed that).
    const uint64_t count = image.offsets[i + 1] - image.offsets[i];
    RASTRAY_CHECK(count <= std::numeric_limits<unsigned int>::max(),
                  "pixel " + std::to_string(i) + " has " + std::to_string(count) + " deep samples");
    counts[i] = unsigned(count);
  }
  deep.set_all_samples(counts);
  for (size_t i = 0; i < pixels; ++i) {
    for (uint32_t s = 0; s < counts[i]; ++s) {
      const DeepSample& d = image.samples[image.offsets[i] + s];
      const int64_t px = int64_t(i);
      const int si = int(s);
      for (int k = 0; k < 4; ++k) deep.set_deep_value(px, k, si, d.color[k]);
      deep.set_deep_value(px, 4, si, d.depth);
      deep.set_deep_value(px, 5, si, d.instance);
      deep.set_deep_value(px, 6, si, d.triangle);
      deep.set_deep_value(px, 7, si, d.sample);
      deep.set_deep_value(px, 8, si, uint32_t(d.cutOff ? 1 : 0));
    }
  }
  writeAtomically(path, tmp, "openexr", spec,
                  [&](OIIO::ImageOutput& out) { return out.write_deep_image(deep); });
}

bool isDeepExr(const std::string& path, uint64_t maxBytes) { return openExr(path, maxBytes)->spec().deep; }

std::string exrChannelType(const std::string& path, const std::string& channel) {
  const std::unique_ptr<OIIO::ImageInput> in = openExr(path, kNoReadLimit);  // owns the spec
  const OIIO::ImageSpec& spec = in->spec();
  const int c = spec.channelindex(channel);
  return c < 0 ? std::string() : std::string(spec.channelformat(c).c_str());
}

namespace {

// Upper bounds of what the readers below allocate for `spec`, per pixel of
// the data window and of the display window (bytes, from the structures:
// FlatImage holds a vec4, a float and two uint32 per pixel).
uint64_t flatReadBytes(const OIIO::ImageSpec& spec) {
  const Windows w = windowsOf(spec);
  const uint64_t data = mulSat(uint64_t(w.dataWidth), uint64_t(w.dataHeight));
  const uint64_t display = mulSat(uint64_t(w.width), uint64_t(w.height));
  // The native buffer, the data-window FlatImage, a double per pixel for a
  // half or float ID channel, and the display-window FlatImage.
  const uint64_t perDataPixel =
      addSat(uint64_t(spec.pixel_bytes(true)), sizeof(FlatImage::color[0]) + 12 + 8);
  return addSat(mulSat(data, perDataPixel), mulSat(display, sizeof(FlatImage::color[0]) + 12));
}

uint64_t deepReadBytes(const OIIO::ImageSpec& spec) {
  const Windows w = windowsOf(spec);
  const uint64_t data = mulSat(uint64_t(w.dataWidth), uint64_t(w.dataHeight));
  const uint64_t display = mulSat(uint64_t(w.width), uint64_t(w.height));
  // OpenEXR's deep frame buffer holds a pointer per pixel and channel;
  // OIIO's DeepData a count, a capacity and a cumulative capacity per
  // pixel; the DeepImage an offset per display pixel. Samples come on top.
  const uint64_t perDataPixel = addSat(mulSat(uint64_t(std::max(spec.nchannels, 0)), 8), 12);
  return addSat(mulSat(data, perDataPixel), mulSat(addSat(display, 1), 8));
}

void checkReadBytes(const std::string& path, uint64_t needed, uint64_t maxBytes) {
  if (needed <= maxBytes) return;
  throw InputError(path, "",
                   "reading it needs more than " + formatBytes(needed) +
                       " (its windows are too large), above the limit of " + formatBytes(maxBytes));
}

}  // namespace

FlatImage readExr(const std::string& path, uint64_t maxBytes) {
  std::unique_ptr<OIIO::ImageInput> in = openExr(path, maxBytes);
  const OIIO::ImageSpec spec = in->spec();
  // Flattening a deep file needs the sample pattern (average the per-sample
  // composites, Z and IDs from the centre sample), which only the caller
  // knows; so we refuse and let the caller use readDeepExr.
  if (spec.deep) throw InputError(path, "", "deep EXR where a flat one is expected");
  const ColorChannels cc = colorChannelsOf(path, spec);
  checkReadBytes(path, flatReadBytes(spec), maxBytes);
  const int cZ = spec.channelindex(kZ);

  // One decode in the file's own formats; every channel is then converted
  // from that buffer.
  std::vector<char> native(spec.image_bytes(true));
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeUnknown, native.data())) {
    throw InputError(path, "", "cannot read pixels: " + in->geterror());
  }

  FlatImage data(spec.width, spec.height);
  const OIIO::stride_t colorStride = sizeof(glm::vec4);
  float* color = &data.color[0][0];
  data.hasColor = cc.complete();
  if (data.hasColor) {
    convertChannel(spec, native, cc.r, OIIO::TypeFloat, color + 0, colorStride);
    convertChannel(spec, native, cc.g, OIIO::TypeFloat, color + 1, colorStride);
    convertChannel(spec, native, cc.b, OIIO::TypeFloat, color + 2, colorStride);
  }
  if (cc.a >= 0) {
    convertChannel(spec, native, cc.a, OIIO::TypeFloat, color + 3, colorStride);
  } else {
    for (glm::vec4& c : data.color) c.a = 1.0f;
  }
  if (cZ >= 0) convertChannel(spec, native, cZ, OIIO::TypeFloat, data.depth.data(), sizeof(float));
  readIdChannel(path, spec, native, kInstance, data.instance);
  readIdChannel(path, spec, native, kTriangle, data.triangle);

  const Windows w = windowsOf(spec);
  if (w.dataX == 0 && w.dataY == 0 && w.dataWidth == w.width && w.dataHeight == w.height) {
    return data;
  }
  FlatImage image(w.width, w.height);
  image.hasColor = data.hasColor;
  for (int y = std::max(0, w.dataY); y < std::min(w.height, w.dataY + w.dataHeight); ++y) {
    for (int x = std::max(0, w.dataX); x < std::min(w.width, w.dataX + w.dataWidth); ++x) {
      const size_t from = data.index(x - w.dataX, y - w.dataY), to = image.index(x, y);
      image.color[to] = data.color[from];
      image.depth[to] = data.depth[from];
      image.instance[to] = data.instance[from];
      image.triangle[to] = data.triangle[from];
    }
  }
  return image;
}

DeepImage readDeepExr(const std::string& path, uint64_t maxBytes) {
  std::unique_ptr<OIIO::ImageInput> in = openExr(path, maxBytes);
  const OIIO::ImageSpec spec = in->spec();
  if (!spec.deep) throw InputError(path, "", "flat EXR where a deep one is expected");
  const ColorChannels cc = colorChannelsOf(path, spec);
  checkReadBytes(path, deepReadBytes(spec), maxBytes);
  const int cZ = spec.channelindex(kZ);
  const int cInstance = spec.channelindex(kInstance);
  const int cTriangle = spec.channelindex(kTriangle);
  const int cSample = spec.channelindex(kSample);
  const int cCutoff = spec.channelindex(kCutoff);

  OIIO::DeepData deep;
  if (!in->read_native_deep_image(0, 0, deep)) {
    throw InputError(path, "", "cannot read deep pixels: " + in->geterror());
  }

  const Windows w = windowsOf(spec);
  DeepImage image;
  image.width = w.width;
  image.height = w.height;
  image.hasColor = cc.complete();
  image.offsets.assign(size_t(w.width) * size_t(w.height) + 1, 0);
  // The data-window pixel that display pixel (x, y) reads, or -1.
  const auto dataPixel = [&](int x, int y) -> int64_t {
    const int dx = x - w.dataX, dy = y - w.dataY;
    if (dx < 0 || dy < 0 || dx >= w.dataWidth || dy >= w.dataHeight) return -1;
    return int64_t(dy) * w.dataWidth + dx;
  };
  for (int y = 0; y < w.height; ++y) {
    for (int x = 0; x < w.width; ++x) {
      const int64_t px = dataPixel(x, y);
      const size_t i = size_t(y) * size_t(w.width) + size_t(x);
      image.offsets[i + 1] = image.offsets[i] + uint64_t(px < 0 ? 0 : deep.samples(px));
    }
  }
  image.samples.resize(image.offsets.back());
  for (int y = 0; y < w.height; ++y) {
    for (int x = 0; x < w.width; ++x) {
      const int64_t px = dataPixel(x, y);
      if (px < 0) continue;
      const size_t i = size_t(y) * size_t(w.width) + size_t(x);
      DeepSample* out = image.samples.data() + image.offsets[i];
      const int n = deep.samples(px);
      for (int s = 0; s < n; ++s) {
        DeepSample& d = out[s];
        const float alpha = cc.a >= 0 ? deep.deep_value(px, cc.a, s) : 1.0f;
        d.color = cc.complete() ? glm::vec4(deep.deep_value(px, cc.r, s), deep.deep_value(px, cc.g, s),
                                            deep.deep_value(px, cc.b, s), alpha)
                                : glm::vec4(0.0f, 0.0f, 0.0f, alpha);
        d.depth = cZ >= 0 ? deep.deep_value(px, cZ, s) : kInf;
        d.instance = deepId(path, deep, cInstance, kInstance, kNoId, px, s, x, y);
        d.triangle = deepId(path, deep, cTriangle, kTriangle, kNoId, px, s, x, y);
        // Without id.sample every layer counts as sample 0.
        d.sample = deepId(path, deep, cSample, kSample, 0, px, s, x, y);
        // A flag, read like an ID (uint, or integral half/float); absent: false.
        d.cutOff = deepId(path, deep, cCutoff, kCutoff, 0, px, s, x, y) != 0;
      }
      // Files from other renderers need not be in our order (DeepImage).
      std::stable_sort(out, out + n, deepSampleBefore);
    }
  }
  return image;
}

}  // namespace rastray::oiio
