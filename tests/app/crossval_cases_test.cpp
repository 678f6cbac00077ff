// Cross-validation on generated scenes that once gave wrong answers: many
// transparent layers past the ray caster's cut-off, duplicated faces next
// to a shared edge, and face culling (SPEC §1, §3, §6).
#include <unistd.h>

#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>
#include <glm/gtc/constants.hpp>
#include <nlohmann/json.hpp>

#include "common/gltf/writer.h"
#include "run_command.h"

#include "tests/test_labels.h"

// Every test here renders on 2 or more threads (the ThreadSanitizer stage runs them).
RASTRAY_TEST_LABELS("threads");

namespace rastray {
namespace {

using nlohmann::json;
using test::runRastray;

std::string writeScene(const GltfScene& scene, const std::string& name) {
  const std::string path = name + "_" + std::to_string(getpid()) + ".gltf";
  scene.write(path);
  return path;
}

// Runs crossval --json on one scene; returns its scene entry.
json crossval(const std::string& path, std::vector<std::string> options, int expectedStatus = 0) {
  std::vector<std::string> args = {"crossval", path, "--json"};
  args.insert(args.end(), options.begin(), options.end());
  const auto r = runRastray(args);
  EXPECT_EQ(r.status, expectedStatus) << r.out << r.err;
  if (r.status != 0 && r.status != 1) return json::object();
  return json::parse(r.out)["scenes"][0];
}

GltfMesh quad(glm::vec3 centre, float half, int material) {
  GltfMesh m;
  m.positions = {centre + glm::vec3(-half, -half, 0), centre + glm::vec3(half, -half, 0),
                 centre + glm::vec3(half, half, 0), centre + glm::vec3(-half, half, 0)};
  m.indices = {0, 1, 2, 0, 2, 3};
  m.material = material;
  return m;
}

uint64_t genuine(const json& s, const char* pair) {
  return s[pair]["visibility"]["mismatches"]["genuine"].get<uint64_t>();
}

uint64_t mismatching(const json& v) {
  return v["layers"]["compared"].get<uint64_t>() - v["layers"]["agreeing"].get<uint64_t>();
}

// 64 stacked BLEND quads: the ray caster stops once the remaining
// transmittance is below its cut-off; the rasterizer's exact lists keep all
// 64. The layers it did not reach are "cut off", never mismatches, and a
// mismatch count never exceeds what was compared.
TEST(CrossvalCases, ManyTransparentLayersBeyondTheCutOff) {
  GltfScene scene;
  for (int i = 0; i < 64; ++i) {
    GltfMaterial m;
    m.alphaMode = "BLEND";
    m.baseColor =
        glm::vec4(0.2f + 0.01f * float(i), 0.5f, 1.0f - 0.01f * float(i), 0.05f + 0.9f * float(i) / 63.0f);
    scene.materials.push_back(m);
    scene.meshes.push_back(quad(glm::vec3(0.0f, 0.0f, -0.01f * float(i)), 1.0f, i));
  }
  scene.camera = GltfCamera{{0.3, 0.2, 3.0}, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, 0.8, 0.1, {}};
  const std::string path = writeScene(scene, "many_layers");
  const json s = crossval(path, {"--size", "96", "64", "--spp", "1"});
  const json& v = s["rasterVsRaytrace"]["visibility"];
  EXPECT_EQ(genuine(s, "rasterVsRaytrace"), 0u);
  EXPECT_EQ(genuine(s, "hybridVsRaytrace"), 0u);
  EXPECT_LE(mismatching(v), v["layers"]["compared"].get<uint64_t>());
  EXPECT_GT(v["cutOff"]["layers"].get<uint64_t>(), 1000u);
  EXPECT_GT(v["layers"]["agreeing"].get<double>(), 0.999 * v["layers"]["compared"].get<double>());
  // The cut-off layers carry at most the cut-off's share of the colour.
  EXPECT_GT(v["cutOff"]["maxColor"].get<double>(), 0.0);
  EXPECT_LT(v["cutOff"]["maxColor"].get<double>(), 1e-3);
  // Without the cut-off the ray caster reaches every layer: nothing is cut off.
  const json all = crossval(path, {"--size", "96", "64", "--spp", "1", "--transparency-cutoff", "0"});
  EXPECT_EQ(all["rasterVsRaytrace"]["visibility"]["cutOff"]["layers"].get<uint64_t>(), 0u);
  EXPECT_EQ(genuine(all, "rasterVsRaytrace"), 0u);
  std::filesystem::remove(path);
}

// Depth peeling with N layers is a declared layer limit: what lies behind
// the N-th peeled layer is cut off, not genuine.
TEST(CrossvalCases, PeelingLayerLimitIsACutOff) {
  GltfScene scene;
  for (int i = 0; i < 6; ++i) {
    GltfMaterial m;
    m.alphaMode = "BLEND";
    m.baseColor = glm::vec4(1.0f, 0.5f, 0.2f, 0.3f);
    scene.materials.push_back(m);
    scene.meshes.push_back(quad(glm::vec3(0.0f, 0.0f, -0.1f * float(i)), 1.0f, i));
  }
  const std::string path = writeScene(scene, "peel_limit");
  const json s = crossval(path, {"--size", "64", "48", "--spp", "1", "--transparency", "peel:2"});
  EXPECT_EQ(genuine(s, "rasterVsRaytrace"), 0u);
  EXPECT_GT(s["rasterVsRaytrace"]["visibility"]["cutOff"]["layers"].get<uint64_t>(), 0u);
  std::filesystem::remove(path);
}

// A BLEND mesh whose index list holds the same two triangles twice (a
// double-sided sheet as exporters write it) beside a BLEND quad sharing an
// edge: every triangle is its own layer (SPEC §1), the shared edge counts
// once, in both renderers and in shadow rays.
TEST(CrossvalCases, DuplicatedFacesAreTwoLayersSharedEdgesOne) {
  GltfScene scene;
  GltfMaterial blend;
  blend.alphaMode = "BLEND";
  blend.baseColor = glm::vec4(0.2f, 0.6f, 1.0f, 0.4f);
  blend.doubleSided = true;
  scene.materials = {blend, blend, GltfMaterial{}};
  scene.materials[1].baseColor = glm::vec4(1.0f, 0.4f, 0.1f, 0.5f);
  GltfMesh sheet = quad(glm::vec3(-0.5f, 0.0f, 0.0f), 0.5f, 0);
  sheet.indices = {0, 1, 2, 0, 2, 3, 0, 1, 2, 0, 2, 3};
  scene.meshes.push_back(sheet);
  scene.meshes.push_back(quad(glm::vec3(0.5f, 0.0f, 0.0f), 0.5f, 1));  // shares the edge x = 0
  GltfMesh floor = quad(glm::vec3(0.0f, 0.0f, -1.0f), 3.0f, 2);
  scene.meshes.push_back(floor);
  scene.lights.push_back({"directional", {0.0, 0.0, 0.0}, {0.2, -0.1, -1.0}, 3.0f});
  scene.camera = GltfCamera{{0.2, 0.1, 2.5}, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, 0.9, 0.1, {}};
  const std::string path = writeScene(scene, "duplicated_faces");
  const json s = crossval(path, {"--size", "160", "120", "--spp", "4"});
  EXPECT_EQ(genuine(s, "rasterVsRaytrace"), 0u);
  EXPECT_EQ(genuine(s, "hybridVsRaytrace"), 0u);
  const json& v = s["rasterVsRaytrace"]["visibility"];
  EXPECT_GT(v["layers"]["agreeing"].get<double>(), 0.999 * v["layers"]["compared"].get<double>());
  // Shading agrees where the hits agree, and overall up to edge pixels.
  EXPECT_LE(s["hybridVsRaytrace"]["color"]["maxWhereHitsAgree"].get<double>(), 1e-5);
  EXPECT_LT(s["hybridVsRaytrace"]["color"]["rms"].get<double>(), 2e-3);
  std::filesystem::remove(path);
}

// Face culling applies to single-sided materials in both renderers, to
// every ray (SPEC §3).
TEST(CrossvalCases, CullingAgreesOnClosedSingleSidedMeshes) {
  GltfScene scene;
  GltfMaterial grey, red, twoSided;
  red.baseColor = glm::vec4(1.0f, 0.2f, 0.2f, 1.0f);
  twoSided.doubleSided = true;
  scene.materials = {grey, red, twoSided};
  scene.meshes.push_back(uvSphereMesh(glm::vec3(-0.6f, 0.0f, 0.0f), 0.5f, 24, 48, 0));
  scene.meshes.push_back(uvSphereMesh(glm::vec3(0.6f, 0.1f, -0.3f), 0.6f, 20, 40, 1));
  GltfMesh wall = quad(glm::vec3(0.0f, 0.0f, -1.5f), 3.0f, 2);
  scene.meshes.push_back(wall);
  scene.lights.push_back({"directional", {0.0, 0.0, 0.0}, {-0.3, -0.5, -1.0}, 3.0f});
  scene.camera = GltfCamera{{0.0, 0.3, 3.0}, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, 0.8, 0.1, {}};
  const std::string path = writeScene(scene, "cull_spheres");
  for (const char* mode : {"back", "front"}) {
    const json s = crossval(path, {"--size", "120", "90", "--spp", "4", "--cull", mode});
    EXPECT_EQ(genuine(s, "rasterVsRaytrace"), 0u) << mode;
    EXPECT_EQ(genuine(s, "hybridVsRaytrace"), 0u) << mode;
  }
  std::filesystem::remove(path);
}

// From inside a single-sided box every face is a back face: with --cull
// back the ray caster sees through them to nothing, like the rasterizer.
TEST(CrossvalCases, RayCasterCullsBackFaces) {
  GltfScene scene;
  scene.materials = {GltfMaterial{}};
  GltfMesh box;
  for (int i = 0; i < 8; ++i)
    box.positions.emplace_back(i & 1 ? 1.0f : -1.0f, i & 2 ? 1.0f : -1.0f, i & 4 ? 1.0f : -1.0f);
  box.indices = {0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4,
                 2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5};
  scene.meshes.push_back(box);
  scene.camera = GltfCamera{{0.1, 0.2, 0.3}, {0.0, 0.0, -1.0}, {0.0, 1.0, 0.0}, 1.2, 0.01, {}};
  const std::string path = writeScene(scene, "inside_box");
  for (const char* renderer : {"raster", "raytrace"}) {
    const std::string exr = std::string("inside_") + renderer + "_" + std::to_string(getpid()) + ".exr";
    auto r = runRastray({"render", path, "--renderer", renderer, "--size", "32", "24", "--cull", "back",
                         "--stats", "-o", exr});
    ASSERT_EQ(r.status, 0) << r.err;
    r = runRastray({"compare", exr, exr, "--json"});
    ASSERT_EQ(r.status, 0) << r.err;
    // Nothing hit: every pixel is empty in the file.
    const json c = json::parse(r.out);
    EXPECT_EQ(c["visibility"]["pixels"]["bothEmpty"].get<uint64_t>(), 32u * 24u) << renderer << r.out;
    std::filesystem::remove(exr);
  }
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace rastray
