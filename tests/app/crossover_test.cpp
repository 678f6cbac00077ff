// The crossover study (rastray sweep --crossover): the generated meshes have
// exactly the triangle count asked for, are deterministic and fill the view;
// a tiny study writes the CSV and JSON with their schema and valid SVG
// plots; peak memory, measured per child process, grows with the triangle
// count; a cell that cannot run is recorded, not fatal.
#ifdef RASTRAY_HAVE_RENDERERS

#include "app/studies/sweep_crossover.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "app/bench/terrain_scene.h"
#include "app/engine/render_setup.h"
#include "common/error.h"
#include "common/interrupt.h"
#include "common/scene.h"
#include "run_command.h"
#include "tests/test_files.h"
#include "tests/test_labels.h"
#include "xml_check.h"

namespace rastray::crossover {
namespace {

namespace fs = std::filesystem;

using test::slurp;

TEST(Crossover, MeshesHaveExactlyTheTrianglesAskedFor) {
  for (const uint64_t t :
       {1ull, 2ull, 3ull, 99ull, 100ull, 101ull, 1000ull, 4097ull, 12345ull, 999983ull, 1'000'000ull}) {
    const GltfScene s = crossoverScene(t, true, 4.0 / 3.0);
    ASSERT_EQ(s.meshes.size(), 1u);
    const GltfMesh& m = s.meshes[0];
    EXPECT_EQ(m.indices.size(), 3 * t) << t;
    EXPECT_EQ(m.normals.size(), m.positions.size());
    uint32_t largest = 0;
    for (const uint32_t i : m.indices) largest = std::max(largest, i);
    EXPECT_LT(largest, m.positions.size()) << t;
  }
  // Powers of ten are full rectangles of quads, close to square ones.
  for (uint64_t t = 100; t <= 10'000'000; t *= 10) {
    const GridShape g = gridShape(t, 1.5);
    EXPECT_EQ(g.triangles(), t);
    EXPECT_EQ(g.partialQuads, 0u) << t;
    EXPECT_FALSE(g.extraTriangle);
    const double aspect = double(g.columns) / double(g.rows);
    EXPECT_GT(aspect, 0.75) << t;
    EXPECT_LT(aspect, 3.0) << t;
  }
  EXPECT_THROW(crossoverScene(0, true, 1.5), std::invalid_argument);
}

TEST(Crossover, MeshesAreDeterministicAndBothVariantsShareThem) {
  const fs::path dir = test::scratchDir();
  crossoverScene(20'000, true, 16.0 / 9.0).writeGlb((dir / "a.glb").string());
  crossoverScene(20'000, true, 16.0 / 9.0).writeGlb((dir / "b.glb").string());
  const std::string a = slurp(dir / "a.glb");
  EXPECT_GT(a.size(), 20'000u * 12);  // indices alone take 12 bytes a triangle
  EXPECT_EQ(a, slurp(dir / "b.glb"));

  const GltfScene lit = crossoverScene(20'000, true, 16.0 / 9.0),
                  unlit = crossoverScene(20'000, false, 16.0 / 9.0);
  EXPECT_EQ(lit.meshes[0].positions, unlit.meshes[0].positions);
  EXPECT_EQ(lit.meshes[0].indices, unlit.meshes[0].indices);
  EXPECT_EQ(lit.lights.size(), 1u);
  EXPECT_TRUE(unlit.lights.empty());
  EXPECT_NE(unlit.materials[0].emissive, glm::vec3(0.0f));
  // The loader reads exactly that many triangles back from the .glb.
  EXPECT_EQ(loadScene((dir / "a.glb").string()).triangles.size(), 20'000u);
}

// Every pixel sees the surface, at 16:9 and 4:3, at a coarse and a fine
// tessellation, and nearly every triangle is in view (the margin ring and
// the row beyond it are not): the study measures full frames of triangles
// that all cost work, not background.
TEST(Crossover, TheSurfaceFillsTheViewWithItsTriangles) {
  const fs::path dir = test::scratchDir();
  for (const uint64_t t : {100ull, 1001ull, 50'000ull})
    for (const ImageSize size : {ImageSize{64, 36}, ImageSize{48, 36}}) {
      const std::string path =
          (dir / ("s" + std::to_string(t) + "-" + std::to_string(size.width) + ".glb")).string();
      crossoverScene(t, false, double(size.width) / double(size.height)).writeGlb(path);
      for (const char* renderer : {"raster", "raytrace"}) {
        RenderSettings settings;
        settings.renderer = *parseRendererKind(renderer);
        settings.camera.size = {size.width, size.height};
        settings.finish();
        const Scene scene = loadSceneForRender(path, settings);
        const RenderRun run = renderScene(scene, settings);
        int empty = 0;
        for (const uint32_t id : run.output.image.instance) empty += id == kNoId;
        EXPECT_EQ(empty, 0) << t << " triangles, " << renderer << " " << size.width << "x" << size.height;
        if (std::string(renderer) == "raster" && t >= 1000) {
          const uint64_t outside = run.output.counters.get("raster.outside");
          EXPECT_LT(double(outside), 0.15 * double(t))
              << t << " triangles, " << size.width << "x" << size.height;
        }
      }
    }
}

CrossoverOptions tinyStudy(const std::string& dir) {
  CrossoverOptions o;
  o.reportDir = dir;
  o.triangles = {100, 200'000};
  o.sizes = {{80, 60}, {160, 90}};
  o.maxRuns = 1;
  o.rastray = RASTRAY_BINARY;
  o.threads = 1;
  o.progress = false;
  return o;
}

RASTRAY_TEST_LABELS_OF(Crossover, TinyStudyWritesCsvJsonAndPlots, "slow");
TEST(Crossover, TinyStudyWritesCsvJsonAndPlots) {
  const fs::path dir = test::scratchDir();
  const CrossoverOptions options = tinyStudy(dir.string());
  StudyMeta meta;
  const std::vector<CellResult> rows = measureCells(options, meta, {});
  writeCrossoverReport(options.reportDir, meta, rows);
  ASSERT_EQ(rows.size(), 2u * 2u * 2u);
  for (const CellResult& r : rows) {
    EXPECT_EQ(r.status, "ok") << r.detail;
    EXPECT_GT(r.visibilitySeconds, 0);
    EXPECT_GT(r.shadedSeconds, 0);
    EXPECT_GE(r.runs, 1);
    EXPECT_GT(r.processSeconds, r.shadedSeconds);  // the process also loads and writes
    EXPECT_EQ(std::isfinite(r.bvhBuildSeconds), r.renderer == "raytrace");
    EXPECT_GT(r.visibilityPeakRssBytes, 1u << 20);
    EXPECT_GT(r.shadedPeakRssBytes, 1u << 20);
  }

  // CSV: the documented header, one line per row, as many fields as columns.
  const std::string csv = slurp(dir / "crossover.csv");
  std::istringstream lines(csv);
  std::string header, line;
  std::getline(lines, header);
  EXPECT_EQ(header,
            "triangles,width,height,pixels,renderer,status,runs,visibility_s,shaded_s,bvh_build_s,process_s,"
            "visibility_peak_rss_bytes,shaded_peak_rss_bytes,detail");
  int count = 0;
  while (std::getline(lines, line)) {
    ++count;
    EXPECT_EQ(std::count(line.begin(), line.end(), ','), 13) << line;
  }
  EXPECT_EQ(count, 8);

  // JSON: schema, version, machine, one row per cell and a winner per cell.
  const nlohmann::json j = nlohmann::json::parse(slurp(dir / "crossover.json"));
  EXPECT_EQ(j.at("schema"), "rastray.crossover");
  EXPECT_EQ(j.at("version"), 1);
  EXPECT_EQ(j.at("threads"), 1);
  EXPECT_GT(j.at("machine").at("memoryBytes").get<uint64_t>(), 0u);
  EXPECT_TRUE(j.at("machine").at("loadAverage").at("start").is_number());
  ASSERT_EQ(j.at("rows").size(), 8u);
  EXPECT_EQ(j.at("rows")[0].at("seconds").size(), 4u);
  ASSERT_EQ(j.at("winners").size(), 4u);
  for (const auto& w : j.at("winners")) {
    const std::string faster = w.at("shaded").at("faster");
    EXPECT_TRUE(faster == "raster" || faster == "raytrace");
    EXPECT_GE(w.at("shaded").at("ratio").get<double>(), 1.0);
  }

  // The JSON reads back to the same rows and files.
  StudyMeta readMeta;
  std::vector<CellResult> readRows;
  readJson((dir / "crossover.json").string(), readMeta, readRows);
  EXPECT_EQ(toCsv(readRows), toCsv(rows));
  EXPECT_EQ(toJson(readMeta, readRows), toJson(meta, rows));
  {
    std::ofstream bad(dir / "other.json");
    bad << R"({"schema": "rastray.sweep", "version": 1})";
  }
  EXPECT_THROW(readJson((dir / "other.json").string(), readMeta, readRows), InputError);

  // Plots: valid XML, labelled axes, every cell placed (the winner maps).
  for (const char* file :
       {"crossover-shaded.svg", "crossover-visibility.svg", "crossover-time.svg", "crossover-memory.svg"}) {
    std::string error;
    const std::vector<test::Element> elements = test::parseXml(slurp(dir / file), &error);
    EXPECT_TRUE(error.empty()) << file << ": " << error;
    std::string xTitle, yTitle;
    for (const test::Element& e : elements) {
      const auto c = e.attributes.find("class");
      if (c != e.attributes.end() && c->second == "x-title") xTitle = e.text;
      if (c != e.attributes.end() && c->second == "y-title") yTitle = e.text;
    }
    EXPECT_EQ(xTitle, "triangles") << file;
    EXPECT_FALSE(yTitle.empty()) << file;
  }
  const std::vector<NamedPlot> plots = crossoverPlots(meta, rows);
  const PlotRender shaded = renderPlot(plots[0].plot);
  EXPECT_EQ(shaded.drawn, 4u);
  EXPECT_EQ(shaded.skipped, 0u);
  EXPECT_NE(slurp(dir / "index.html").find("<svg"), std::string::npos);

  // Peak memory grows with the triangle count, for each renderer and size.
  // The floor is what 200,000 triangles must hold at the least: 2.4 MB of
  // indices and 1.2 MB of positions, with the glTF buffer they were read
  // from. The raster visibility cell grows by only about 8 MB in all (no
  // BVH, no shading data), so a margin of 8 MiB failed on some machines.
  constexpr uint64_t kLeastGrowth = 4u << 20;
  for (const CellResult& small : rows)
    for (const CellResult& large : rows)
      if (small.triangles == 100 && large.triangles == 200'000 && small.renderer == large.renderer &&
          small.width == large.width) {
        EXPECT_GT(large.visibilityPeakRssBytes, small.visibilityPeakRssBytes + kLeastGrowth)
            << small.renderer << " " << small.width << "x" << small.height;
        EXPECT_GT(large.shadedPeakRssBytes, small.shadedPeakRssBytes + kLeastGrowth)
            << small.renderer << " " << small.width << "x" << small.height;
      }
}

// A cell that cannot run is recorded with its reason, and the cells of that
// renderer at least as large are skipped; the study goes on.
TEST(Crossover, CellsThatCannotRunAreRecorded) {
#if defined(__SANITIZE_ADDRESS__)
  // AddressSanitizer reserves terabytes of shadow address space at start-up,
  // so a child under a 64 MiB RLIMIT_AS dies by SIGSEGV before main() and
  // cannot say it ran out of memory; the plain build runs this test.
  GTEST_SKIP() << "RLIMIT_AS cannot simulate running out of memory under AddressSanitizer";
#endif
  const fs::path dir = test::scratchDir();
  CrossoverOptions options = tinyStudy(dir.string());
  // Too little for the dynamic loader to map rastray's libraries: every cell
  // that runs fails for memory.
  options.childMemoryLimitBytes = 64ull << 20;
  StudyMeta meta;
  const std::vector<CellResult> rows = measureCells(options, meta, {});
  ASSERT_EQ(rows.size(), 8u);
  int notOk = 0, skipped = 0;
  for (const CellResult& r : rows) {
    if (r.status == "skipped") ++skipped;
    if (!r.ok()) {
      ++notOk;
      EXPECT_FALSE(r.detail.empty());
      EXPECT_TRUE(std::isnan(r.shadedSeconds));
    }
  }
  EXPECT_EQ(notOk, 8);
  EXPECT_EQ(skipped, 6);  // each renderer's first cell failed: every larger one is skipped
  for (const CellResult& r : rows) {
    if (r.status != "skipped") {
      EXPECT_EQ(r.status, "out of memory") << r.detail;
    }
  }
  writeCrossoverReport(options.reportDir, meta, rows);
  EXPECT_NE(slurp(dir / "crossover.csv").find("skipped"), std::string::npos);
  // The winner map still places every cell, as "neither renderer ran".
  const PlotRender map = renderPlot(crossoverPlots(meta, rows)[0].plot);
  EXPECT_EQ(map.drawn, 4u);
  EXPECT_EQ(map.skipped, 0u);

  options.rastray = "/nonexistent/rastray";
  options.childMemoryLimitBytes = 0;
  const std::vector<CellResult> none = measureCells(options, meta, {});
  int failed = 0;
  for (const CellResult& r : none) {
    if (r.status == "failed") {
      ++failed;
      EXPECT_NE(r.detail.find("could not run /nonexistent/rastray"), std::string::npos) << r.detail;
    }
  }
  EXPECT_EQ(failed, 8);  // a failure that is not for memory or time skips nothing
}

// The command: --crossover takes its own scenes and no render option but
// --threads; --quick belongs to it (exit 2 with one line otherwise).
TEST(Crossover, CommandRefusesWhatDoesNotApply) {
  const std::string scene = std::string(RASTRAY_SCENES) + "/three-triangles.gltf";
  const std::vector<std::vector<std::string>> refused = {
      {"sweep", "--crossover", scene},
      {"sweep", "--crossover", "--vary", "spp=1,4"},
      {"sweep", "--crossover", "--spp", "4"},
      {"sweep", "--crossover", "--renderer", "raster"},
      {"sweep", "--crossover", "--repeat", "5"},
      {"sweep", "--quick", scene, "--vary", "spp=1,4", "--report", "x"},
  };
  for (const auto& args : refused) {
    const test::CommandResult r = test::runRastray(args);
    EXPECT_EQ(r.status, 2) << args.back();
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
}

// Ctrl-C or SIGTERM during the study (issue 13): the child rendering the
// cell in progress is stopped, the generated meshes are removed, the cells
// finished so far stay in crossover.csv and crossover.json (written after
// each), the account names the cell not finished; --resume keeps those
// cells as measured and runs the rest.
RASTRAY_TEST_LABELS_OF(Crossover, InterruptedStudyKeepsFinishedCellsAndResumes, "slow");
TEST(Crossover, InterruptedStudyKeepsFinishedCellsAndResumes) {
  const fs::path dir = test::scratchDir();
  const fs::path temp = dir / "temp";  // where the study's scratch folder goes
  fs::create_directories(temp);
  const char* oldTmp = std::getenv("TMPDIR");
  const std::string savedTmp = oldTmp ? oldTmp : "";
  ::setenv("TMPDIR", temp.c_str(), 1);
  CrossoverOptions options = tinyStudy((dir / "report").string());
  const fs::path json = dir / "report" / "crossover.json";
  auto rowsIn = [&](const fs::path& file) {
    std::error_code ec;
    if (!fs::exists(file, ec)) return size_t(0);
    return nlohmann::json::parse(slurp(file)).at("rows").size();
  };
  // The stop arrives once the first cell is on disk, while the second runs.
  std::atomic<bool> done{false};
  std::thread stopper([&] {
    while (!done && rowsIn(json) < 1) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    if (!done) setInterruptForTesting(SIGTERM);
  });
  std::string account;
  try {
    runCrossover(options);
  } catch (const Interrupted& e) {
    account = e.finished();
  }
  done = true;
  stopper.join();
  setInterruptForTesting(0);
  ASSERT_FALSE(account.empty()) << "the study finished before the stop arrived";
  const size_t finished = rowsIn(json);
  EXPECT_GE(finished, 1u);
  EXPECT_NE(account.find(std::to_string(finished) + " of 8 cells finished (in " + json.string() +
                         "; --resume runs the rest); the cell of "),
            std::string::npos)
      << account;
  EXPECT_NE(account.find(") not finished"), std::string::npos) << account;
  EXPECT_TRUE(fs::is_empty(temp)) << "generated meshes left in " << temp;
  EXPECT_FALSE(fs::exists(dir / "report" / "index.html"));  // the full report is written at the end
  const std::string csvBefore = slurp(dir / "report" / "crossover.csv");

  options.resume = true;
  options.progress = false;
  EXPECT_EQ(runCrossover(options), 0);
  if (oldTmp)
    ::setenv("TMPDIR", savedTmp.c_str(), 1);
  else
    ::unsetenv("TMPDIR");
  EXPECT_EQ(rowsIn(json), 8u);
  // The finished cells are kept as they were measured: the earlier CSV is
  // the start of the new one.
  const std::string csvAfter = slurp(dir / "report" / "crossover.csv");
  EXPECT_EQ(csvAfter.compare(0, csvBefore.size(), csvBefore), 0) << csvBefore << "\n---\n" << csvAfter;
  EXPECT_TRUE(fs::exists(dir / "report" / "index.html"));
  EXPECT_TRUE(fs::is_empty(temp));

  // Another study in the same folder is refused.
  options.triangles = {100};
  EXPECT_THROW(runCrossover(options), InputError);
}

}  // namespace
}  // namespace rastray::crossover

#endif  // RASTRAY_HAVE_RENDERERS
