// `rastray sweep` (app/studies/sweep.h): cells planned as `rastray render` parses
// options, the CSV and JSON schemas and their exact round trip, the `auto`
// reference (deterministic, error 0 for its own settings), depth formats on
// a z-fighting scene, shards merging to the full table, --resume, the plots
// as well-formed SVG with labelled axes, and bad --vary refused (exit 2).
// Sizes are tiny: these test the bookkeeping and the metrics, not speed.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app/studies/sweep.h"
#include "app/studies/sweep_report.h"
#include "app/studies/sweep_table.h"
#include "common/error.h"
#include "common/gltf/writer.h"
#include "run_command.h"
#include "tests/test_files.h"
#include "xml_check.h"

namespace rastray::sweep {
namespace {

const std::string kScenes = RASTRAY_SCENES;

using test::slurp;

// A fresh folder under the test's scratch directory (tests/test_files.h:
// removed when the test passes, kept when it fails).
struct TempDir {
  std::filesystem::path path;
  explicit TempDir(const std::string& name) {
    path = test::scratchDir() / name;
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
  }
  std::string operator/(const std::string& name) const { return (path / name).string(); }
};

SweepSpec spec(std::vector<std::string> scenes, std::vector<std::string> vary,
               std::vector<std::string> plain) {
  SweepSpec s;
  s.scenes = std::move(scenes);
  for (const std::string& v : vary) s.vary.push_back(parseVary(v));
  s.plainArgs = std::move(plain);
  s.repeat = 1;
  return s;
}

// The InputError's element when planning `s` fails, "" when it plans.
std::string planError(const SweepSpec& s) {
  try {
    planCells(s);
  } catch (const InputError& e) {
    return e.element();
  }
  return "";
}

TEST(SweepPlan, CellsAreEveryCombinationLastOptionFastest) {
  const std::vector<Cell> cells =
      planCells(spec({kScenes + "/three-triangles.gltf"}, {"spp=1,4", "depth-format=float-reversed,unorm16"},
                     {"--size", "16", "12"}));
  ASSERT_EQ(cells.size(), 4u);
  const std::vector<std::vector<std::string>> values = {
      {"1", "float-reversed"}, {"1", "unorm16"}, {"4", "float-reversed"}, {"4", "unorm16"}};
  for (size_t i = 0; i < cells.size(); ++i) {
    EXPECT_EQ(cells[i].index, i);
    EXPECT_EQ(cells[i].values, values[i]);
    EXPECT_EQ(cells[i].settings.camera.width(), 16);
  }
  EXPECT_EQ(cells[3].settings.spp, 4);
  EXPECT_EQ(cells[3].settings.raster.depthFormat, DepthFormat::Unorm16);
  // The auto reference keeps the picture (size), not the quality settings.
  const std::vector<std::string>& ref = cells[3].referenceArgs;
  EXPECT_NE(std::find(ref.begin(), ref.end(), "--size"), ref.end());
  EXPECT_EQ(std::find(ref.begin(), ref.end(), "--depth-format"), ref.end());
}

TEST(SweepPlan, OptionsThatDoNotApplyCollapseIntoOneCell) {
  // depth-format means nothing to the ray caster: raytrace is one cell, n/a.
  const std::vector<Cell> cells = planCells(spec(
      {kScenes + "/three-triangles.gltf"}, {"renderer=raster,raytrace", "depth-format=float,unorm24"}, {}));
  ASSERT_EQ(cells.size(), 3u);
  EXPECT_EQ(cells[2].values, (std::vector<std::string>{"raytrace", "n/a"}));
  EXPECT_EQ(cells[2].settings.renderer, RendererKind::Raytrace);
  // A plain option goes to the cells it applies to.
  const std::vector<Cell> plain = planCells(
      spec({kScenes + "/three-triangles.gltf"}, {"renderer=raster,raytrace"}, {"--max-depth", "3"}));
  ASSERT_EQ(plain.size(), 2u);
  EXPECT_EQ(std::count(plain[0].args.begin(), plain[0].args.end(), "--max-depth"), 0);
  EXPECT_EQ(plain[1].settings.shading.maxDepth, 3);
  // Several numbers per value, and flags.
  const std::vector<Cell> sizes =
      planCells(spec({kScenes + "/three-triangles.gltf"}, {"size=8x6,16:12", "wireframe=off,on"}, {}));
  ASSERT_EQ(sizes.size(), 4u);
  EXPECT_EQ(sizes[2].settings.camera.height(), 12);
  EXPECT_TRUE(sizes[1].settings.raster.wireframe);
  EXPECT_FALSE(sizes[0].settings.raster.wireframe);
}

TEST(SweepPlan, BadVaryNamesTheOption) {
  const std::string scene = kScenes + "/three-triangles.gltf";
  EXPECT_EQ(planError(spec({scene}, {"colour=1,2"}, {})), "--vary colour");
  EXPECT_EQ(planError(spec({scene}, {"spp=1,3"}, {})), "--vary spp");
  EXPECT_EQ(planError(spec({scene}, {"depth-format=float,unorm12"}, {})), "--vary depth-format");
  EXPECT_EQ(planError(spec({scene}, {"transparency=peel:x"}, {})), "--vary transparency");
  EXPECT_EQ(planError(spec({scene}, {"size=10"}, {})), "--vary size");
  EXPECT_EQ(planError(spec({scene}, {"wireframe=yes"}, {})), "--vary wireframe");
  EXPECT_EQ(planError(spec({scene}, {"spp=1", "spp=4"}, {})), "--vary spp");
  EXPECT_EQ(planError(spec({scene}, {"spp=1,4"}, {"--spp", "4"})), "--vary spp");
  // Applies to no cell: the ray caster has no depth buffer.
  EXPECT_EQ(planError(spec({scene}, {"depth-format=float,unorm16"}, {"--renderer", "raytrace"})),
            "--vary depth-format");
  EXPECT_THROW(parseVary("spp"), InputError);
  EXPECT_THROW(parseVary("spp=1,,4"), InputError);
  EXPECT_THROW(parseShard("2/2"), InputError);
  EXPECT_THROW(parseShard("1-2"), InputError);
  EXPECT_EQ(parseShard("1/3").n, 3);
}

// The auto reference is the cell's own picture: a cell that keeps no light
// or doubles the exposure is scored against a reference that does the same
// (against the default picture: RMS 1.03 to 1.1; the default cell 0.07,
// the reference being 64 spp at depth 16).
TEST(SweepCommand, AutoReferenceKeepsTheCellsLightsAndExposure) {
  const std::string report = test::scratchPath("sweep");
  const auto r = test::runRastray({"sweep", test::scenePath("cornell-box.gltf"), "--vary", "lights=all,none",
                                   "--vary", "exposure=0,1", "--renderer", "raytrace", "--size", "24", "18",
                                   "--spp", "16", "--repeat", "1", "--report", report});
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const nlohmann::json j = nlohmann::json::parse(slurp(report + "/sweep.json"));
  ASSERT_EQ(j.at("rows").size(), 4u) << j.dump();
  for (const nlohmann::json& row : j.at("rows"))
    EXPECT_LT(row.at("errors").at("rms").get<double>(), 0.2)
        << row.dump();  // 1.03 to 1.1 against the default picture
}

TEST(SweepCommand, BadVaryExits2WithOneLineBeforeAnythingRuns) {
  TempDir dir("bad");
  const std::string report = dir / "report";
  for (const std::vector<std::string>& vary :
       {std::vector<std::string>{"--vary", "colour=1,2"}, {"--vary", "spp=3"}, {"--vary", "spp"}}) {
    std::vector<std::string> args = {
        "sweep", kScenes + "/three-triangles.gltf", "--size", "8", "6", "--report", report};
    args.insert(args.end(), vary.begin(), vary.end());
    const test::CommandResult r = test::runRastray(args);
    EXPECT_EQ(r.status, 2) << vary[1] << "\n" << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find("--vary"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(report)) << "the report folder was created before the check";
  }
}

TEST(SweepTable, CsvAndJsonSchemasRoundTripExactly) {
  const SweepSpec s =
      spec({kScenes + "/three-triangles.gltf"}, {"spp=1,4", "renderer=raster,hybrid"}, {"--size", "12", "8"});
  std::vector<Cell> cells = planCells(s);
  ReferenceSource references(s.reference);
  std::vector<CellResult> rows;
  for (const Cell& c : cells) rows.push_back(measureCell(c, 2, references));

  // CSV: the header, then one line per cell with every column filled.
  const std::string csv = toCsv(s.vary, rows);
  const std::string header = csv.substr(0, csv.find('\n'));
  EXPECT_EQ(
      header,
      "cell,scene,spp,renderer,args,width,height,repeat,load_s,load_min_s,load_max_s,build_s,build_min_s,"
      "build_max_s,frame_s,frame_min_s,frame_max_s,time_s,time_min_s,time_max_s,rms_error,max_error,"
      "perceptual_error,visibility_error,visibility_shared_edge,depth_mean_abs,depth_max_abs,depth_mean_rel,"
      "depth_max_rel,"
      "depth_pixels,pixels");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), long(rows.size() + 1));
  TempDir dir("schema");
  writeTextFile(dir / "sweep.csv", csv);
  const std::vector<CellResult> back = readCsv(dir / "sweep.csv", s.vary);
  ASSERT_EQ(back.size(), rows.size());
  EXPECT_EQ(toCsv(s.vary, back), csv);  // 17 digits: bit for bit
  EXPECT_THROW(readCsv(dir / "sweep.csv", {parseVary("spp=1,4")}), InputError);

