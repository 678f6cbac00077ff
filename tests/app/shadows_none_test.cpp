// --shadows none through the real binary, for every renderer: exit 0, no
// shadow ray counted, the pass said left out with its reason, and the
// picture the unshadowed shading: on a floor under a ball lit from above,
// every floor pixel shows the analytic Lambert value C/π·E·cos θ, the
// ball's shadow included (which the default render does show).
#ifdef RASTRAY_HAVE_RENDERERS

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/gltf/writer.h"
#include "common/image.h"
#include "common/math_constants.h"
#include "run_command.h"
#include "tests/test_files.h"

namespace rastray {
namespace {

using nlohmann::json;
using Args = std::vector<std::string>;

constexpr float kAlbedo = 0.6f, kIntensity = 2.0f;
const glm::dvec3 kToLight = glm::normalize(glm::dvec3(0.3, 1.0, 0.2));

// A 4×4 floor at y = 0 (instance 0) and a ball above it (instance 1),
// under one directional light, seen from straight above (orthographic).
std::string writeFloorAndBox() {
  GltfScene s;
  GltfMaterial grey;
  grey.baseColor = glm::vec4(kAlbedo, kAlbedo, kAlbedo, 1.0f);
  s.materials.push_back(grey);
  GltfMesh floor;
  floor.positions = {{-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}};
  floor.indices = {0, 1, 2, 0, 2, 3};  // CCW from +y
  s.meshes.push_back(floor);
  s.meshes.push_back(uvSphereMesh(glm::vec3(0.0f, 0.8f, 0.0f), 0.5f, 6, 8, 0));
  s.lights.push_back({"directional", glm::dvec3(0.0), -kToLight, kIntensity});
  GltfCamera camera;
  camera.eye = {0.0, 5.0, 0.0};
  camera.target = {0.0, 0.0, 0.0};
  camera.up = {0.0, 0.0, -1.0};
  camera.orthographic = true;
  camera.xmag = camera.ymag = 2.2;
  camera.znear = 0.1;
  camera.zfar = 20.0;
  s.camera = camera;
  const std::string path = test::scratchPath("floor-and-box.gltf");
  s.write(path);
  return path;
}

struct Render {
  FlatImage image;
  json report;
};

Render render(const std::string& scene, const std::string& renderer, const Args& extra) {
  static int count = 0;
  const std::string out = test::scratchPath("shadows-none-" + std::to_string(count++) + ".exr");
  Args args = {"render", scene, "--renderer", renderer, "--size", "64", "64", "--float", "--json", "-o", out};
  args.insert(args.end(), extra.begin(), extra.end());
  const auto r = test::runRastray(args);
  EXPECT_EQ(r.status, 0) << r.err;
  if (r.status != 0) return {};
  return {readExr(out), json::parse(r.out)};
}

bool leftOut(const Render& r, const std::string& text) {
  for (const json& p : r.report["passesLeftOut"])
    if (p.get<std::string>() == text) return true;
  return false;
}

TEST(ShadowsNone, EveryRendererShowsTheUnshadowedShading) {
  const std::string scene = writeFloorAndBox();
  const float lambert = float(kAlbedo / kPi * kIntensity * kToLight.y);
  for (const std::string renderer : {"raytrace", "hybrid", "raster"}) {
    SCOPED_TRACE(renderer);
    const Render shadowed = render(scene, renderer, {});
    const Render none = render(scene, renderer, {"--shadows", "none"});
    ASSERT_EQ(none.image.width, 64);
    EXPECT_EQ(none.report["counters"].value("rays.shadow", uint64_t(0)), 0u);
    EXPECT_EQ(none.report["counters"].value("raster.shadow_maps", uint64_t(0)), 0u);
    const std::string said =
        renderer == "raytrace" ? "shadow rays: --shadows none" : "shadows: --shadows none";
    EXPECT_TRUE(leftOut(none, said)) << none.report["passesLeftOut"].dump();
    int floor = 0, darkWithShadows = 0, off = 0;
    for (size_t i = 0; i < none.image.color.size(); ++i) {
      if (none.image.instance[i] != 0u) continue;
      ++floor;
      if (std::abs(none.image.color[i].r - lambert) > 1e-5f * lambert) ++off;
      if (shadowed.image.instance[i] == 0u && shadowed.image.color[i].r < 0.6f * lambert) ++darkWithShadows;
    }
    EXPECT_GT(floor, 2000);
    EXPECT_GT(darkWithShadows, 50);  // the default render shows the shadow: the check can fail
    EXPECT_EQ(off, 0) << "floor pixels away from " << lambert << " without shadows";
  }
}

}  // namespace
}  // namespace rastray

#endif
