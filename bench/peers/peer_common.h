// What the performance peers (rastray_osmesa_peer, rastray_embree_peer)
// share: the explicit camera of their command line, the scene rebased the
// way rastray rebases it, and the frame-time lines `rastray bench --peers`
// reads (app/bench/bench_peers.h).
//
// The camera is given explicitly because the peer must see what rastray
// sees: the caller resolves it with rastray's makeCamera and passes every
// number (in file space, printed with 17 significant digits so doubles
// round-trip). Without --eye/--forward/--up the peer resolves the file's
// camera (or SPEC §2's default) itself with makeCamera, like `rastray
// render` without camera options.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "common/camera.h"
#include "common/scene.h"

namespace rastray::peers {

struct PeerCameraArgs {
  std::vector<int> size;                         // W H
  std::vector<double> eye, forward, up, origin;  // file space; 3 values each when given
  std::string projection = "perspective";
  double yfovDegrees = 0;  // perspective; 0: not given
  double aspect = 0;       // 0: width / height
  double xmag = 0, ymag = 0;
  double znear = 0;  // 0: not given (refused with an explicit perspective camera)
  std::string zfar;  // a number or "inf"; empty: not given (inf with an explicit camera)
};

// Registers what every peer takes first: the positional SCENE (a glTF
// file, required) into `scenePath`, then its camera options (everything
// above) into `camera`.
void addSceneOptions(CLI::App& app, std::string& scenePath, PeerCameraArgs& camera);

// Rebases `scene` (freshly loaded, origin 0) on --origin (default: the
// eye, rastray's `--origin camera`) and returns the camera in that frame.
// Throws InputError("command line", option, message) for impossible
// settings, the same ones makeCamera refuses.
Camera resolveCamera(Scene& scene, const PeerCameraArgs& args);

// The median of the frame times (the mean of the two middle ones for an
// even count); 0 for none.
double medianOf(std::vector<double> values);

// Prints "frame I: T ms" for every frame (with cpuMs, parallel to frameMs:
// "frame I: T ms (cpu C ms)"), then "median frame: M ms" (3 decimals), the
// last line the bench runner reads. With cpuMs a "median cpu: C ms" line
// comes before it.
void printFrameTimes(const std::vector<double>& frameMs, const std::vector<double>& cpuMs = {});

// Parses the command line into `app`, runs `body` and maps exceptions to
// SPEC §7 exit statuses: bad usage (CLI11) and InputError print one line on
// stderr and return 2; any other error prints one line and returns 1.
int runPeerMain(CLI::App& app, int argc, char** argv, const std::function<int()>& body);

}  // namespace rastray::peers
