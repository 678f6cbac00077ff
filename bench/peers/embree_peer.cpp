// rastray_embree_peer: the ray-casting peer of `rastray bench --peers`.
// Exports rastray's flattened scene (rebased like rastray rebases it) to an
// OBJ, cached in --work-dir, and runs Embree's own `viewer --benchmark`
// (Debian embree-tools) on it with the same camera and size, with the
// `eyelight` shader: one primary ray per pixel shaded by |n·d|, the work of
// rastray's ray caster on a scene without lights (primary rays, eye light).
//
// The viewer times each frame it skips ("frame [i / N]: F fps (skipped)")
// and only a summary of the others, so it runs with --benchmark (1 + K) 1:
// frame 0 is the warm-up, frames 1..K are the timed ones, one per line.
// Its camera has no near plane, no orthographic mode and takes the aspect
// ratio from the image size; a camera with another aspect ratio is noted
// (same ray count, a different picture).
//
// Output (stdout): renderer, obj, command and scene lines, "frame I: T ms"
// per timed frame, a primary-ray rate, and last "median frame: M ms".
// Exit status 0; 2 for bad input (one line on stderr); 3 when the viewer
// program is absent (nothing run); 1 when the viewer fails.
#include <fcntl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "bench/peers/obj_export.h"
#include "bench/peers/peer_common.h"
#include "common/error.h"
#include "common/gltf/loader.h"
#include "common/math_constants.h"

