// libFuzzer target: bytes → what `rastray compare` does with an EXR file
// before its colour metrics: isDeepExr opens it with OpenImageIO (after
// checkExrHeaders), readExr or readDeepExr reads it (common/image.h:
// channels, IDs, data and display windows, deep sample order), then the
// visibility comparison of the file with itself (compare/visibility.h) and
// the flattening of deep colour. The colour metrics are left out: they are
// OpenImageIO's ImageBufAlgo (uninstrumented), whose time grows with the
// pixels and says nothing about the reader. OpenImageIO needs a file name,
// so each input is written to one temporary file per process, reused.
//
// An InputError is the reader refusing bad input (exit 2 on the command
// line) and is a normal outcome. A crash, a sanitizer report, a failed
// internal check or any other exception escaping is a finding.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <OpenImageIO/imageio.h>

#include "common/error.h"
#include "common/image.h"
#include "compare/color_metrics.h"
#include "compare/visibility.h"

namespace {

std::string gPath;

void printCheckFailure(const std::string& message) {
  std::fprintf(stderr, "rastray: %s\n", message.c_str());
  std::fflush(stderr);
}

void removeInputFile() { std::remove(gPath.c_str()); }

void writeInputFile(const uint8_t* data, size_t size) {
  std::FILE* f = std::fopen(gPath.c_str(), "wb");
  if (!f || (size > 0 && std::fwrite(data, 1, size, f) != size) || std::fclose(f) != 0) {
    std::fprintf(stderr, "exr_reader_fuzzer: cannot write %s\n", gPath.c_str());
    std::abort();  // a harness failure, not an input's: stop loudly
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  rastray::setCheckFailureHandler(&printCheckFailure);
  // tmpfs when there is one: every input is written once.
  const char* dir =
      access("/dev/shm", W_OK) == 0 ? "/dev/shm" : (std::getenv("TMPDIR") ? std::getenv("TMPDIR") : "/tmp");
  gPath = std::string(dir) + "/rastray-exr-fuzz-" + std::to_string(getpid()) + ".exr";
  std::atexit(&removeInputFile);
  // One thread: the machine is shared, and OpenImageIO's decoding threads
  // add nothing to what rastray's code is fed.
  OIIO::attribute("threads", 1);
  OIIO::attribute("exr_threads", 1);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  writeInputFile(data, size);
  // Files whose reading the estimate puts above 256 KiB (about 9,000
  // flat or 32,000 deep pixels) are refused: a large valid image is slow,
  // not wrong. The comparison's work is pixels x samples per pixel (up to
  // 256, inferred from id.sample), so a deep file of 257,000 mostly empty
  // pixels took 9 s here. An allocation the estimate missed still shows
  // against -rss_limit_mb.
  constexpr uint64_t kMaxImageBytes = uint64_t(256) << 10;
  try {
    const rastray::ClassifierSettings settings;  // as compare without --scene
    const rastray::FrameNames names{gPath, gPath};
    if (rastray::isDeepExr(gPath, kMaxImageBytes)) {
      const rastray::DeepImage image = rastray::readDeepExr(gPath, kMaxImageBytes);
      const rastray::VisibilityReport report = rastray::compareVisibility(image, image, 0, settings, names);
      rastray::flattenDeepColor(image, report.spp);
    } else {
      const rastray::FlatImage image = rastray::readExr(gPath, kMaxImageBytes);
      rastray::compareVisibility(image, image, 0, settings, names);
    }
  } catch (const rastray::InputError&) {
    // Refused with a message: what the reader is for.
  }
  return 0;
}
