// The performance peers `rastray bench --peers` runs beside our renderers
// (issue 12): Mesa's llvmpipe through OSMesa (bench/peers/osmesa_peer.cpp)
// and Embree's own `viewer --benchmark` on the scene exported to OBJ
// (bench/peers/embree_peer.cpp). Each peer is a child process that loads
// the scene with rastray's loader, rebases it on the same origin and takes
// the camera number by number, so it sees the same floats from the same
// viewpoint; its per-frame times come back parsed.
//
// A peer whose program or package is absent is skipped with a message
// saying what to install or build, never an error.
#pragma once

#include <string>
#include <vector>

#include "common/camera.h"

namespace rastray {

struct PeerRequest {
  std::string scenePath;
  // makeCamera's camera on the scene rebased as rastray renders it:
  // camera.worldOrigin is the rebase point the peer rebases on as well.
  Camera camera;
  int spp = 1;                  // OSMesa: MSAA samples; the viewer traces 1 ray per pixel
  int threads = 0;              // 0: the peer's default (LP_NUM_THREADS as inherited; the viewer: every core)
  int frames = 10;              // timed frames, after one warm-up frame
  std::string workDir;          // the children's output files and the cached OBJ; created when missing
  std::string imageOut;         // optional: the peer writes its last frame here (OSMesa: .png or .exr with Z
                                // and IDs; viewer: .ppm)
  double timeoutSeconds = 900;  // a peer still running then is killed and reported as failed
};

struct PeerRun {
  std::string peer;      // "llvmpipe" or "embree viewer"
  bool ran = false;      // it ran and printed its frame times
  std::string skipped;   // why it did not run (its program or package is absent); empty otherwise
  std::string error;     // it ran and failed: exit status and its error line
  std::string command;   // the command line run (for the table's footnotes)
  std::string renderer;  // what the peer says it is, e.g. "llvmpipe (LLVM 15.0.6, 256 bits) | 4.5 (Core
                         // Profile) Mesa 22.3.6"
  std::vector<std::string> notes;  // the peer's "note:" lines and the viewer's own command
  std::vector<double> frameMs;     // the timed frames, in order
  double medianMs = 0;             // the peer's own "median frame" line
  // CPU time of all the peer's threads per frame (OSMesa only; empty for
  // the viewer), and its median: the load-independent part of the frame.
  std::vector<double> cpuMs;
  double medianCpuMs = 0;
};

// Runs rastray_osmesa_peer, found beside this executable (build/) or in
// bench/peers/ under it or its parent (build/tests/ → build/bench/peers/).
PeerRun runOsmesaPeer(const PeerRequest& request);
// Runs rastray_embree_peer (found the same way), which runs /usr/bin/viewer;
// skipped when either is absent or the camera is orthographic.
PeerRun runEmbreeViewer(const PeerRequest& request);

// The command-line arguments that hand `camera` to a peer (--size, --eye,
// --forward, --up, --origin, --projection, --yfov or --xmag/--ymag,
// --aspect, --znear, --zfar), every number with 17 significant digits.
std::vector<std::string> peerCameraArgs(const Camera& camera);

// Reads a peer's standard output into `run`: "renderer: …", "note: …",
// "command: …", "obj: …", "frame I: T ms" (optionally "(cpu C ms)"),
// "median cpu: C ms" and the last "median frame: M ms". False
// (with run.error set) when the frame lines or the median are missing.
bool parsePeerOutput(const std::string& out, PeerRun& run);

}  // namespace rastray
