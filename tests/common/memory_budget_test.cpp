// The memory budget (common/memory_budget.h) and the loader's checks
// against it: a tiny file whose node tree or primitives instance one
// large accessor many times is refused before the flattened store is
// allocated (issue 13), by count beyond 2^32 or by the budget.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include "common/error.h"
#include "common/gltf/loader.h"
#include "common/memory_budget.h"
#include "tests/test_files.h"

namespace rastray {
namespace {

TEST(MemoryBudget, ParsesSizesWithUnits) {
  EXPECT_EQ(MemoryBudget::parse("4096").bytes, 4096u);
  EXPECT_EQ(MemoryBudget::parse("512M").bytes, 512ull << 20);
  EXPECT_EQ(MemoryBudget::parse("4G").bytes, 4ull << 30);
  EXPECT_EQ(MemoryBudget::parse("4GiB").bytes, 4ull << 30);
  EXPECT_EQ(MemoryBudget::parse("4gb").bytes, 4ull << 30);
  EXPECT_EQ(MemoryBudget::parse("1.5T").bytes, 3ull << 39);
  EXPECT_EQ(MemoryBudget::parse("4G").origin, "--max-memory 4G");
}

TEST(MemoryBudget, RefusesWhatIsNotASize) {
  for (const char* bad : {"", "G", "abc", "12Q", "0", "-1G", "nan", "1e30T", "4 G"}) {
    try {
      MemoryBudget::parse(bad);
      ADD_FAILURE() << "'" << bad << "' was accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(e.file(), "command line");
      EXPECT_EQ(e.element(), "--max-memory");
    }
  }
}

TEST(MemoryBudget, DefaultIsAFractionOfPhysicalMemory) {
  const uint64_t physical = physicalMemoryBytes();
  ASSERT_GT(physical, 0u);
  const MemoryBudget b = MemoryBudget::machineDefault();
  EXPECT_LT(b.bytes, physical);
  EXPECT_GT(b.bytes, physical / 2);
  EXPECT_NE(b.origin.find("physical memory"), std::string::npos) << b.origin;
}

TEST(MemoryEstimate, SumsSaturatesAndNamesTheLargestParts) {
  MemoryEstimate e;
  e.add("frame", 100);
  e.add("deep samples", 5000);
  e.add("frame", 50);
  e.add("setups", 700);
  EXPECT_EQ(e.total(), 5850u);
  EXPECT_EQ(e.parts().size(), 3u);
  EXPECT_EQ(e.largest(2), "deep samples 4.88 KiB, setups 700 B");
  e.add("absurd", UINT64_MAX - 1);
  EXPECT_EQ(e.total(), UINT64_MAX);  // saturates, never wraps to a small number
  EXPECT_EQ(mulSat(uint64_t(1) << 40, uint64_t(1) << 40), UINT64_MAX);
}

TEST(MemoryEstimate, CheckRefusesAboveTheBudgetWithOneLine) {
  MemoryEstimate e;
  e.add("depth target", 3ull << 30);
  MemoryBudget b = MemoryBudget::parse("2G");
  try {
    checkMemory(e, b, "scene.gltf", "", "rendering 8000x8000 at 16 spp (raster)");
    FAIL() << "not refused";
  } catch (const InputError& err) {
    const std::string what = err.what();
    EXPECT_EQ(what.find('\n'), std::string::npos);
    EXPECT_NE(
        what.find("scene.gltf: rendering 8000x8000 at 16 spp (raster) needs about 3.00 GiB (depth target"),
        std::string::npos)
        << what;
    EXPECT_NE(what.find("above the memory limit of 2.00 GiB (--max-memory 2G)"), std::string::npos) << what;
  }
  b.bytes = 3ull << 30;
  EXPECT_NO_THROW(checkMemory(e, b, "scene.gltf", "", "rendering"));
}

// A glTF whose one POSITION accessor has no bufferView (zeros, glTF
// §3.6.2.3: no file bytes at all) and `count` vertices, used by
// `primitives` primitives of one mesh, on `nodes` nodes.
std::string instancingFile(const std::string& name, int64_t count, int primitives, int nodes) {
  nlohmann::json doc;
  doc["asset"] = {{"version", "2.0"}};
  doc["accessors"] = nlohmann::json::array({{{"componentType", 5126},
                                             {"count", count},
                                             {"type", "VEC3"},
                                             {"min", {0, 0, 0}},
                                             {"max", {0, 0, 0}}}});
  nlohmann::json prims = nlohmann::json::array();
  for (int p = 0; p < primitives; ++p) prims.push_back({{"attributes", {{"POSITION", 0}}}});
  doc["meshes"] = nlohmann::json::array({{{"primitives", prims}}});
  doc["nodes"] = nlohmann::json::array();
  nlohmann::json roots = nlohmann::json::array();
  for (int n = 0; n < nodes; ++n) {
    doc["nodes"].push_back({{"mesh", 0}, {"translation", {n, 0, 0}}});
    roots.push_back(n);
  }
  doc["scenes"] = nlohmann::json::array({{{"nodes", roots}}});
  doc["scene"] = 0;
  const std::string path = test::scratchPath(name);
  std::ofstream(path) << doc.dump();
  return path;
}

std::string loadError(const std::string& path, const MemoryBudget& budget) {
  try {
    loadScene(path, budget);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// 300 primitives × 16,777,215 zero vertices: 5·10^9 vertices from a
// file of a few kilobytes. Refused by count before the walk; the walk
// would have allocated hundreds of GiB first (the check it had was per
// primitive, after appending).
TEST(SceneLoaderLimits, PrimitivesBeyond2To32VerticesAreRefusedBeforeAllocating) {
  const std::string path = instancingFile("rastray-many-primitives.gltf", 16777215, 300, 1);
  EXPECT_LT(std::filesystem::file_size(path), 20000u);
  const std::string error = loadError(path, MemoryBudget::machineDefault());
  EXPECT_NE(error.find(": scene: the node tree instances meshes into 5033164500 vertices"), std::string::npos)
      << error;
  EXPECT_LT(currentRssBytes(), uint64_t(2) << 30);
  std::filesystem::remove(path);
}

// 200 nodes × one primitive of 16,777,215 vertices: 3.4·10^9 vertices
// (under 2^32) would take ~190 GB flattened; the budget refuses it first.
TEST(SceneLoaderLimits, InstancingBeyondTheBudgetIsRefusedBeforeAllocating) {
  const std::string path = instancingFile("rastray-many-nodes.gltf", 16777215, 1, 200);
  const std::string error = loadError(path, MemoryBudget::parse("4G"));
  EXPECT_NE(error.find(": scene: flattening 200 instances into 3355443000 vertices and 1118481000 triangles "
                       "needs about"),
            std::string::npos)
      << error;
  EXPECT_NE(error.find("above the memory limit of 4.00 GiB (--max-memory 4G)"), std::string::npos) << error;
  EXPECT_LT(currentRssBytes(), uint64_t(2) << 30);
  std::filesystem::remove(path);
}

// The same file with a few nodes fits, and loads with exactly the
// reserved sizes (no growth copies).
TEST(SceneLoaderLimits, AFittingInstancedSceneLoadsWithReservedStore) {
  const std::string path = instancingFile("rastray-few-nodes.gltf", 3000, 2, 3);
  const Scene scene = loadScene(path, MemoryBudget::parse("4G"));
  EXPECT_EQ(scene.positions.size(), 18000u);
  EXPECT_EQ(scene.positions.capacity(), 18000u);
  EXPECT_EQ(scene.triangles.size(), 6000u);
  EXPECT_EQ(scene.triangles.capacity(), 6000u);
  EXPECT_EQ(scene.instances.size(), 6u);
  std::filesystem::remove(path);
}

std::string base64(const std::string& bytes) {
  static const char* alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const size_t n = std::min<size_t>(3, bytes.size() - i);  // bytes in this group
    uint32_t v = 0;
    for (size_t k = 0; k < 3; ++k) v = v << 8 | (k < n ? uint8_t(bytes[i + k]) : 0u);
    for (size_t k = 0; k < 4; ++k) out += k <= n ? alphabet[(v >> (18 - 6 * k)) & 63] : '=';
  }
  return out;
}

// A PNG whose header declares a 16000 x 16000 RGBA canvas (stb's limit is
// 2^30 bytes per image; 3 GB counted with the conversions) in 33 bytes:
// refused from its header, before stb decodes anything.
TEST(SceneLoaderLimits, AnImageDeclaringAHugeCanvasIsRefusedFromItsHeader) {
  std::string png = std::string("\x89PNG\r\n\x1a\n", 8) + std::string("\0\0\0\x0dIHDR", 8);
  for (const uint32_t side : {16000u, 16000u})
    for (int shift = 24; shift >= 0; shift -= 8) png += char((side >> shift) & 0xFF);
  png += std::string("\x08\x06\0\0\0", 5) + std::string(4, '\0');  // 8-bit RGBA, CRC unchecked
  nlohmann::json doc;
  doc["asset"] = {{"version", "2.0"}};
  doc["images"] = nlohmann::json::array({{{"uri", "data:image/png;base64," + base64(png)}}});
  const std::string path = test::scratchPath("huge-image.gltf");
  std::ofstream(path) << doc.dump();
  const std::string error = loadError(path, MemoryBudget::parse("2G"));
  EXPECT_NE(error.find(": image 0: decoding the images needs about"), std::string::npos) << error;
  EXPECT_NE(error.find("decoded images 2.86 GiB"), std::string::npos) << error;
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace rastray
