#include "app/bench/bench_peers.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "app/bench/child_process.h"
#include "common/math_constants.h"

namespace rastray {

namespace {

std::string num(double v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);  // 17 digits: the double comes back bit for bit
  return buf;
}

void addVec(std::vector<std::string>& args, const char* option, const glm::dvec3& v) {
  args.insert(args.end(), {option, num(v.x), num(v.y), num(v.z)});
}

bool executable(const std::string& path) { return !path.empty() && ::access(path.c_str(), X_OK) == 0; }

// The peer program `name`: beside this executable (build/rastray →
// build/bench/peers/name) or, for the test binaries in build/tests/, under
// the parent directory. Empty when none exists.
std::string findPeer(const std::string& name) {
  const std::filesystem::path self = crossover::selfExecutable();
  if (self.empty()) return {};
  const std::filesystem::path dir = self.parent_path();
  for (const std::filesystem::path& candidate :
       {dir / "bench" / "peers" / name, dir / name, dir.parent_path() / "bench" / "peers" / name})
    if (executable(candidate.string())) return candidate.string();
  return {};
}

// The last non-empty line of a child's stderr (SPEC §7: one line).
std::string lastLine(const std::string& text) {
  std::istringstream in(text);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  return last;
}

PeerRun runPeer(const std::string& peerName, const std::string& program, const std::vector<std::string>& args,
                const PeerRequest& request) {
  PeerRun run;
  run.peer = peerName;
  run.command = program;
  for (const std::string& a : args) run.command += " " + a;
  std::error_code ec;
  std::filesystem::create_directories(request.workDir, ec);
  if (ec) {
    run.error = "cannot create the work directory " + request.workDir + ": " + ec.message();
    return run;
  }
  crossover::ChildLimits limits;
  limits.timeoutSeconds = request.timeoutSeconds;
  const crossover::ChildResult child = crossover::runChild(program, args, request.workDir, limits);
  if (!child.started) {
    run.error = "cannot run " + program + ": " + lastLine(child.err);
    return run;
  }
  if (child.timedOut) {
    run.error = "killed after " + num(request.timeoutSeconds) + " s";
    return run;
  }
  if (child.signal != 0) {
    run.error = "ended by signal " + std::to_string(child.signal) + ": " + lastLine(child.err);
    return run;
  }
  if (child.exitCode == 3) {  // rastray_embree_peer: the viewer program is absent
    run.skipped = lastLine(child.err);
    return run;
  }
  if (child.exitCode != 0) {
    run.error = "exit status " + std::to_string(child.exitCode) + ": " + lastLine(child.err);
    return run;
  }
  run.ran = parsePeerOutput(child.out, run);
  return run;
}

}  // namespace

std::vector<std::string> peerCameraArgs(const Camera& camera) {
  std::vector<std::string> args = {"--size", std::to_string(camera.width), std::to_string(camera.height)};
  // World (file-space) eye; the scene is rebased on worldOrigin, where
  // rastray's store has its (0, 0, 0).
  addVec(args, "--eye", camera.eye() + camera.worldOrigin);
  addVec(args, "--forward", camera.forward());
  addVec(args, "--up", glm::dvec3(camera.worldFromView[1]));
  addVec(args, "--origin", camera.worldOrigin);
  if (camera.projection == Projection::Perspective) {
    args.insert(args.end(), {"--projection", "perspective", "--yfov", num(camera.yfov * 180.0 / kPi)});
  } else {
    args.insert(args.end(),
                {"--projection", "orthographic", "--xmag", num(camera.xmag), "--ymag", num(camera.ymag)});
  }
  args.insert(args.end(),
              {"--aspect", num(camera.aspect), "--znear", num(camera.znear), "--zfar", num(camera.zfar)});
  return args;
}

