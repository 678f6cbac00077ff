// Inputs the fuzz targets (fuzz/) found crashing or exhausting memory,
// kept in tests/data/fuzz-regressions/ and read through the normal code:
// each must be refused with an InputError naming the file (exit status 2
// on the command line), without the process first allocating what the
// file claims. Peak RSS (getrusage) is the witness for the allocations:
// ctest runs each test in a process of its own, so the growth measured is
// this test's.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cstdint>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "common/error.h"
#include "common/gltf/loader.h"
#include "common/image.h"

namespace rastray {
namespace {

const std::string kRegressions = std::string(RASTRAY_TEST_DATA) + "/fuzz-regressions/";

uint64_t peakRssBytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return uint64_t(usage.ru_maxrss) * 1024;  // Linux reports KiB
}

// Each of these files claims at least 1.6 GB; reading must stay far below.
constexpr uint64_t kMaxGrowth = uint64_t(256) << 20;

// Calls read(path) and expects an InputError naming the file whose message
// contains `phrase`, with peak RSS growing less than kMaxGrowth.
template <typename Read>
void expectRefusedCheaply(const std::string& name, const std::string& phrase, Read read) {
  const std::string path = kRegressions + name;
  const uint64_t before = peakRssBytes();
  try {
    read(path);
    ADD_FAILURE() << name << " was read without an InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_NE(std::string(e.what()).find(phrase), std::string::npos) << e.what();
  }
  const uint64_t growth = peakRssBytes() - before;
  EXPECT_LT(growth, kMaxGrowth) << name << ": peak RSS grew by " << growth << " bytes";
}

// A 31-byte file whose string attribute declares 1.8 GB: OpenEXR
// allocated and filled that much before finding the end of the file
// (found as a 346-byte file, cut down by hand).
TEST(FuzzRegressions, ExrAttributeLargerThanTheFile) {
  for (auto read : {+[](const std::string& p) { readExr(p); }, +[](const std::string& p) { readDeepExr(p); },
                    +[](const std::string& p) { isDeepExr(p); }})
    expectRefusedCheaply("exr-string-attribute-1.8GB.exr", "are left in the file", read);
}

// A channel list declaring 147 bytes whose channels end after 56: OpenEXR
// reads the list up to its end and the next attribute from there, where
// the bytes declare a 1.6 GB string.
TEST(FuzzRegressions, ExrChannelListShorterThanDeclared) {
  expectRefusedCheaply("exr-channel-list-shorter-than-declared.exr", "ends before its declared size",
                       [](const std::string& p) { readExr(p); });
}

// A channel whose pixel type is none of OpenEXR's three: OpenImageIO 2.4
// aborted the process while opening the file ("TypeDesc_from_ImfPixelType:
// Assertion '0' failed: Unknown Imf::PixelType 3").
TEST(FuzzRegressions, ExrChannelPixelTypeOutOfRange) {
  expectRefusedCheaply("exr-channel-pixel-type-invalid.exr", "has pixel type",
                       [](const std::string& p) { readDeepExr(p); });
  expectRefusedCheaply("exr-channel-pixel-type-invalid.exr", "has pixel type",
                       [](const std::string& p) { isDeepExr(p); });
}

// A 1.5 KB deep file declaring a 50,331,654 x 1 data window: OpenEXR
// allocated 200 MB of sample counts on opening, OpenImageIO 3.6 GB of
// per-pixel pointers on reading, before the missing data showed.
TEST(FuzzRegressions, ExrDeepDataWindowTheFileCannotHold) {
  expectRefusedCheaply("exr-deep-data-window-50M-pixels.exr", "cannot be stored in",
                       [](const std::string& p) { readDeepExr(p); });
  expectRefusedCheaply("exr-deep-data-window-50M-pixels.exr", "cannot be stored in",
                       [](const std::string& p) { isDeepExr(p); });
}

// A 497-byte tiled file whose tiles are 4 x 16,776,964 pixels: OpenEXR
// allocated 1.4 GB of tile buffers for a 6 x 4 image (found as a timeout:
// freeing them under ASan took over 10 s).
TEST(FuzzRegressions, ExrTilesFarLargerThanTheImage) {
  expectRefusedCheaply("exr-tiles-4x16776964.exr", "are larger than the data window",
                       [](const std::string& p) { readExr(p); });
}

// The readers' estimate: a file within the format's bounds whose windows
// need more than the caller allows is refused before decoding.
TEST(FuzzRegressions, ExrReadLimitRefusesBeforeDecoding) {
  const std::string path = kRegressions + "../../../fuzz/corpus/exr_reader_fuzzer/flat-half.exr";
  const FlatImage image = readExr(path);  // 6 x 4 pixels
  EXPECT_EQ(image.width, 6);
  EXPECT_NO_THROW(readExr(path, 4096));
  try {
    readExr(path, 256);
    ADD_FAILURE() << "a 6 x 4 image read within 256 bytes";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("above the limit of 256"), std::string::npos) << e.what();
  }
  EXPECT_THROW(readDeepExr(kRegressions + "../../../fuzz/corpus/exr_reader_fuzzer/deep.exr", 256),
               InputError);
}

// The fuzz target's entry point loads exactly what loadScene loads.
TEST(FuzzRegressions, LoadSceneFromMemoryMatchesLoadScene) {
  for (const std::string name : {"cornell-box.gltf", "textured-plane.gltf"}) {
    const std::string path = std::string(RASTRAY_SCENES) + "/" + name;
    std::ifstream in(path, std::ios::binary);
    std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const Scene fromFile = loadScene(path), fromMemory = loadSceneFromMemory(path, bytes);
    EXPECT_EQ(fromFile.positions, fromMemory.positions) << name;
    EXPECT_EQ(fromFile.instances.size(), fromMemory.instances.size()) << name;
    EXPECT_EQ(fromFile.materials.size(), fromMemory.materials.size()) << name;
    EXPECT_EQ(fromFile.textures.size(), fromMemory.textures.size()) << name;
  }
  try {
    loadSceneFromMemory("/no-such-folder/x.glb", std::vector<uint8_t>{'g', 'l', 'T', 'F', 2, 0, 0, 0});
    ADD_FAILURE() << "a truncated GLB header loaded";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), "/no-such-folder/x.glb");
    EXPECT_EQ(e.element(), "GLB header");
  }
}

}  // namespace
}  // namespace rastray
