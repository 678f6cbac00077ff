#include "app/povray/povray_check.h"

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <set>
#include <sstream>

#include "app/bench/child_process.h"
#include "app/engine/render_setup.h"
#include "app/povray/pov_export.h"
#include "common/error.h"
#include "common/interrupt.h"

namespace rastray {

namespace {

// A directory of its own under the system's temporary directory (POV-Ray's
// default configuration lets it write there and in "."), removed when done.
class TemporaryDirectory {
 public:
  TemporaryDirectory() {
    std::string pattern = (std::filesystem::temp_directory_path() / "rastray-povray-XXXXXX").string();
    if (!::mkdtemp(pattern.data()))
      throw InputError("povray", "", "cannot create a temporary directory like " + pattern);
    path_ = pattern;
  }
  ~TemporaryDirectory() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TemporaryDirectory(const TemporaryDirectory&) = delete;
  TemporaryDirectory& operator=(const TemporaryDirectory&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace

// The last non-empty line POV-Ray wrote to stderr that says what went
// wrong, for the one-line error. POV-Ray warns that it "cannot open the user
// configuration file" on every run without ~/.povray/3.7/povray.conf, failed
// or not, so that warning never stands for the failure.
std::string povrayComplaint(const std::string& err) {
  auto isUserConfigWarning = [](const std::string& line) {
    return line.find("user configuration file") != std::string::npos;
  };
  std::istringstream in(err);
  std::string line, last;
  while (std::getline(in, line)) {
    if (isUserConfigWarning(line)) continue;
    if (line.find("rror") != std::string::npos || line.find("annot") != std::string::npos ||
        line.find("ailed") != std::string::npos)
      last = line;
  }
  if (last.empty()) {
    std::istringstream again(err);
    while (std::getline(again, line))
      if (line.find_first_not_of(" \t") != std::string::npos && !isUserConfigWarning(line)) last = line;
  }
  const size_t start = last.find_first_not_of(" \t");
  return start == std::string::npos ? std::string("no message") : last.substr(start);
}

namespace {

FlatImage renderWithPovray(const std::string& povray, const std::string& dir, const Camera& camera,
                           bool shadows, double& seconds) {
  const std::string output = shadows ? "lit.exr" : "unlit.exr";
  crossover::ChildLimits limits;
  limits.workingDirectory = dir;
  const crossover::ChildResult r = crossover::runChild(
      povray, povrayArguments("scene.pov", output, camera.width, camera.height, shadows), dir, limits);
  seconds += r.wallSeconds;
  if (!r.started) throw InputError(povray, "", "cannot run POV-Ray: " + povrayComplaint(r.err));
  if (r.exitCode != 0 || r.signal != 0 || !std::filesystem::exists(dir + "/" + output))
    throw InputError(povray, shadows ? "+Q4" : "+Q3",
                     "POV-Ray failed (exit " + std::to_string(r.exitCode) + "): " + povrayComplaint(r.err));
  return readExr(dir + "/" + output);
}

}  // namespace

std::string findPovray() {
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path ? path : "");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    if (dir.empty()) continue;
    const std::string candidate = dir + "/povray";
    if (::access(candidate.c_str(), X_OK) == 0 && !std::filesystem::is_directory(candidate))
      return std::filesystem::absolute(candidate).string();
  }
  return "";
}

RenderSettings withoutShadows(const RenderSettings& settings) {
  std::set<std::string> leaveOut{"--shadows"};
  for (const RenderOptionSpec& spec : renderOptionTable())
    if (spec.condition == OptionCondition::ShadowMaps) leaveOut.insert(spec.name);
  std::vector<std::string> args = toArgs(settings, leaveOut);
  args.insert(args.end(), {"--shadows", "none"});
  return renderSettingsFrom(args, settings.allRenderers);
}

PovrayCheck runPovrayCheck(Scene scene, const RenderSettings& settings, const std::string& povray,
                           const ShadowMaskOptions& options) {
  if (settings.spp != 1)
    throw InputError(
        "command line", "--spp",
        "the POV-Ray check compares one sample per pixel (POV-Ray traces the pixel centre): give "
        "--spp 1");
  if (scene.lights.empty())
    throw InputError(scene.path, "lights",
                     "the scene has no light (lit by the eye light): no shadows to compare");
  makeOpaqueDiffuse(scene);

  PovrayCheck check;
  RenderRun lit = renderScene(scene, settings);
  RenderRun unlit = renderScene(scene, withoutShadows(settings));
  check.camera = lit.camera;
  check.oursLit = std::move(lit.output.image);
  check.oursUnlit = std::move(unlit.output.image);
  throwIfInterrupted();

  check.povSource = povSceneText(scene, check.camera);
  TemporaryDirectory dir;
  writeTextFile(dir.path() + "/scene.pov", check.povSource);
  check.povrayLit = renderWithPovray(povray, dir.path(), check.camera, true, check.povraySeconds);
  check.povrayUnlit = renderWithPovray(povray, dir.path(), check.camera, false, check.povraySeconds);

  check.ours = shadowMask(check.oursLit, check.oursUnlit, options);
  check.povray = shadowMask(check.povrayLit, check.povrayUnlit, options);
  check.agreement = compareShadowMasks(check.ours, check.povray);
  return check;
}

nlohmann::json povrayCheckJson(const std::string& scenePath, const RenderSettings& settings,
                               const PovrayCheck& check) {
  const ShadowMaskAgreement& a = check.agreement;
  return {{"schema", "rastray.povray"},
          {"version", 1},
          {"scene", scenePath},
          {"renderer", toString(settings.renderer)},
          {"width", check.camera.width},
          {"height", check.camera.height},
          {"povray_seconds", check.povraySeconds},
          {"agreement",
           {{"pixels", a.pixels},
            {"lit_reference", a.litReference},
            {"shadowed_reference", a.shadowedReference},
            {"shadowed_ours", a.shadowedOurs},
            {"ours_shadowed_reference_lit", a.oursShadowedRefLit},
            {"ours_lit_reference_shadowed", a.oursLitRefShadowed},
            {"lit_in_one_only", a.litInOneOnly},
            {"disagreeing", a.disagreeing()},
            {"disagreeing_percent", 100.0 * a.disagreeingFraction()}}}};
}

}  // namespace rastray