bool parsePeerOutput(const std::string& out, PeerRun& run) {
  std::istringstream in(out);
  std::string line;
  bool haveMedian = false;
  run.frameMs.clear();
  run.cpuMs.clear();
  while (std::getline(in, line)) {
    const auto rest = [&](const char* prefix) { return line.substr(std::char_traits<char>::length(prefix)); };
    unsigned index = 0;
    double ms = 0;
    char unit[8] = {};
    if (line.rfind("renderer: ", 0) == 0) {
      run.renderer = rest("renderer: ");
    } else if (line.rfind("note: ", 0) == 0) {
      run.notes.push_back(rest("note: "));
    } else if (line.rfind("command: ", 0) == 0) {
      run.notes.push_back("runs " + rest("command: "));
    } else if (line.rfind("obj: ", 0) == 0) {
      run.notes.push_back("scene as " + rest("obj: "));
    } else if (std::sscanf(line.c_str(), "median frame: %lf %7s", &ms, unit) == 2 &&
               std::string(unit) == "ms") {
      run.medianMs = ms;
      haveMedian = true;
    } else if (std::sscanf(line.c_str(), "median cpu: %lf %7s", &ms, unit) == 2 &&
               std::string(unit) == "ms") {
      run.medianCpuMs = ms;
    } else if (std::sscanf(line.c_str(), "frame %u: %lf %7s", &index, &ms, unit) == 3 &&
               std::string(unit) == "ms") {
      if (index != run.frameMs.size()) {
        run.error = "frame lines out of order at '" + line + "'";
        return false;
      }
      run.frameMs.push_back(ms);
      double cpu = 0;
      if (std::sscanf(line.c_str(), "frame %*u: %*f ms (cpu %lf ms)", &cpu) == 1) run.cpuMs.push_back(cpu);
    }
  }
  if (run.frameMs.empty() || !haveMedian) {
    run.error = "no frame times in the peer's output";
    return false;
  }
  if (!run.cpuMs.empty() && run.cpuMs.size() != run.frameMs.size()) {
    run.error = "a CPU time on some frame lines only";
    return false;
  }
  return true;
}

PeerRun runOsmesaPeer(const PeerRequest& request) {
  const std::string program = findPeer("rastray_osmesa_peer");
  if (program.empty()) {
    PeerRun run;
    run.peer = "llvmpipe";
    run.skipped =
        "rastray_osmesa_peer is not built: OSMesa was not found when cmake ran (install libosmesa6-dev and "
        "re-run cmake) or the build has RASTRAY_BUILD_BENCH=OFF";
    return run;
  }
  std::vector<std::string> args = {request.scenePath};
  const std::vector<std::string> camera = peerCameraArgs(request.camera);
  args.insert(args.end(), camera.begin(), camera.end());
  args.insert(args.end(), {"--spp", std::to_string(request.spp), "--frames", std::to_string(request.frames)});
  if (request.threads > 0) args.insert(args.end(), {"--threads", std::to_string(request.threads)});
  if (!request.imageOut.empty()) args.insert(args.end(), {"--out", request.imageOut});
  return runPeer("llvmpipe", program, args, request);
}

PeerRun runEmbreeViewer(const PeerRequest& request) {
  PeerRun skipped;
  skipped.peer = "embree viewer";
  const std::string viewer = "/usr/bin/viewer";
  if (!executable(viewer)) {
    skipped.skipped = "Embree's viewer (" + viewer + ") is not installed: apt-get install embree-tools";
    return skipped;
  }
  if (request.camera.projection != Projection::Perspective) {
    skipped.skipped = "Embree's viewer has only a perspective camera";
    return skipped;
  }
  const std::string program = findPeer("rastray_embree_peer");
  if (program.empty()) {
    skipped.skipped = "rastray_embree_peer is not built (the build has RASTRAY_BUILD_BENCH=OFF)";
    return skipped;
  }
  std::vector<std::string> args = {request.scenePath};
  const std::vector<std::string> camera = peerCameraArgs(request.camera);
  args.insert(args.end(), camera.begin(), camera.end());
  args.insert(args.end(), {"--work-dir", request.workDir, "--frames", std::to_string(request.frames),
                           "--viewer", viewer});
  if (request.threads > 0) args.insert(args.end(), {"--threads", std::to_string(request.threads)});
  if (!request.imageOut.empty()) args.insert(args.end(), {"--out", request.imageOut});
  return runPeer("embree viewer", program, args, request);
}

}  // namespace rastray