  for (const CellResult& r : rows) {
    EXPECT_EQ(r.repeat, 2);
    EXPECT_LE(r.time.min, r.time.median);
    EXPECT_LE(r.time.median, r.time.max);
    // The BVH is built by hybrid only (raster has none), reported apart.
    if (r.values[1] == "hybrid")
      EXPECT_GT(r.build.median, 0.0);
    else
      EXPECT_EQ(r.build.max, 0.0);
    EXPECT_NEAR(r.time.median, r.build.median + r.frame.median, 1e-3 + 0.5 * r.time.median);
    EXPECT_EQ(r.errors.pixels, 96u);
  }

  // JSON: schema name and version, the sweep, one row per cell.
  SweepMeta meta;
  meta.spec = s;
  meta.fingerprint = fingerprint(s);
  meta.cells = cells.size();
  meta.shard = "all";
  meta.reference = "auto";
  const nlohmann::json j = toJson(meta, rows);
  EXPECT_EQ(j.at("schema"), "rastray.sweep");
  EXPECT_EQ(j.at("version"), 1);
  EXPECT_EQ(j.at("fingerprint").get<std::string>().size(), 16u);
  EXPECT_EQ(j.at("sweep").at("vary").size(), 2u);
  ASSERT_EQ(j.at("rows").size(), rows.size());
  const nlohmann::json& row = j.at("rows")[3];
  for (const char* key :
       {"cell", "scene", "settings", "args", "width", "height", "repeat", "seconds", "errors"})
    EXPECT_TRUE(row.contains(key)) << key;
  for (const char* key : {"load", "build", "frame", "time"})
    for (const char* stat : {"median", "min", "max"}) EXPECT_TRUE(row.at("seconds").at(key).contains(stat));
  for (const char* key :
       {"rms", "max", "perceptual", "visibility", "visibilitySharedEdge", "depth", "pixels"})
    EXPECT_TRUE(row.at("errors").contains(key)) << key;
  EXPECT_EQ(row.at("settings").at("renderer"), "hybrid");
  writeTextFile(dir / "sweep.json", j.dump(1));
  SweepMeta metaBack;
  std::vector<CellResult> jsonBack;
  readJson(dir / "sweep.json", metaBack, jsonBack);
  EXPECT_EQ(metaBack.fingerprint, meta.fingerprint);
  EXPECT_EQ(toCsv(s.vary, jsonBack), csv);
  writeTextFile(dir / "other.json", R"({"schema": "something.else", "version": 1})");
  EXPECT_THROW(readJson(dir / "other.json", metaBack, jsonBack), InputError);
}

