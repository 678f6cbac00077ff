#include "bench/peers/peer_common.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <limits>

#include "common/error.h"
#include "common/math_constants.h"

namespace rastray::peers {

namespace {

[[noreturn]] void badOption(const std::string& option, const std::string& message) {
  throw InputError("command line", option, message);
}

glm::dvec3 vec3Of(const std::vector<double>& v, const std::string& option) {
  const glm::dvec3 r(v[0], v[1], v[2]);
  if (!(std::isfinite(r.x) && std::isfinite(r.y) && std::isfinite(r.z))) badOption(option, "must be finite");
  return r;
}

double parseZfar(const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || std::isnan(v)) badOption("--zfar", "'" + text + "' is not a number");
  return v;
}

// One line whatever the message holds (SPEC §7).
void printErrorLine(const std::string& message) {
  std::string line;
  for (const char ch : message) line += (static_cast<unsigned char>(ch) < 0x20) ? ' ' : ch;
  std::fprintf(stderr, "%s\n", line.c_str());
}

}  // namespace

void addSceneOptions(CLI::App& app, std::string& scenePath, PeerCameraArgs& camera) {
  app.add_option("scene", scenePath, "glTF scene (.gltf or .glb)")->required();
  app.add_option("--size", camera.size, "image width and height in pixels")->expected(2)->required();
  app.add_option("--eye", camera.eye, "eye position (file space)")->expected(3);
  app.add_option("--forward", camera.forward, "view direction (need not be unit)")->expected(3);
  app.add_option("--up", camera.up, "up vector (re-orthogonalised against --forward)")->expected(3);
  app.add_option("--origin", camera.origin,
                 "render origin the scene is rebased on before rounding to float (default: the eye)")
      ->expected(3);
  app.add_option("--projection", camera.projection, "perspective or orthographic")
      ->check(CLI::IsMember({"perspective", "orthographic"}));
  app.add_option("--yfov", camera.yfovDegrees, "vertical field of view in degrees (perspective)");
  app.add_option("--aspect", camera.aspect, "aspect ratio (default: width / height)");
  app.add_option("--xmag", camera.xmag, "orthographic half width");
  app.add_option("--ymag", camera.ymag, "orthographic half height");
  app.add_option("--znear", camera.znear, "near plane distance");
  app.add_option("--zfar", camera.zfar, "far plane distance, or inf (default: inf, or the file camera's)");
}

Camera resolveCamera(Scene& scene, const PeerCameraArgs& args) {
  const int width = args.size[0], height = args.size[1];
  if (width < 1 || height < 1) badOption("--size", "image size must be at least 1x1");
  const bool anyPose = !args.eye.empty() || !args.forward.empty() || !args.up.empty();
  if (!anyPose) {
    // The file's camera (or SPEC §2's default), as `rastray render` makes it.
    CameraOverrides overrides;
    if (args.yfovDegrees != 0) overrides.yfovDegrees = args.yfovDegrees;
    if (args.znear != 0) overrides.znear = args.znear;
    if (!args.zfar.empty()) overrides.zfar = parseZfar(args.zfar);
    if (!args.origin.empty())
      rebaseScene(scene, vec3Of(args.origin, "--origin"));
    else
      applyRenderOrigin(scene, RenderOrigin::Camera, overrides);
    return makeCamera(scene, overrides, width, height);
  }
  if (args.eye.empty() || args.forward.empty() || args.up.empty())
    badOption("--eye", "--eye, --forward and --up go together");
  const glm::dvec3 eyeFile = vec3Of(args.eye, "--eye");
  const glm::dvec3 forward = vec3Of(args.forward, "--forward");
  const glm::dvec3 up = vec3Of(args.up, "--up");
  if (!(glm::length(forward) > 0.0)) badOption("--forward", "must be non-zero");
  if (!(glm::length(up) > 0.0)) badOption("--up", "must be non-zero");
  rebaseScene(scene, args.origin.empty() ? eyeFile : vec3Of(args.origin, "--origin"));

  Camera camera;
  camera.projection = args.projection == "orthographic" ? Projection::Orthographic : Projection::Perspective;
  camera.width = width;
  camera.height = height;
  camera.worldOrigin = scene.origin;
  camera.origin = "command line";
  // The same orthonormal frame makeCamera builds from a forward and an up.
  const glm::dvec3 f = glm::normalize(forward);
  const glm::dvec3 r = glm::cross(f, glm::normalize(up));
  if (!(glm::length(r) > 1e-9)) badOption("--up", "is parallel to --forward");
  const glm::dvec3 right = glm::normalize(r);
  const glm::dvec3 trueUp = glm::cross(right, f);
  camera.worldFromView = glm::dmat4(glm::dvec4(right, 0.0), glm::dvec4(trueUp, 0.0), glm::dvec4(-f, 0.0),
                                    glm::dvec4(eyeFile - scene.origin, 1.0));
  camera.viewFromWorld = glm::inverse(camera.worldFromView);
  camera.aspect = args.aspect != 0 ? args.aspect : double(width) / double(height);
  if (!(camera.aspect > 0.0 && std::isfinite(camera.aspect))) badOption("--aspect", "must be finite and > 0");
  camera.znear = args.znear;
  camera.zfar = args.zfar.empty() ? std::numeric_limits<double>::infinity() : parseZfar(args.zfar);
  if (camera.projection == Projection::Perspective) {
    if (!(args.yfovDegrees > 0.0 && args.yfovDegrees < 180.0))
      badOption("--yfov", "a perspective camera needs --yfov in (0, 180) degrees");
    camera.yfov = args.yfovDegrees * kPi / 180.0;
    if (!(camera.znear > 0.0 && std::isfinite(camera.znear))) badOption("--znear", "must be finite and > 0");
  } else {
    if (!(args.xmag > 0.0 && args.ymag > 0.0 && std::isfinite(args.xmag) && std::isfinite(args.ymag)))
      badOption("--xmag", "an orthographic camera needs --xmag and --ymag > 0");
    camera.xmag = args.xmag;
    camera.ymag = args.ymag;
    if (!(camera.znear >= 0.0 && std::isfinite(camera.znear)))
      badOption("--znear", "must be finite and >= 0");
    if (!std::isfinite(camera.zfar)) badOption("--zfar", "an orthographic camera needs a finite zfar");
  }
  if (!(camera.zfar > camera.znear)) badOption("--zfar", "zfar must be greater than znear");
  return camera;
}

double medianOf(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

void printFrameTimes(const std::vector<double>& frameMs, const std::vector<double>& cpuMs) {
  const bool cpu = cpuMs.size() == frameMs.size() && !cpuMs.empty();
  for (size_t i = 0; i < frameMs.size(); ++i) {
    if (cpu)
      std::printf("frame %zu: %.3f ms (cpu %.3f ms)\n", i, frameMs[i], cpuMs[i]);
    else
      std::printf("frame %zu: %.3f ms\n", i, frameMs[i]);
  }
  if (cpu) std::printf("median cpu: %.3f ms\n", medianOf(cpuMs));
  std::printf("median frame: %.3f ms\n", medianOf(frameMs));
  std::fflush(stdout);
}

int runPeerMain(CLI::App& app, int argc, char** argv, const std::function<int()>& body) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    printErrorLine(app.get_name() + ": " + e.what());
    return 2;
  }
  try {
    return body();
  } catch (const InputError& e) {
    printErrorLine(e.what());
    return 2;
  } catch (const std::exception& e) {
    printErrorLine(app.get_name() + ": " + e.what());
    return 1;
  }
}

}  // namespace rastray::peers