namespace rastray::peers {

namespace {

struct Options {
  std::string scenePath;
  PeerCameraArgs camera;
  std::string workDir;
  int frames = 10;
  int threads = 0;  // 0: the viewer's default (every core)
  std::string viewer = "/usr/bin/viewer";
  std::string shader = "eyelight";
  std::string out;
};

std::string num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.9g", v);  // float precision: the viewer parses floats
  return buf;
}

// Runs argv (argv[0] a path) with stdout and stderr into `logPath`;
// returns its exit status (-1 when a signal ended it).
int runToLog(const std::vector<std::string>& args, const std::string& logPath) {
  std::vector<char*> argv;
  std::vector<std::string> copy = args;
  for (std::string& a : copy) argv.push_back(a.data());
  argv.push_back(nullptr);
  const int fd = ::open(logPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw InputError(logPath, "", "cannot write the viewer's log");
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::dup2(fd, 1);
    ::dup2(fd, 2);
    const int in = ::open("/dev/null", O_RDONLY);
    if (in >= 0) ::dup2(in, 0);
    ::execv(argv[0], argv.data());
    _exit(127);
  }
  ::close(fd);
  if (pid < 0) throw std::runtime_error("fork failed");
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string readWhole(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string lastLines(const std::string& text, int count) {
  size_t pos = text.size();
  for (int i = 0; i <= count && pos > 0; ++i) pos = text.rfind('\n', pos - 1);
  std::string tail = text.substr(pos == std::string::npos ? 0 : pos + 1);
  for (char& c : tail)
    if (c == '\n') c = '|';
  return tail;
}

int run(const Options& o) {
  if (o.frames < 1) throw InputError("command line", "--frames", "must be at least 1");
  if (o.threads < 0) throw InputError("command line", "--threads", "must be >= 0");
  if (::access(o.viewer.c_str(), X_OK) != 0) {
    std::fprintf(stderr, "%s: not found or not executable (Debian package embree-tools)\n", o.viewer.c_str());
    return 3;
  }
  std::error_code ec;
  std::filesystem::create_directories(o.workDir, ec);
  if (ec) throw InputError(o.workDir, "", "cannot create the work directory: " + ec.message());

  Scene scene = loadScene(o.scenePath);
  const Camera camera = resolveCamera(scene, o.camera);
  if (camera.projection != Projection::Perspective)
    throw InputError("command line", "--projection", "Embree's viewer has only a perspective camera");
  const int w = camera.width, h = camera.height;
  const double imageAspect = double(w) / double(h);
  if (std::abs(camera.aspect - imageAspect) > 1e-6 * imageAspect)
    std::printf(
        "note: the camera's aspect ratio %.6g is not %dx%d's; the viewer uses the image's (same rays "
        "per frame, a %s picture)\n",
        camera.aspect, w, h, camera.aspect < imageAspect ? "wider" : "narrower");

  const std::string obj = cachedObjPath(o.scenePath, scene.origin, o.workDir);
  if (std::filesystem::exists(obj)) {
    std::printf("obj: %s (cached)\n", obj.c_str());
  } else {
    const auto t0 = std::chrono::steady_clock::now();
    writeObj(scene, obj);
    std::printf("obj: %s (exported in %.1f ms)\n", obj.c_str(),
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }

  // The camera in the OBJ's frame (the scene's rebased one).
  const glm::dvec3 eye = camera.eye(), at = eye + camera.forward();
  const glm::dvec3 up(camera.worldFromView[1]);
  std::vector<std::string> args = {o.viewer,
                                   "-i",
                                   obj,
                                   "--vp",
                                   num(eye.x),
                                   num(eye.y),
                                   num(eye.z),
                                   "--vi",
                                   num(at.x),
                                   num(at.y),
                                   num(at.z),
                                   "--vu",
                                   num(up.x),
                                   num(up.y),
                                   num(up.z),
                                   "--fov",
                                   num(camera.yfov * 180.0 / kPi),
                                   "--size",
                                   std::to_string(w),
                                   std::to_string(h),
                                   "--shader",
                                   o.shader,
                                   "--verbose",
                                   "1",
                                   "--benchmark",
                                   std::to_string(1 + o.frames),
                                   "1"};
  if (o.threads > 0) args.insert(args.begin() + 1, {"--threads", std::to_string(o.threads)});
  if (!o.out.empty()) args.insert(args.end(), {"-o", o.out});
  std::string command;
  for (const std::string& a : args) command += (command.empty() ? "" : " ") + a;
  std::printf("command: %s\n", command.c_str());
  std::fflush(stdout);

  const std::string log = (std::filesystem::path(o.workDir) / "viewer.log").string();
  const int status = runToLog(args, log);
  const std::string text = readWhole(log);
  if (status != 0)
    throw std::runtime_error("the viewer exited with status " + std::to_string(status) + ": " +
                             lastLines(text, 3));

  std::smatch m;
  if (std::regex_search(text, m, std::regex(R"(Embree Ray Tracing Kernels (\S+))")))
    std::printf("renderer: Embree %s viewer (%s), shader %s\n", m[1].str().c_str(), o.viewer.c_str(),
                o.shader.c_str());
  std::printf("scene: %zu instances, %zu triangles, %dx%d, 1 primary ray per pixel\n", scene.instances.size(),
              scene.triangles.size(), w, h);

  // "frame [  3 /  11]:   173.45 fps (skipped)": frame 0 is the warm-up.
  const std::regex frameLine(R"(frame \[\s*(\d+)\s*/\s*\d+\]:\s*([0-9.eE+-]+) fps \(skipped\))");
  std::vector<double> frameMs;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), frameLine); it != std::sregex_iterator();
       ++it) {
    const int index = std::stoi((*it)[1].str());
    const double fps = std::stod((*it)[2].str());
    if (index == 0) continue;
    if (!(fps > 0.0)) throw std::runtime_error("the viewer printed a frame rate of " + (*it)[2].str());
    frameMs.push_back(1000.0 / fps);
  }
  if (int(frameMs.size()) != o.frames)
    throw std::runtime_error("expected " + std::to_string(o.frames) + " timed frames from the viewer, read " +
                             std::to_string(frameMs.size()) + ": " + lastLines(text, 3));
  const double median = medianOf(frameMs);
  std::printf("primary rays: %.2f Mrays/s at the median frame\n", double(w) * h / (median * 1e3));
  printFrameTimes(frameMs);
  return 0;
}

}  // namespace

}  // namespace rastray::peers

int main(int argc, char** argv) {
  using namespace rastray::peers;
  Options o;
  CLI::App app{
      "rastray_embree_peer: exports rastray's flattened scene to OBJ (cached in --work-dir) and times "
      "Embree's `viewer --benchmark` on it with an explicit camera; the last line is 'median frame: <ms> ms'",
      "rastray_embree_peer"};
  addSceneOptions(app, o.scenePath, o.camera);
  app.add_option("--work-dir", o.workDir, "where the OBJ is cached and the viewer's log is kept")->required();
  app.add_option("--frames", o.frames, "timed frames, after one warm-up frame");
  app.add_option("--threads", o.threads, "the viewer's threads (default: every core)");
  app.add_option("--viewer", o.viewer, "Embree's viewer program");
  app.add_option("--shader", o.shader, "the viewer's shader (eyelight: primary rays with an eye light)");
  app.add_option("--out", o.out, "the viewer writes one frame here (.ppm, .pfm or .tga)");
  return runPeerMain(app, argc, argv, [&] { return run(o); });
}