TEST(SweepReference, AutoIsDeterministicAndItsOwnSettingsHaveNoError) {
  // The Cornell box: shadows, a mirror and glass, so every setting of the
  // reference matters.
  std::vector<std::string> own = autoReferenceArgs();
  own.erase(own.begin(), own.begin() + 2);  // "--renderer raytrace" goes in as a vary value
  own.insert(own.end(), {"--size", "24", "18"});
  const SweepSpec s = spec({kScenes + "/cornell-box.gltf"}, {"renderer=raytrace,raster"}, own);
  const std::vector<Cell> cells = planCells(s);
  ASSERT_EQ(cells.size(), 2u);
  ReferenceSource a("auto"), b("auto");
  const Reference& ra = a.referenceFor(cells[0]);
  const Reference& rb = b.referenceFor(cells[0]);
  ASSERT_EQ(ra.color.color.size(), 24u * 18u);
  EXPECT_EQ(0, std::memcmp(ra.color.color.data(), rb.color.color.data(),
                           ra.color.color.size() * sizeof(glm::vec4)));
  EXPECT_EQ(ra.centre.instance, rb.centre.instance);
  EXPECT_EQ(ra.centre.triangle, rb.centre.triangle);
  EXPECT_EQ(
      0, std::memcmp(ra.centre.depth.data(), rb.centre.depth.data(), ra.centre.depth.size() * sizeof(float)));

  const CellResult own_ = measureCell(cells[0], 1, a);
  EXPECT_EQ(own_.errors.rms, 0.0);
  EXPECT_EQ(own_.errors.max, 0.0);
  EXPECT_EQ(own_.errors.perceptual, 0.0);
  EXPECT_EQ(own_.errors.visibility, 0.0);
  EXPECT_EQ(own_.errors.depthMaxAbs, 0.0);
  EXPECT_GT(own_.errors.depthPixels, 0u);
  // The rasterizer (no mirror or glass rays, shadow maps) is measurably off.
  const CellResult raster = measureCell(cells[1], 1, a);
  EXPECT_GT(raster.errors.rms, 1e-3);
  EXPECT_GT(raster.errors.perceptual, 0.0);
}

