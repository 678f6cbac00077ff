// Issue 13, interrupted work: Ctrl-C or SIGTERM during render, crossval or
// sweep leaves the finished outputs whole and no temporary file, says what
// was finished, exits with 128 + the signal (common/interrupt.h); crossval
// and sweep resume with --resume without redoing finished work.
//
// The signals are real, sent by the test once it sees the run's progress on
// the file system (run_command.h): when the command has installed its
// handlers, or when the first scene's or cell's record appears. The work
// left after that point takes seconds, the test polls every 5 ms.
#include <signal.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app/crossval/crossval.h"
#include "app/crossval/crossval_record.h"
#include "app/crossval/crossval_report.h"
#include "app/studies/stability_measure.h"
#include "cli/exit_status.h"
#include "common/image.h"
#include "common/interrupt.h"
#include "tests/app/run_command.h"
#include "tests/test_files.h"
#include "tests/test_labels.h"

namespace rastray {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string scene(const char* name) { return std::string(RASTRAY_SCENES) + "/" + name + ".gltf"; }

using test::slurp;

// Every file below `dir` whose name has the atomic writers' ".tmp." in it
// (common/image.cpp temporaryPathFor).
std::vector<std::string> temporaryFiles(const fs::path& dir) {
  std::vector<std::string> found;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.path().filename().string().find(".tmp.") != std::string::npos) found.push_back(e.path().string());
  return found;
}

struct FileStamp {
  ino_t inode = 0;
  int64_t mtime = 0;
  bool operator==(const FileStamp& o) const { return inode == o.inode && mtime == o.mtime; }
};
FileStamp stampOf(const fs::path& p) {
  struct stat st {};
  if (::stat(p.c_str(), &st) != 0) return {};
  return {st.st_ino, int64_t(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec};
}

class Interrupt : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::scratchPath("out");
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { setInterruptForTesting(0); }
  std::string dir_;
};

// The status chosen once (common/interrupt.h): the shell's 128 + signal.
TEST_F(Interrupt, ExitStatusIsTheShellsAndCollidesWithNoOther) {
  EXPECT_EQ(interruptedExitStatus(SIGINT), 130);
  EXPECT_EQ(interruptedExitStatus(SIGTERM), 143);
}

// The handler only records: the process lives on, the request is visible,
// and the next signal has its default action again (a second Ctrl-C quits).
TEST_F(Interrupt, HandlerRecordsTheSignalAndRestoresTheDefault) {
  installInterruptHandlers();
  struct sigaction now {};
  sigaction(SIGTERM, nullptr, &now);
  EXPECT_NE(now.sa_handler, SIG_DFL);
  ASSERT_FALSE(interruptRequested());
  ASSERT_EQ(raise(SIGTERM), 0);
  EXPECT_TRUE(interruptRequested());
  EXPECT_EQ(interruptSignal(), SIGTERM);
  EXPECT_THROW(throwIfInterrupted(), Interrupted);
  sigaction(SIGINT, nullptr, &now);
  EXPECT_EQ(now.sa_handler, SIG_DFL);
  sigaction(SIGTERM, nullptr, &now);
  EXPECT_EQ(now.sa_handler, SIG_DFL);
}

// A write does not poll: with a stop requested (a signal that arrived while
// it ran), it still completes and renames its temporary file into place.
TEST_F(Interrupt, WritesCompleteAndLeaveNoTemporaryFile) {
  setInterruptForTesting(SIGINT);
  const std::string text(4 << 20, 'x');
  writeTextFile(dir_ + "/big.txt", text);
  writeImage(dir_ + "/a.exr", FlatImage(64, 48), ColorPrecision::Half);
  EXPECT_EQ(fs::file_size(dir_ + "/big.txt"), text.size());
  EXPECT_TRUE(fs::exists(dir_ + "/a.exr"));
  EXPECT_TRUE(temporaryFiles(dir_).empty());
}

// Each renderer stops at its tiles and throws; with the request cleared
// the same settings render normally.
TEST_F(Interrupt, EveryRendererThrowsFromItsTileLoop) {
  for (const char* renderer : {"raster", "raytrace", "hybrid"}) {
    const RenderSettings settings =
        renderSettingsFrom({"--renderer", renderer, "--size", "64", "48", "--spp", "2"});
    const Scene s = loadSceneForRender(scene("cornell-box"), settings);
    setInterruptForTesting(SIGINT);
    try {
      renderScene(s, settings);
      ADD_FAILURE() << renderer << " did not stop";
    } catch (const Interrupted& e) {
      EXPECT_EQ(e.signal(), SIGINT) << renderer;
    }
    setInterruptForTesting(0);
    EXPECT_EQ(renderScene(s, settings).output.image.width, 64) << renderer;
  }
}

