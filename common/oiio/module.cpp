// The rastray_oiio module's entry point (common/oiio_module.h), the
// ImageBufAlgo calls it offers, and the functions of common/ it borrows
// from the program that loads it.
#include <cmath>
#include <stdexcept>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include "common/error.h"
#include "common/memory_budget.h"
#include "common/oiio/image_files.h"
#include "common/oiio_module.h"

namespace rastray {

namespace {

const OiioHost* gHost = nullptr;  // set once, before any function of the table runs

}  // namespace

// Borrowed from the program (OiioHost): compiled once, one state.
ExrHeaderFacts checkExrHeaders(const std::string& path) { return gHost->checkExrHeaders(path); }

void checkFailed(const char* expr, const char* file, int line, const std::string& detail) {
  gHost->checkFailed(expr, file, line, detail);
  std::abort();  // the host's checkFailed does not return; this keeps [[noreturn]] true
}

std::string formatBytes(uint64_t bytes) { return gHost->formatBytes(bytes); }

namespace oiio {
namespace {

static_assert(sizeof(glm::vec4) == 4 * sizeof(float), "vec4 must be packed RGBA");

// Wraps packed RGBA floats without copying; OIIO reads them in place.
OIIO::ImageBuf wrapRgba(int width, int height, const glm::vec4* pixels) {
  const OIIO::ImageSpec spec(width, height, 4, OIIO::TypeDesc::FLOAT);
  return OIIO::ImageBuf(spec, const_cast<glm::vec4*>(pixels));
}

void resizeBox(int srcWidth, int srcHeight, const glm::vec4* src, int dstWidth, int dstHeight,
               glm::vec4* dst) {
  const OIIO::ImageBuf in = wrapRgba(srcWidth, srcHeight, src);
  OIIO::ImageBuf out(OIIO::ImageSpec(dstWidth, dstHeight, 4, OIIO::TypeDesc::FLOAT));
  if (!OIIO::ImageBufAlgo::resize(out, in, "box") ||
      !out.get_pixels(OIIO::ROI::All(), OIIO::TypeDesc::FLOAT, dst))
    throw std::runtime_error("OpenImageIO resize: " + out.geterror());
}

std::vector<unsigned char> encodePng(int width, int height, int channels, const uint8_t* pixels) {
  std::vector<unsigned char> png;
  OIIO::Filesystem::IOVecOutput proxy(png);
  auto out = OIIO::ImageOutput::create("texture.png", &proxy);
  const OIIO::ImageSpec spec(width, height, channels, OIIO::TypeDesc::UINT8);
  if (!out || !out->open("texture.png", spec) || !out->write_image(OIIO::TypeDesc::UINT8, pixels) ||
      !out->close())
    throw std::runtime_error("cannot encode an image as PNG: " + (out ? out->geterror() : OIIO::geterror()));
  return png;
}

ImageDifference compareColors(int width, int height, const glm::vec4* a, const glm::vec4* b,
                              float yeeLuminance, float yeeFieldOfView) {
  const OIIO::ImageBuf ba = wrapRgba(width, height, a), bb = wrapRgba(width, height, b);
  // failthresh = warnthresh = 0: nfail counts every pixel that differs at all.
  const OIIO::ImageBufAlgo::CompareResults c = OIIO::ImageBufAlgo::compare(ba, bb, 0.0f, 0.0f);
  // CompareResults::error also reports "some pixel failed the threshold"
  // (with a threshold of 0: any difference), so real errors are read from
  // OpenImageIO's error state instead.
  if (OIIO::has_error()) throw std::runtime_error("OpenImageIO compare: " + OIIO::geterror());
  ImageDifference d;
  d.meanError = c.meanerror;
  d.rmsError = c.rms_error;
  d.maxError = c.maxerror;
  if (c.maxerror > 0.0) {
    d.maxX = c.maxx;
    d.maxY = c.maxy;
    d.maxChannel = c.maxc;
  }
  d.differingPixels = uint64_t(c.nfail);
  OIIO::ImageBufAlgo::CompareResults yee;
  const int failing = OIIO::ImageBufAlgo::compare_Yee(ba, bb, yee, yeeLuminance, yeeFieldOfView);
  if (failing < 0 || OIIO::has_error())
    throw std::runtime_error("OpenImageIO compare_Yee: " + OIIO::geterror());
  d.yeeFailingPixels = uint64_t(failing);
  return d;
}

const OiioFunctions kFunctions = {kOiioModuleVersion, writeRgba8Png,  writeExr,      writeDeepExr,
                                  isDeepExr,          exrChannelType, readExr,       readDeepExr,
                                  resizeBox,          encodePng,      compareColors, encodeRgba8PngQuick};

}  // namespace
}  // namespace oiio
}  // namespace rastray

extern "C" __attribute__((visibility("default"))) const rastray::OiioFunctions* rastray_oiio_module(
    const rastray::OiioHost* host) {
  if (!host || host->version != rastray::kOiioModuleVersion) return nullptr;
  rastray::gHost = host;
  return &rastray::oiio::kFunctions;
}