TEST(SweepReference, AFlatExrWorksAndItsOwnSettingsHaveNoError) {
  TempDir dir("exr");
  const std::string scene = kScenes + "/cornell-box.gltf";
  // Float colour: a half EXR would round the reference's colours.
  const test::CommandResult made = test::runRastray(
      {"render", scene, "--renderer", "raytrace", "--size", "12", "8", "--float", "-o", dir / "ref.exr"});
  ASSERT_EQ(made.status, 0) << made.err;
  const test::CommandResult r =
      test::runRastray({"sweep", scene, "--renderer", "raytrace", "--vary", "spp=1,4", "--size", "12", "8",
                        "--repeat", "1", "--reference", dir / "ref.exr", "--report", dir / "r"});
  ASSERT_EQ(r.status, 0) << r.err;
  SweepMeta meta;
  std::vector<CellResult> rows;
  readJson(dir / "r/sweep.json", meta, rows);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_NE(meta.reference.find("ref.exr"), std::string::npos);
  EXPECT_EQ(rows[0].errors.rms, 0.0);
  EXPECT_EQ(rows[0].errors.visibility, 0.0);
  EXPECT_EQ(rows[0].errors.depthMaxAbs, 0.0);
  EXPECT_GT(rows[1].errors.rms, 0.0);  // 4 spp resolves edges differently
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
  // A half-float reference cannot score 0 at its own settings: the sweep
  // says so, and which file settings would.
  const test::CommandResult half = test::runRastray(
      {"render", scene, "--renderer", "raytrace", "--size", "12", "8", "-o", dir / "half.exr"});
  ASSERT_EQ(half.status, 0) << half.err;
  const test::CommandResult warned =
      test::runRastray({"sweep", scene, "--renderer", "raytrace", "--vary", "spp=1", "--size", "12", "8",
                        "--repeat", "1", "--reference", dir / "half.exr", "--report", dir / "h"});
  ASSERT_EQ(warned.status, 0) << warned.err;
  EXPECT_NE(warned.err.find("rastray sweep: warning: " + (dir / "half.exr") +
                            ": its colour is half-float, so no cell scores 0 against it"),
            std::string::npos)
      << warned.err;
  EXPECT_NE(warned.err.find("--float (and --spp 1"), std::string::npos) << warned.err;
  // A reference of another size is refused before anything runs.
  const test::CommandResult wrong =
      test::runRastray({"sweep", scene, "--renderer", "raytrace", "--vary", "spp=1,4", "--size", "16", "8",
                        "--reference", dir / "ref.exr", "--report", dir / "wrong"});
  EXPECT_EQ(wrong.status, 2);
  EXPECT_NE(wrong.err.find("ref.exr"), std::string::npos) << wrong.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "wrong"));
}

