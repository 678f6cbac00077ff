// The render origin (issue 9): a lit scene moved 1e6 and 1e7 units from the
// file's origin by its node translations renders like the same scene at the
// origin when the store is rebased on the camera (the default), and visibly
// does not with --origin world (the failure it exists to prevent).
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include <gtest/gtest.h>
#include <glm/gtc/constants.hpp>

#include "app/engine/render_setup.h"
#include "common/camera.h"
#include "common/gltf/loader.h"
#include "common/gltf/writer.h"
#include "common/scene.h"

namespace rastray {
namespace {

GltfMesh box(glm::vec3 lo, glm::vec3 hi, int material) {
  GltfMesh m;
  m.material = material;
  for (int i = 0; i < 8; ++i)
    m.positions.push_back({i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z});
  // Outward CCW faces: -x, +x, -y, +y, -z, +z.
  m.indices = {0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5, 0, 1, 5, 0, 5, 4,
               2, 6, 7, 2, 7, 3, 0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6};
  return m;
}

// The scene: a floor, a box and a flat-shaded sphere of radius 1.5
// under one directional light, everything (camera and meshes) translated by
// `offset` through node translations, so the file holds it exactly.
GltfScene litScene(const glm::dvec3& offset) {
  GltfScene s;
  s.materials.resize(3);
  s.materials[0].baseColor = {0.8f, 0.8f, 0.8f, 1.0f};
  s.materials[1].baseColor = {0.9f, 0.4f, 0.2f, 1.0f};
  s.materials[2].baseColor = {0.3f, 0.5f, 0.9f, 1.0f};
  GltfMesh floor;
  floor.positions = {{-6, 0, -6}, {6, 0, -6}, {6, 0, 6}, {-6, 0, 6}};
  floor.indices = {0, 2, 1, 0, 3, 2};  // facing +y
  s.meshes = {floor, box({-3.0f, 0.0f, -1.0f}, {-1.0f, 2.0f, 1.0f}, 1),
              uvSphereMesh({1.8f, 1.5f, 0.0f}, 1.5f, 16, 32, 2)};
  for (GltfMesh& m : s.meshes) m.translation = offset;
  GltfCamera camera;
  camera.eye = offset + glm::dvec3(0.0, 4.0, 9.0);
  camera.target = offset + glm::dvec3(0.0, 1.0, 0.0);
  camera.yfov = 0.8;
  camera.znear = 0.1;
  s.camera = camera;
  GltfLight sun;
  sun.direction = glm::normalize(glm::dvec3(-0.5, -1.0, -0.4));
  s.lights = {sun};
  return s;
}

RenderSettings settingsFor(RendererKind renderer, RenderOrigin origin) {
  RenderSettings s;
  s.renderer = renderer;
  s.renderOrigin = origin;
  s.camera.size = {480, 320};
  s.finish();
  return s;
}

FlatImage renderFile(const std::string& path, const RenderSettings& settings) {
  Scene scene = loadScene(path);
  applyRenderOrigin(scene, settings.renderOrigin, settings.camera.overrides());
  return renderScene(scene, settings).output.image;
}

// Fraction of pixels whose linear RGB differs by more than 0.1 in a channel.
double fractionOff(const FlatImage& a, const FlatImage& b) {
  size_t off = 0;
  for (size_t i = 0; i < a.color.size(); ++i) {
    const glm::vec4 d = glm::abs(a.color[i] - b.color[i]);
    if (std::max(d.r, std::max(d.g, d.b)) > 0.1f) ++off;
  }
  return double(off) / double(a.color.size());
}

class RenderOrigin_ : public ::testing::TestWithParam<RendererKind> {
 protected:
  static std::string write(const glm::dvec3& offset, const std::string& name) {
    const std::string path = name + "_" + std::to_string(getpid()) + ".gltf";
    litScene(offset).write(path);
    return path;
  }
};

TEST_P(RenderOrigin_, NodeTranslationsFarAwayRenderLikeTheOrigin) {
  const RendererKind renderer = GetParam();
  const std::string atOrigin = write(glm::dvec3(0.0), "origin0");
  const FlatImage reference = renderFile(atOrigin, settingsFor(renderer, RenderOrigin::Camera));
  for (double distance : {1e6, 1e7}) {
    const std::string far = write(glm::dvec3(distance, 0.0, -0.37 * distance), "originfar");
    const double rebased =
        fractionOff(renderFile(far, settingsFor(renderer, RenderOrigin::Camera)), reference);
    const double world = fractionOff(renderFile(far, settingsFor(renderer, RenderOrigin::World)), reference);
    std::printf("%s at %.0e: off %.5f (--origin camera), %.5f (--origin world)\n", toString(renderer),
                distance, rebased, world);
    EXPECT_LT(rebased, 1e-3) << toString(renderer) << " at " << distance << ", --origin camera";
    // The failure the default prevents: float spacing at 1e6 is 1/16, at
    // 1e7 a whole unit, so the sphere's facets and shadows move.
    EXPECT_GT(world, 2e-3) << toString(renderer) << " at " << distance << ", --origin world";
    std::filesystem::remove(far);
  }
  std::filesystem::remove(atOrigin);
}

INSTANTIATE_TEST_SUITE_P(Renderers, RenderOrigin_,
                         ::testing::Values(RendererKind::Raster, RendererKind::Raytrace,
                                           RendererKind::Hybrid),
                         [](const auto& p) { return std::string(toString(p.param)); });

TEST(RenderOrigin, RebasingKeepsTheCameraOverridesInWorldSpace) {
  const std::string path = "overrides_" + std::to_string(getpid()) + ".gltf";
  litScene(glm::dvec3(5e6, 0.0, 0.0)).write(path);
  Scene scene = loadScene(path);
  CameraOverrides overrides;
  overrides.eye = glm::dvec3(5e6 + 1.0, 3.0, 8.0);
  overrides.target = glm::dvec3(5e6, 1.0, 0.0);
  applyRenderOrigin(scene, RenderOrigin::Camera, overrides);
  EXPECT_EQ(scene.origin, *overrides.eye);
  const Camera camera = makeCamera(scene, overrides, 64, 48);
  EXPECT_EQ(camera.eye(), glm::dvec3(0.0));
  EXPECT_EQ(camera.eye() + camera.worldOrigin, *overrides.eye);
  // Every rebased position is the world position minus the origin, rounded once.
  for (size_t i = 0; i < scene.positions.size(); ++i)
    EXPECT_EQ(scene.positions[i], glm::vec3(scene.worldPositions[i] - scene.origin));
  // The light moved with the scene; directions do not move.
  applyRenderOrigin(scene, RenderOrigin::World, overrides);
  EXPECT_EQ(scene.origin, glm::dvec3(0.0));
  EXPECT_EQ(makeCamera(scene, overrides, 64, 48).eye(), *overrides.eye);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace rastray
