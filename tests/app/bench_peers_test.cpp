// The performance peers (app/bench/bench_peers.h, bench/peers/): they run, their
// frame times are read, and they see what rastray sees: the OSMesa peer's
// IDs and depth agree with rastray's rasterizer pixel by pixel (same
// camera, same flattened geometry), the viewer's OBJ holds rastray's
// vertices and triangles and is exported once. Bad input exits 2.
#include "app/bench/bench_peers.h"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "common/camera.h"
#include "common/gltf/loader.h"
#include "common/image.h"
#include "run_command.h"

namespace rastray {
namespace {

namespace fs = std::filesystem;

std::string scenePath(const std::string& name) { return std::string(RASTRAY_SCENES) + "/" + name; }

// A fresh directory per test under the current one (ctest runs each test
// in its own process, possibly in parallel; each test has its own name).
std::string workDir(const std::string& name) {
  const fs::path dir = fs::current_path() / ("bench_peers_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

// The camera `rastray render` makes: the scene rebased on the eye
// (--origin camera), then makeCamera with the same overrides.
Camera renderCamera(const std::string& path, const CameraOverrides& overrides, int w, int h) {
  Scene scene = loadScene(path);
  applyRenderOrigin(scene, RenderOrigin::Camera, overrides);
  return makeCamera(scene, overrides, w, h);
}

FlatImage renderOurs(const std::string& path, int w, int h, int spp,
                     const std::vector<std::string>& cameraArgs, const std::string& out) {
  std::vector<std::string> args = {
      "render",          path,    "--renderer",        "raster", "--size", std::to_string(w),
      std::to_string(h), "--spp", std::to_string(spp), "-o",     out};
  args.insert(args.end(), cameraArgs.begin(), cameraArgs.end());
  const test::CommandResult r = test::runRastray(args);
  EXPECT_EQ(r.status, 0) << r.err;
  return readExr(out);
}

struct Agreement {
  double ids = 0;          // fraction of pixels with equal (instance, triangle)
  double coverage = 0;     // fraction with equal hit / no hit
  double covered = 0;      // fraction hit in ours
  double maxDepthRel = 0;  // over pixels whose IDs agree and are hits
};

Agreement agreement(const FlatImage& a, const FlatImage& b) {
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  Agreement r;
  const size_t n = a.instance.size();
  size_t ids = 0, coverage = 0, covered = 0;
  for (size_t i = 0; i < n; ++i) {
    const bool hitA = a.instance[i] != kNoId, hitB = b.instance[i] != kNoId;
    covered += hitB;
    coverage += hitA == hitB;
    if (a.instance[i] == b.instance[i] && a.triangle[i] == b.triangle[i]) {
      ++ids;
      if (hitA) {
        const double rel = std::abs(double(a.depth[i]) - b.depth[i]) / std::max(a.depth[i], b.depth[i]);
        r.maxDepthRel = std::max(r.maxDepthRel, rel);
      }
    }
  }
  r.ids = double(ids) / n;
  r.coverage = double(coverage) / n;
  r.covered = double(covered) / n;
  return r;
}

// Which pixels of a binary PPM (P6, 8 bit, as Embree's viewer writes it)
// are not black; empty when the file is not such a PPM of w x h.
std::vector<bool> readPpmCoverage(const std::string& path, int w, int h) {
  std::ifstream in(path, std::ios::binary);
  std::string magic;
  int fw = 0, fh = 0, maxValue = 0;
  in >> magic >> fw >> fh >> maxValue;
  in.get();  // the one whitespace byte before the pixels
  if (magic != "P6" || fw != w || fh != h || maxValue != 255) {
    ADD_FAILURE() << path << ": not a " << w << "x" << h << " P6 PPM";
    return {};
  }
  std::vector<unsigned char> bytes(size_t(w) * h * 3);
  in.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(bytes.size()));
  std::vector<bool> mask(size_t(w) * h);
  for (size_t i = 0; i < mask.size(); ++i) mask[i] = bytes[3 * i] || bytes[3 * i + 1] || bytes[3 * i + 2];
  return mask;
}

#ifdef RASTRAY_OSMESA_PEER_BUILT
constexpr bool kOsmesaPeerBuilt = true;
#else
constexpr bool kOsmesaPeerBuilt = false;
#endif
#ifdef RASTRAY_EMBREE_PEER_BUILT
constexpr bool kEmbreePeerBuilt = true;
#else
constexpr bool kEmbreePeerBuilt = false;
#endif

#define SKIP_WITHOUT_OSMESA_PEER()                                                                    \
  if (!kOsmesaPeerBuilt)                                                                              \
  GTEST_SKIP() << "rastray_osmesa_peer is not built (RASTRAY_BUILD_BENCH=OFF or no OSMesa): nothing " \
                  "to run"

// Runs the OSMesa peer and rastray's rasterizer with one camera and
// compares their ID buffers.
Agreement compareWithRaster(const std::string& name, const std::string& scene,
                            const CameraOverrides& overrides, const std::vector<std::string>& cameraArgs,
                            int spp) {
  const int w = 96, h = 72;
  const std::string dir = workDir(name);
  PeerRequest request;
  request.scenePath = scenePath(scene);
  request.camera = renderCamera(request.scenePath, overrides, w, h);
  request.spp = spp;
  request.threads = 1;
  request.frames = 2;
  request.workDir = dir;
  request.imageOut = dir + "/peer.exr";
  const PeerRun run = runOsmesaPeer(request);
  EXPECT_TRUE(run.ran) << run.skipped << run.error;
  EXPECT_EQ(run.frameMs.size(), 2u);
  EXPECT_GT(run.medianMs, 0.0);
  EXPECT_EQ(run.cpuMs.size(), 2u);
  EXPECT_GT(run.medianCpuMs, 0.0);
  EXPECT_NE(run.renderer.find("Mesa"), std::string::npos) << run.renderer;
  if (!run.ran) return {};
  return agreement(readExr(request.imageOut),
                   renderOurs(request.scenePath, w, h, spp, cameraArgs, dir + "/ours.exr"));
}

TEST(OsmesaPeer, SeesRastrayIdsAndDepthWithTheFileCamera) {
  SKIP_WITHOUT_OSMESA_PEER();
  const Agreement a = compareWithRaster("file_camera", "cornell-box.gltf", {}, {}, 1);
  // Edge ties (SPEC §3: either triangle of a shared edge) are the only
  // allowed difference; at 96x72 they are a handful of pixels.
  EXPECT_GT(a.covered, 0.3);
  EXPECT_GT(a.ids, 0.99);
  EXPECT_GT(a.coverage, 0.995);
  // Both store float reversed-Z (n/d) and recover d in double: the float
  // rounding of n/d and of the interpolation, a few float ULPs.
  EXPECT_LT(a.maxDepthRel, 1e-5);
}

TEST(OsmesaPeer, SeesRastrayIdsWithAnExplicitCameraAwayFromTheOrigin) {
  SKIP_WITHOUT_OSMESA_PEER();
  // An oblique camera with a finite far plane: the peer is rebased on an
  // eye that is not the file's origin, and the projection's far row is used.
  CameraOverrides overrides;
  overrides.eye = glm::dvec3(1.7, 0.9, 2.6);
  overrides.target = glm::dvec3(-0.2, -0.3, 0.0);
  overrides.up = glm::dvec3(0.1, 1.0, 0.0);
  overrides.yfovDegrees = 52.0;
  overrides.znear = 0.05;
  overrides.zfar = 50.0;
  const std::vector<std::string> cli = {"--eye",  "1.7", "0.9",     "2.6",  "--target", "-0.2",
                                        "-0.3",   "0",   "--up",    "0.1",  "1",        "0",
                                        "--yfov", "52",  "--znear", "0.05", "--zfar",   "50"};
  const Agreement a = compareWithRaster("explicit_camera", "cornell-box.gltf", overrides, cli, 1);
  EXPECT_GT(a.covered, 0.3);
  EXPECT_GT(a.ids, 0.99);
  EXPECT_GT(a.coverage, 0.995);
  EXPECT_LT(a.maxDepthRel, 1e-5);
}

TEST(OsmesaPeer, SeesRastrayIdsWithAnOrthographicCamera) {
  SKIP_WITHOUT_OSMESA_PEER();
  const Agreement a = compareWithRaster("orthographic", "three-triangles.gltf", {}, {}, 1);
  EXPECT_GT(a.covered, 0.1);
  EXPECT_GT(a.ids, 0.99);
  EXPECT_GT(a.coverage, 0.99);
  EXPECT_LT(a.maxDepthRel, 1e-5);
}

TEST(OsmesaPeer, MsaaRunsAndResolvesIdsOfOneSample) {
  SKIP_WITHOUT_OSMESA_PEER();
  // At 4 spp both keep one sample's IDs per pixel, not necessarily the
  // same sample: they differ along every silhouette and triangle edge.
  const Agreement a = compareWithRaster("msaa", "cornell-box.gltf", {}, {}, 4);
  EXPECT_GT(a.ids, 0.9);
  EXPECT_GT(a.coverage, 0.97);
}

TEST(EmbreeViewerPeer, ParsesARealRunAndCachesTheObj) {
  if (::access("/usr/bin/viewer", X_OK) != 0)
    GTEST_SKIP() << "Embree's viewer (/usr/bin/viewer, Debian embree-tools) is not installed";
  if (!kEmbreePeerBuilt) GTEST_SKIP() << "rastray_embree_peer is not built (RASTRAY_BUILD_BENCH=OFF)";
  PeerRequest request;
  request.scenePath = scenePath("cornell-box.gltf");
  request.camera = renderCamera(request.scenePath, {}, 64, 48);
  request.threads = 1;
  request.frames = 3;
  request.workDir = workDir("viewer");
  request.imageOut = request.workDir + "/viewer.ppm";
  const PeerRun first = runEmbreeViewer(request);
  ASSERT_TRUE(first.ran) << first.skipped << first.error;
  EXPECT_EQ(first.frameMs.size(), 3u);
  EXPECT_NE(first.renderer.find("Embree"), std::string::npos) << first.renderer;
  const double lo = *std::min_element(first.frameMs.begin(), first.frameMs.end());
  const double hi = *std::max_element(first.frameMs.begin(), first.frameMs.end());
  EXPECT_GT(lo, 0.0);
  EXPECT_GE(first.medianMs, lo - 5e-4);  // the printed median has 3 decimals
  EXPECT_LE(first.medianMs, hi + 5e-4);

  // The OBJ holds rastray's store: every vertex and every triangle.
  std::vector<fs::path> objs;
  for (const auto& e : fs::directory_iterator(request.workDir))
    if (e.path().extension() == ".obj") objs.push_back(e.path());
  ASSERT_EQ(objs.size(), 1u);
  const Scene scene = loadScene(request.scenePath);
  std::ifstream in(objs[0]);
  std::string line;
  size_t vertices = 0, faces = 0, groups = 0;
  while (std::getline(in, line)) {
    vertices += line.rfind("v ", 0) == 0;
    faces += line.rfind("f ", 0) == 0;
    groups += line.rfind("g ", 0) == 0;
  }
  EXPECT_EQ(vertices, scene.positions.size());
  EXPECT_EQ(faces, scene.triangles.size());
  EXPECT_EQ(groups, scene.instances.size());

  // The viewer's picture covers what rastray's does: its eyelight shader
  // writes |n·d| > 0 where a ray hits and black elsewhere (every wall of
  // the box faces the camera, so no hit is exactly black).
  const std::vector<bool> viewerMask = readPpmCoverage(request.imageOut, 64, 48);
  const FlatImage ours = renderOurs(request.scenePath, 64, 48, 1, {}, request.workDir + "/ours.exr");
  ASSERT_EQ(viewerMask.size(), ours.instance.size());
  size_t agree = 0, covered = 0;
  for (size_t i = 0; i < viewerMask.size(); ++i) {
    agree += viewerMask[i] == (ours.instance[i] != kNoId);
    covered += viewerMask[i];
  }
  EXPECT_GT(double(covered) / viewerMask.size(), 0.3);
  // The viewer aims its rays at pixel corners (x, y), ours at centres
  // (x + 0.5, y + 0.5): its picture is shifted by half a pixel, which flips
  // about half of the silhouette pixels (the box's outline is ~6 % of a
  // 64x48 image); a wrong camera (pose, field of view) would flip far more.
  EXPECT_GT(double(agree) / viewerMask.size(), 0.95);

  // A second run reuses it.
  const auto written = fs::last_write_time(objs[0]);
  const PeerRun second = runEmbreeViewer(request);
  ASSERT_TRUE(second.ran) << second.error;
  bool cached = false;
  for (const std::string& note : second.notes) cached |= note.find("(cached)") != std::string::npos;
  EXPECT_TRUE(cached);
  EXPECT_EQ(fs::last_write_time(objs[0]), written);
}

TEST(BenchPeers, CameraArgumentsCarryEveryNumberExactly) {
  CameraOverrides overrides;
  overrides.eye = glm::dvec3(0.1, 0.2, 3.3);
  const Camera camera = renderCamera(scenePath("cornell-box.gltf"), overrides, 320, 200);
  const std::vector<std::string> args = peerCameraArgs(camera);
  const auto valuesOf = [&](const std::string& option, size_t count) {
    const auto it = std::find(args.begin(), args.end(), option);
    EXPECT_NE(it, args.end()) << option;
    std::vector<double> v;
    for (size_t i = 1; i <= count && it != args.end(); ++i)
      v.push_back(std::strtod((it + i)->c_str(), nullptr));
    return v;
  };
  EXPECT_EQ(valuesOf("--size", 2), (std::vector<double>{320, 200}));
  const glm::dvec3 eye = camera.eye() + camera.worldOrigin;
  EXPECT_EQ(valuesOf("--eye", 3), (std::vector<double>{eye.x, eye.y, eye.z}));
  EXPECT_EQ(valuesOf("--origin", 3),
            (std::vector<double>{camera.worldOrigin.x, camera.worldOrigin.y, camera.worldOrigin.z}));
  const glm::dvec3 f = camera.forward();
  EXPECT_EQ(valuesOf("--forward", 3), (std::vector<double>{f.x, f.y, f.z}));
  EXPECT_EQ(valuesOf("--aspect", 1), (std::vector<double>{camera.aspect}));
  EXPECT_EQ(valuesOf("--znear", 1), (std::vector<double>{camera.znear}));
  EXPECT_EQ(valuesOf("--zfar", 1), (std::vector<double>{camera.zfar}));

  // An infinite far plane is spelled "inf".
  CameraOverrides infinite;
  infinite.zfar = std::numeric_limits<double>::infinity();
  const std::vector<std::string> inf =
      peerCameraArgs(renderCamera(scenePath("cornell-box.gltf"), infinite, 8, 8));
  const auto zfar = std::find(inf.begin(), inf.end(), "--zfar");
  ASSERT_NE(zfar, inf.end());
  EXPECT_EQ(*(zfar + 1), "inf");
}

TEST(BenchPeers, ParsesFrameLinesAndRefusesIncompleteOutput) {
  PeerRun run;
  ASSERT_TRUE(parsePeerOutput(
      "renderer: llvmpipe (LLVM 15) | 4.5 Mesa\nnote: wider picture\nwarm-up: 9.000 ms\nframe 0: 1.500 ms\n"
      "frame 1: 2.250 ms\nframe 2: 1.750 ms\nmedian frame: 1.750 ms\n",
      run))
      << run.error;
  EXPECT_EQ(run.renderer, "llvmpipe (LLVM 15) | 4.5 Mesa");
  EXPECT_EQ(run.frameMs, (std::vector<double>{1.5, 2.25, 1.75}));
  EXPECT_EQ(run.medianMs, 1.75);
  ASSERT_EQ(run.notes.size(), 1u);
  EXPECT_EQ(run.notes[0], "wider picture");

  EXPECT_TRUE(run.cpuMs.empty());

  PeerRun withCpu;
  ASSERT_TRUE(
      parsePeerOutput("frame 0: 2.000 ms (cpu 3.500 ms)\nframe 1: 4.000 ms (cpu 7.250 ms)\n"
                      "median cpu: 5.375 ms\nmedian frame: 3.000 ms\n",
                      withCpu))
      << withCpu.error;
  EXPECT_EQ(withCpu.frameMs, (std::vector<double>{2.0, 4.0}));
  EXPECT_EQ(withCpu.cpuMs, (std::vector<double>{3.5, 7.25}));
  EXPECT_EQ(withCpu.medianCpuMs, 5.375);
  EXPECT_EQ(withCpu.medianMs, 3.0);

  PeerRun noMedian;
  EXPECT_FALSE(parsePeerOutput("frame 0: 1.500 ms\n", noMedian));
  EXPECT_FALSE(noMedian.error.empty());
  PeerRun gap;
  EXPECT_FALSE(parsePeerOutput("frame 0: 1.0 ms\nframe 2: 1.0 ms\nmedian frame: 1.0 ms\n", gap));
  EXPECT_NE(gap.error.find("out of order"), std::string::npos);
}

// Runs a peer program directly: exit status and stderr.
test::CommandResult runProgram(const std::string& program, const std::vector<std::string>& args) {
  const std::string errPath = "peer_" + std::to_string(::getpid()) + ".err";
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int err = ::open(errPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, 1);
    ::dup2(err, 2);
    std::vector<std::string> copy = args;
    copy.insert(copy.begin(), program);
    std::vector<char*> argv;
    for (std::string& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(program.c_str(), argv.data());
    _exit(127);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  test::CommandResult r;
  r.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream in(errPath);
  std::stringstream s;
  s << in.rdbuf();
  r.err = s.str();
  std::remove(errPath.c_str());
  return r;
}

std::string peerProgram(const std::string& name) {
  return (fs::path(RASTRAY_BINARY).parent_path() / "bench" / "peers" / name).string();
}

void expectBadInput(const std::string& program, const std::vector<std::string>& args,
                    const std::string& needle) {
  const test::CommandResult r = runProgram(program, args);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;  // one line (SPEC §7)
  EXPECT_NE(r.err.find(needle), std::string::npos) << r.err;
}

void expectPeerRefusesBadInput(const std::string& program, const std::vector<std::string>& extra) {
  const std::string cornell = scenePath("cornell-box.gltf");
  const auto with = [&](std::vector<std::string> a) {
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  };
  expectBadInput(program, with({"no-such-scene.gltf", "--size", "8", "8"}), "no-such-scene.gltf");
  expectBadInput(program,
                 with({std::string(RASTRAY_TEST_DATA) + "/malformed/invalid-json.gltf", "--size", "8", "8"}),
                 "invalid-json.gltf");
  expectBadInput(program, with({cornell, "--size", "0", "8"}), "--size");
  expectBadInput(program, with({cornell, "--size", "8", "8", "--eye", "0", "0", "3"}), "--forward");
  expectBadInput(program,
                 with({cornell, "--size", "8",    "8", "--eye", "0", "0",      "3",  "--forward", "0",
                       "0",     "-1",     "--up", "0", "1",     "0", "--yfov", "45", "--znear",   "0"}),
                 "--znear");
  expectBadInput(program,
                 with({cornell, "--size", "8",    "8", "--eye", "0",  "0",      "3",  "--forward", "0",
                       "0",     "-1",     "--up", "0", "0",     "-1", "--yfov", "45", "--znear",   "0.1"}),
                 "--up");
  expectBadInput(program, with({cornell, "--size", "8", "8", "--zfar", "far"}), "--zfar");
  expectBadInput(program, with({cornell, "--size", "8", "8", "--frames", "0"}), "--frames");
}

TEST(OsmesaPeer, RefusesBadInputWithExitStatus2) {
  SKIP_WITHOUT_OSMESA_PEER();
  const std::string program = peerProgram("rastray_osmesa_peer");
  expectPeerRefusesBadInput(program, {});
  expectBadInput(program, {scenePath("cornell-box.gltf"), "--size", "8", "8", "--spp", "64"}, "--spp");
}

TEST(EmbreeViewerPeer, RefusesBadInputWithExitStatus2) {
  if (!kEmbreePeerBuilt) GTEST_SKIP() << "rastray_embree_peer is not built (RASTRAY_BUILD_BENCH=OFF)";
  if (::access("/usr/bin/viewer", X_OK) != 0)
    GTEST_SKIP() << "Embree's viewer (/usr/bin/viewer, Debian embree-tools) is not installed";
  const std::string dir = workDir("viewer_bad");
  expectPeerRefusesBadInput(peerProgram("rastray_embree_peer"), {"--work-dir", dir});
  expectBadInput(peerProgram("rastray_embree_peer"),
                 {scenePath("three-triangles.gltf"), "--size", "8", "8", "--work-dir", dir}, "perspective");
}

}  // namespace
}  // namespace rastray