TEST_F(Interrupt, RenderWritesNothing) {
  for (const auto& [signal, renderer] :
       {std::pair<int, const char*>{SIGINT, "raster"}, {SIGTERM, "raytrace"}}) {
    const std::string out = dir_ + "/out-" + renderer + ".exr";
    bool sent = false;
    // 1920x1080 at 16 spp takes seconds; the signal goes as soon as the
    // handlers are in, before the scene is loaded.
    const test::CommandResult r =
        test::runRastrayAndSignal({"render", scene("cornell-box"), "--renderer", renderer, "--size", "1920",
                                   "1080", "--spp", "16", "-o", out},
                                  signal, test::catchesStopSignals, &sent);
    ASSERT_TRUE(sent) << r.err;
    EXPECT_EQ(r.status, interruptedExitStatus(signal)) << r.err;
    EXPECT_NE(r.err.find("interrupted by " + std::string(signal == SIGINT ? "SIGINT" : "SIGTERM") +
                         ": nothing written"),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(out));
  }
  EXPECT_TRUE(fs::is_empty(dir_)) << "temporary files: " << temporaryFiles(dir_).size();
}

// Three scenes; the signal comes once the first scene's record exists
// (three triangles, quick), while the Cornell box renders.
TEST_F(Interrupt, CrossvalKeepsFinishedScenesAndResumes) {
  const std::string report = dir_ + "/report";
  const std::vector<std::string> args = {"crossval",
                                         scene("three-triangles"),
                                         scene("cornell-box"),
                                         scene("textured-plane"),
                                         "--size",
                                         "320",
                                         "240",
                                         "--spp",
                                         "4",
                                         "--report",
                                         report};
  const fs::path firstRecord = crossvalScenePath(report, scene("three-triangles"));
  bool sent = false;
  const test::CommandResult stopped = test::runRastrayAndSignal(
      args, SIGINT, [&](pid_t) { return fs::exists(firstRecord); }, &sent);
  ASSERT_TRUE(sent) << stopped.err;
  ASSERT_EQ(stopped.status, 130) << stopped.err;
  EXPECT_NE(stopped.err.find("1 of 3 scenes finished (reports in " + report + "/three-triangles"),
            std::string::npos)
      << stopped.err;
  EXPECT_NE(stopped.err.find(scene("cornell-box") + ", " + scene("textured-plane") + " not finished"),
            std::string::npos)
      << stopped.err;
  EXPECT_TRUE(stopped.out.empty()) << stopped.out;
  EXPECT_TRUE(temporaryFiles(report).empty());
  // The finished scene's folder is whole; nothing of the others, no index.
  for (const char* file : {"index.html", "raster.png", "mismatch.png", "color-diff-hybrid.png"})
    EXPECT_TRUE(fs::exists(fs::path(report) / "three-triangles" / file)) << file;
  EXPECT_FALSE(fs::exists(fs::path(report) / "cornell-box" / "crossval-scene.json"));
  EXPECT_FALSE(fs::exists(fs::path(report) / "index.html"));
  const json record = json::parse(slurp(firstRecord));
  EXPECT_EQ(record.value("schema", ""), kCrossvalSceneSchema);
  EXPECT_EQ(record.value("version", 0), 1);
  EXPECT_EQ(json::parse(slurp(crossvalRunPath(report))).value("schema", ""), kCrossvalRunSchema);

  // Other render options: refused before anything is written.
  std::vector<std::string> other = args;
  other[other.size() - 3] = "2";  // --spp 2
  other.push_back("--resume");
  const test::CommandResult refused = test::runRastray(other);
  EXPECT_EQ(refused.status, 2);
  EXPECT_NE(
      refused.err.find("crossval-run.json: options: the folder holds a crossval made with --size 320 240 "
                       "--spp 4, this one has --size 320 240 --spp 2"),
      std::string::npos)
      << refused.err;
  EXPECT_EQ(test::runRastray({"crossval", scene("three-triangles"), "--resume"}).status, 2);

  // The resume runs the two others only; the first scene's files stay
  // untouched and its numbers (its timings too) come from its record.
  const FileStamp recordBefore = stampOf(firstRecord),
                  pageBefore = stampOf(fs::path(report) / "three-triangles" / "index.html");
  std::vector<std::string> resume = args;
  resume.push_back("--resume");
  resume.push_back("--json");
  const test::CommandResult resumed = test::runRastray(resume);
  ASSERT_EQ(resumed.status, 0) << resumed.err;
  EXPECT_NE(resumed.err.find("resume: 1 of 3 scenes already done in " + report + ", 2 to run"),
            std::string::npos)
      << resumed.err;
  EXPECT_TRUE(stampOf(firstRecord) == recordBefore);
  EXPECT_TRUE(stampOf(fs::path(report) / "three-triangles" / "index.html") == pageBefore);
  const json all = json::parse(resumed.out);
  ASSERT_EQ(all.at("scenes").size(), 3u);
  EXPECT_EQ(all["scenes"][0], record.at("result"));
  EXPECT_EQ(all["scenes"][1].value("scene", ""), scene("cornell-box"));
  EXPECT_EQ(all["scenes"][2].value("scene", ""), scene("textured-plane"));
  const std::string index = slurp(fs::path(report) / "index.html");
  for (const char* name : {"three-triangles", "cornell-box", "textured-plane"})
    EXPECT_NE(index.find(std::string("href=\"") + name + "/index.html\""), std::string::npos) << name;
  EXPECT_TRUE(temporaryFiles(report).empty());
}

