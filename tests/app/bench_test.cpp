// `rastray bench`: the statistics, frames on a prepared scene (each frame
// reports its own work, however many came before), the JSON schema and the
// command's last line and bad input.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "app/bench/bench.h"
#include "app/report/csv.h"
#include "app/studies/stability_measure.h"
#include "tests/app/run_command.h"
#include "tests/test_files.h"

namespace rastray {
namespace {

const std::string kCornell = std::string(RASTRAY_SCENES) + "/cornell-box.gltf";

TEST(BenchSpread, MedianOfOddAndEvenCounts) {
  const Spread odd = spreadOf({5.0, 1.0, 3.0});
  EXPECT_EQ(odd.median, 3.0);
  EXPECT_EQ(odd.min, 1.0);
  EXPECT_EQ(odd.max, 5.0);
  EXPECT_EQ(odd.count, 3);
  EXPECT_EQ(spreadOf({4.0, 1.0, 2.0, 3.0}).median, 2.5);
  EXPECT_EQ(spreadOf({}).count, 0);
}

BenchResult bench(const std::vector<std::string>& args, int frames, int warmup) {
  BenchRequest request;
  request.scenePath = kCornell;
  request.settings = renderSettingsFrom(args);
  request.frames = frames;
  request.warmup = warmup;
  return runBench(request);
}

// Every frame does the same work, so the counters of the last frame do not
// depend on how many frames came before it (the ray caster's counts restart
// per frame, the BVH is kept).
TEST(Bench, EachFrameReportsItsOwnRays) {
  const BenchResult one = bench({"--renderer", "raytrace", "--size", "40", "30", "--spp", "4"}, 1, 0);
  const BenchResult four = bench({"--renderer", "raytrace", "--size", "40", "30", "--spp", "4"}, 3, 1);
  EXPECT_EQ(one.counters.get("rays.primary"), 40u * 30u * 4u);
  EXPECT_EQ(four.counters.get("rays.primary"), 40u * 30u * 4u);
  EXPECT_EQ(four.counters.get("rays.shadow"), one.counters.get("rays.shadow"));
  EXPECT_EQ(four.frameSeconds.size(), 3u);
  EXPECT_GE(four.bvhBuildSeconds, 0.0);
  EXPECT_GT(raysPerSecond(four, "rays.primary"), 0.0);
}

// --peers: the peer runs after each round of ours, on the one prepared
// scene; every round's frames are ours.
TEST(Bench, RoundsCallBackAfterEachRoundWithTheCamera) {
  BenchRequest request;
  request.scenePath = kCornell;
  request.settings = renderSettingsFrom({"--renderer", "raytrace", "--size", "24", "16"});
  request.frames = 2;
  request.warmup = 1;
  request.rounds = 3;
  std::vector<int> rounds;
  request.afterRound = [&](int round, const Camera& camera) {
    rounds.push_back(round);
    EXPECT_EQ(camera.width, 24);
    EXPECT_EQ(camera.height, 16);
  };
  const BenchResult r = runBench(request);
  EXPECT_EQ(rounds, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(r.frameSeconds.size(), 6u);
  EXPECT_EQ(r.frame.count, 6);
}

TEST(Bench, HybridFramesCountTheirOwnShadowRays) {
  const std::vector<std::string> args{"--renderer", "hybrid", "--size", "40", "30", "--shadows", "rays"};
  const BenchResult one = bench(args, 1, 0);
  const BenchResult three = bench(args, 2, 1);
  EXPECT_GT(one.counters.get("rays.shadow"), 0u);
  EXPECT_EQ(three.counters.get("rays.shadow"), one.counters.get("rays.shadow"));
}

TEST(Bench, RasterReportsStagesAndNoBvh) {
  const BenchResult r = bench({"--size", "64", "48"}, 2, 0);
  EXPECT_EQ(r.width, 64);
  EXPECT_EQ(r.height, 48);
  EXPECT_LT(r.bvhBuildSeconds, 0.0);
  EXPECT_EQ(r.triangles, 742u);
  bool tiles = false;
  for (const StageTime& s : r.stages) tiles = tiles || (s.name == "raster.tiles" && s.seconds.count == 2);
  EXPECT_TRUE(tiles);
  // The tile loop's passes split its wall time: in one frame they add up.
  BenchRequest one;
  one.scenePath = kCornell;
  one.settings = renderSettingsFrom({"--size", "64", "48", "--threads", "2"});
  one.frames = 1;
  one.warmup = 0;
  const BenchResult single = runBench(one);
  double whole = -1.0, parts = 0.0;
  int partCount = 0;
  for (const StageTime& s : single.stages) {
    if (s.name == "raster.tiles") whole = s.seconds.median;
    if (s.name.rfind("raster.tiles.", 0) == 0) {
      parts += s.seconds.median;
      ++partCount;
    }
  }
  EXPECT_EQ(partCount, 3);  // depth, shade, resolve (no BLEND material)
  EXPECT_NEAR(parts, whole, 1e-9 * std::max(1.0, whole));
  EXPECT_LE(r.frame.min, r.frame.median);
  EXPECT_LE(r.frame.median, r.frame.max);

  const nlohmann::json j = benchJson(r);
  EXPECT_EQ(j.at("schema"), "rastray.bench");
  EXPECT_EQ(j.at("version"), 1);
  EXPECT_EQ(j.at("frameSeconds").size(), 2u);
  EXPECT_TRUE(j.at("bvhBuildSeconds").is_null());
  EXPECT_EQ(j.at("counters").at("raster.triangles_in"), 742);
  EXPECT_TRUE(j.at("stages").contains("raster.tiles"));
}

TEST(Bench, CsvRowMatchesItsHeader) {
  BenchResult r = bench({"--renderer", "raytrace", "--size", "16", "12"}, 1, 0);
  const auto fields = [](const std::string& line) {
    std::istringstream in(line);
    std::vector<std::string> record;
    readCsvRecord(in, record);
    return record.size();
  };
  EXPECT_EQ(fields(benchCsvRow(r)), fields(benchCsvHeader()));
  EXPECT_NE(benchCsvRow(r).find(",raytrace,16,12,1,"), std::string::npos) << benchCsvRow(r);
  r.scenePath = "a,b.gltf";  // a comma in a path must not add a field
  r.bvhBuildSeconds = -1.0;  // nor an absent BVH remove one
  EXPECT_EQ(fields(benchCsvRow(r)), fields(benchCsvHeader()));
  std::istringstream row(benchCsvRow(r));
  std::vector<std::string> record;
  ASSERT_TRUE(readCsvRecord(row, record));
  EXPECT_EQ(record.front(), "a,b.gltf");  // quoted, read back whole
}

TEST(BenchCommand, LastLineIsTheMedianFrame) {
  const test::CommandResult r =
      test::runRastray({"bench", kCornell, "--size", "64", "48", "--frames", "3", "--renderer", "hybrid"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(std::regex_search(r.out, std::regex("median frame: [0-9]+\\.[0-9]{3} ms\n$"))) << r.out;
  EXPECT_NE(r.out.find("BVH build"), std::string::npos);
}

TEST(BenchCommand, GeneratedTerrainHasTheTrianglesAsked) {
  const std::string dir = test::scratchPath("bench-terrain");
  const test::CommandResult r = test::runRastray(
      {"bench", "terrain:2000", "--size", "80", "60", "--frames", "1", "--warmup", "0", "--work-dir", dir});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("2000 triangles"), std::string::npos) << r.out;
}

// The peers run in alternation with ours and their ratio is printed above
// our median (a peer that is not built or installed is skipped with a
// message; CI builds and installs both).
TEST(BenchCommand, PeersPrintRatiosAndCsvRows) {
  const std::string dir = test::scratchPath("bench-peers");
  const std::string csv = dir + "/peers.csv";
  std::filesystem::remove_all(dir);
  for (const char* renderer : {"raster", "raytrace"}) {
    const test::CommandResult r =
        test::runRastray({"bench", kCornell, "--renderer", renderer, "--size", "48", "32", "--frames", "2",
                          "--peers", "--rounds", "2", "--work-dir", dir, "--peers-csv", csv});
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("ratio = peer / rastray"), std::string::npos) << r.out;
    EXPECT_TRUE(std::regex_search(r.out, std::regex("median frame: [0-9]+\\.[0-9]{3} ms\n$"))) << r.out;
    const bool skipped = r.out.find("skipped:") != std::string::npos;
    const char* peer = std::string(renderer) == "raster" ? "\nllvmpipe " : "\nembree viewer ";
    if (!skipped) {
      EXPECT_NE(r.out.find(peer), std::string::npos) << r.out;
    }
  }
  std::ifstream f(csv);
  std::string header, row;
  std::getline(f, header);
  EXPECT_EQ(header.rfind("scene,renderer,", 0), 0u);
  int rows = 0;
  while (std::getline(f, row)) {
    ++rows;
    EXPECT_EQ(std::count(row.begin(), row.end(), ','), std::count(header.begin(), header.end(), ',')) << row;
  }
  EXPECT_LE(rows, 2);
}

TEST(BenchCommand, BadInputExitsTwoWithOneLine) {
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"bench", "terrain:0", "--size", "8", "8"},
        std::vector<std::string>{"bench", "terrain:abc"},
        std::vector<std::string>{"bench", kCornell, "--frames", "0"},
        std::vector<std::string>{"bench", kCornell, "--peers-csv", "x.csv"},  // needs --peers
        std::vector<std::string>{"bench", "/nonexistent/scene.gltf"}}) {
    const test::CommandResult r = test::runRastray(args);
    EXPECT_EQ(r.status, 2) << args[1];
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
}

}  // namespace
}  // namespace rastray