// Two parallel quads 1e-4 apart at distance 10 with the near plane at 1e-3:
// unorm16 (step about d²/n · 2^-16 = 1.5) and unorm24 (6e-3) cannot tell
// them apart, float-reversed (relative step 2^-24: 6e-7) can. The far quad
// is listed first so a depth tie (broken by the lower ID) shows it.
std::string writeZFightingScene(const std::string& path) {
  GltfScene scene;
  scene.materials = {GltfMaterial{}, GltfMaterial{}};
  scene.materials[0].baseColor = {0.1f, 0.9f, 0.1f, 1.0f};
  scene.materials[1].baseColor = {0.9f, 0.1f, 0.1f, 1.0f};
  for (int q = 0; q < 2; ++q) {
    GltfMesh m;
    const float z = q == 0 ? -10.0001f : -10.0f;
    m.positions = {{-5, -5, z}, {5, -5, z}, {5, 5, z}, {-5, 5, z}};
    m.indices = {0, 1, 2, 0, 2, 3};
    m.material = q;
    scene.meshes.push_back(m);
  }
  GltfCamera camera;
  camera.eye = {0, 0, 0};
  camera.target = {0, 0, -1};
  camera.znear = 1e-3;
  scene.camera = camera;
  scene.write(path);
  return path;
}

TEST(SweepErrors, DepthFormatsOnZFightingShowVisibilityError) {
  TempDir dir("zfight");
  const std::string scene = writeZFightingScene(dir / "zfight.gltf");
  const SweepSpec s = spec({scene}, {"depth-format=float-reversed,unorm24,unorm16"},
                           {"--size", "24", "18", "--threads", "2"});
  const std::vector<Cell> cells = planCells(s);
  ASSERT_EQ(cells.size(), 3u);
  ReferenceSource references("auto");
  std::vector<CellErrors> e;
  for (const Cell& c : cells) e.push_back(measureCell(c, 1, references).errors);
  std::printf("visibility disagreement: float-reversed %g, unorm24 %g, unorm16 %g\n", e[0].visibility,
              e[1].visibility, e[2].visibility);
  // float-reversed differs only where a pixel centre lies on a quad's
  // diagonal (a shared-edge tie, counted apart).
  EXPECT_EQ(e[0].visibility, 0.0);
  EXPECT_GT(e[0].visibilitySharedEdge, 0.0);
  EXPECT_GT(e[1].visibility, e[0].visibility + 0.1);
  EXPECT_GT(e[2].visibility, e[0].visibility + 0.1);
  EXPECT_GT(e[2].rms, e[0].rms);
}

// Rows of a sweep.csv without its time columns.
std::vector<std::string> rowsWithoutTimes(const std::string& csv) {
  std::vector<std::string> lines, out;
  std::istringstream in(csv);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  std::vector<bool> keep;
  {
    std::istringstream h(lines.at(0));
    for (std::string c; std::getline(h, c, ',');) keep.push_back(!isTimeColumn(c));
  }
  for (const std::string& line : lines) {
    // No field of these sweeps is quoted (no commas in paths or args).
    std::istringstream f(line);
    std::string kept;
    size_t i = 0;
    for (std::string c; std::getline(f, c, ','); ++i)
      if (i < keep.size() && keep[i]) kept += c + ",";
    out.push_back(kept);
  }
  return out;
}