// What a resumed run prints and indexes comes from the records: a summary
// read back gives the same JSON and the same index page as the original.
TEST_F(Interrupt, CrossvalSummaryReadBackGivesTheSameIndex) {
  const RenderSettings settings =
      renderSettingsFrom({"--size", "48", "36", "--spp", "2"}, /*allRenderers=*/true);
  std::vector<CrossvalSummary> original;
  for (const char* name : {"three-triangles", "textured-plane"})
    original.push_back(
        summarize(crossvalidate(loadSceneForRender(scene(name), settings), settings, nullptr), settings.spp));
  std::vector<CrossvalSummary> readBack;
  for (const CrossvalSummary& s : original) {
    const json j = json::parse(summaryJson(s).dump());
    readBack.push_back(summaryFromJson(j, "record"));
    EXPECT_EQ(summaryJson(readBack.back()), summaryJson(s));
  }
  writeCrossvalIndex(dir_ + "/a", original, settings);
  writeCrossvalIndex(dir_ + "/b", readBack, settings);
  EXPECT_EQ(slurp(dir_ + "/a/index.html"), slurp(dir_ + "/b/index.html"));
  // three-triangles is identical in both renderers: PSNR +inf survives.
  EXPECT_EQ(readBack[0].hybridVsRayColor.psnr, original[0].hybridVsRayColor.psnr);
}

// Two cells: the signal comes once the first is in sweep.csv, while the
// second (64 spp) renders.
RASTRAY_TEST_LABELS_OF(Interrupt, SweepKeepsFinishedCellsAndResumes, "slow");
TEST_F(Interrupt, SweepKeepsFinishedCellsAndResumes) {
  const std::string ref = dir_ + "/ref.exr", report = dir_ + "/sweep";
  ASSERT_EQ(test::runRastray({"render", scene("cornell-box"), "--renderer", "raytrace", "--size", "160",
                              "120", "--spp", "4", "-o", ref})
                .status,
            0);
  const std::vector<std::string> args = {
      "sweep", scene("cornell-box"), "--vary", "spp=1,64", "--size", "160", "120", "--repeat",
      "2",     "--reference",        ref,      "--report", report};
  const fs::path csv = fs::path(report) / "sweep.csv";
  auto rows = [&]() {
    std::ifstream in(csv);
    std::string line;
    std::vector<std::string> lines;
    while (std::getline(in, line)) lines.push_back(line);
    return lines;
  };
  bool sent = false;
  const test::CommandResult stopped = test::runRastrayAndSignal(
      args, SIGTERM, [&](pid_t) { return rows().size() >= 2; }, &sent);
  ASSERT_TRUE(sent) << stopped.err;
  ASSERT_EQ(stopped.status, 143) << stopped.err;
  EXPECT_NE(stopped.err.find("interrupted by SIGTERM: 1 of 2 cells finished (in " + csv.string()),
            std::string::npos)
      << stopped.err;
  EXPECT_NE(stopped.err.find("cell 1 (cornell-box.gltf, spp 64) not finished"), std::string::npos)
      << stopped.err;
  const std::vector<std::string> before = rows();
  ASSERT_EQ(before.size(), 2u);  // header and cell 0
  EXPECT_TRUE(temporaryFiles(report).empty());

  const test::CommandResult resumed = test::runRastray([&] {
    std::vector<std::string> a = args;
    a.push_back("--resume");
    return a;
  }());
  ASSERT_EQ(resumed.status, 0) << resumed.err;
  EXPECT_NE(resumed.err.find("resume: 1 cells already in"), std::string::npos) << resumed.err;
  const std::vector<std::string> after = rows();
  ASSERT_EQ(after.size(), 3u);
  EXPECT_EQ(after[1], before[1]);  // cell 0 kept as measured, not run again
  EXPECT_TRUE(temporaryFiles(report).empty());
}

}  // namespace
}  // namespace rastray