TEST(SweepCommand, ShardsMergeToTheFullTableAndResumeSkipsDoneCells) {
  TempDir dir("shards");
  const std::vector<std::string> base = {"sweep",  kScenes + "/three-triangles.gltf",
                                         "--vary", "spp=1,4",
                                         "--vary", "renderer=raster,raytrace,hybrid",
                                         "--size", "12",
                                         "8",      "--repeat",
                                         "1"};
  const auto run = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = base;
    args.insert(args.end(), extra.begin(), extra.end());
    const test::CommandResult r = test::runRastray(args);
    EXPECT_EQ(r.status, 0) << r.err;
    return r;
  };
  const test::CommandResult full = run({"--report", dir / "full"});
  EXPECT_NE(full.out.find("raytrace"), std::string::npos) << full.out;
  run({"--shard", "0/2", "--report", dir / "s0"});
  run({"--shard", "1/2", "--report", dir / "s1"});
  const test::CommandResult merged =
      test::runRastray({"sweep", "--merge", dir / "s0", dir / "s1", "--report", dir / "merged"});
  ASSERT_EQ(merged.status, 0) << merged.err;
  const std::string fullCsv = slurp(dir / "full/sweep.csv"), mergedCsv = slurp(dir / "merged/sweep.csv");
  EXPECT_EQ(std::count(fullCsv.begin(), fullCsv.end(), '\n'), 7);
  EXPECT_EQ(rowsWithoutTimes(fullCsv), rowsWithoutTimes(mergedCsv));
  EXPECT_NE(slurp(dir / "s0/sweep.csv"), slurp(dir / "s1/sweep.csv"));
  EXPECT_TRUE(std::filesystem::exists(dir / "merged/index.html"));

  // Shards of another sweep are refused.
  run({"--vary", "depth-format=float,unorm16", "--shard", "0/2", "--report", dir / "other"});
  const test::CommandResult mixed =
      test::runRastray({"sweep", "--merge", dir / "s0", dir / "other", "--report", dir / "bad"});
  EXPECT_EQ(mixed.status, 2);
  EXPECT_NE(mixed.err.find("fingerprint"), std::string::npos) << mixed.err;

  // --resume on shard 0's folder runs only shard 1's cells; shard 0's rows
  // stay as they were, times included (they did not run again).
  const std::string before = slurp(dir / "s0/sweep.csv");
  const test::CommandResult resumed = run({"--resume", "--report", dir / "s0"});
  EXPECT_NE(resumed.err.find("3 cells already"), std::string::npos) << resumed.err;
  const std::string after = slurp(dir / "s0/sweep.csv");
  EXPECT_EQ(rowsWithoutTimes(after), rowsWithoutTimes(fullCsv));
  const auto row = [](const std::string& csv, const std::string& cell) {
    const size_t at = csv.find("\n" + cell + ",");
    return at == std::string::npos ? std::string() : csv.substr(at, csv.find('\n', at + 1) - at);
  };
  for (const char* cell : {"0", "2", "4"}) {
    EXPECT_FALSE(row(before, cell).empty());
    EXPECT_EQ(row(after, cell), row(before, cell)) << "cell " << cell << " ran again";
  }
  // Resuming into a folder of another sweep is refused.
  const test::CommandResult wrong =
      test::runRastray({"sweep", kScenes + "/three-triangles.gltf", "--vary", "spp=1,16", "--size", "12", "8",
                        "--resume", "--report", dir / "s0"});
  EXPECT_EQ(wrong.status, 2);
}

TEST(SweepReport, PlotsAreWellFormedSvgWithLabelledAxesAndAParetoFront) {
  TempDir dir("plots");
  const test::CommandResult r = test::runRastray({"sweep", kScenes + "/three-triangles.gltf", "--vary",
                                                  "spp=1,4", "--vary", "renderer=raster,raytrace", "--size",
                                                  "12", "8", "--repeat", "1", "--report", dir / "r"});
  ASSERT_EQ(r.status, 0) << r.err;
  std::vector<std::filesystem::path> svgs;
  for (const auto& entry : std::filesystem::directory_iterator(dir.path / "r/plots"))
    svgs.push_back(entry.path());
  // 4 errors × 2 varied options.
  ASSERT_EQ(svgs.size(), 8u);
  for (const auto& path : svgs) {
    std::string error;
    const std::vector<test::Element> elements = test::parseXml(slurp(path.string()), &error);
    ASSERT_TRUE(error.empty()) << path << ": " << error;
    EXPECT_EQ(elements.at(0).name, "svg");
    std::string texts;
    for (const test::Element& e : elements) texts += e.text + "\n";
    EXPECT_NE(texts.find("render time (BVH build + frame, median) (s)"), std::string::npos) << path;
    EXPECT_NE(texts.find("Pareto front"), std::string::npos) << path;
    EXPECT_NE(texts.find(" against time, by "), std::string::npos) << path;
    const bool any = std::any_of(errorMetrics().begin(), errorMetrics().end(), [&](const ErrorMetric& m) {
      return texts.find(m.quantity) != std::string::npos;
    });
    EXPECT_TRUE(any) << path << ": no y axis title";
  }
  const std::string html = slurp(dir / "r/index.html");
  EXPECT_EQ(html.find("http://"), html.find("http://www.w3.org/2000/svg"));  // only the SVG namespace name
  EXPECT_EQ(html.find("https://"), std::string::npos);
  EXPECT_NE(html.find("<svg"), std::string::npos);
}

}  // namespace
}  // namespace rastray::sweep
