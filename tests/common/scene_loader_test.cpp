// The flattened store (SPEC §1) and the default camera (SPEC §2) for the
// valid edge cases in tests/data/malformed/valid (written by
// tests/data/malformed/generate.py), checked value by value; and the
// structured InputError the loader raises for bad input (SPEC §7).
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <glm/glm.hpp>
#include <limits>
#include <ostream>
#include <string>
#include <vector>

#include "common/camera.h"
#include "common/error.h"
#include "common/gltf/loader.h"
#include "common/math_constants.h"
#include "common/scene.h"
#include "tests/test_files.h"

// Readable failure messages for the GLM vectors compared below.
namespace glm {
template <int N, typename T, qualifier Q>
void PrintTo(const vec<N, T, Q>& v, std::ostream* os) {
  *os << "(";
  for (int k = 0; k < N; ++k) *os << (k ? ", " : "") << v[k];
  *os << ")";
}
}  // namespace glm

namespace rastray {
namespace {

const std::string kValid = std::string(RASTRAY_TEST_DATA) + "/malformed/valid/";
const std::string kMalformed = std::string(RASTRAY_TEST_DATA) + "/malformed/";

Scene load(const std::string& name) { return loadScene(kValid + name); }

// Positions of one instance's vertices, in store order.
std::vector<glm::vec3> positionsOf(const Scene& s, uint32_t instance) {
  const Instance& in = s.instances.at(instance);
  return {s.positions.begin() + in.firstVertex, s.positions.begin() + in.firstVertex + in.vertexCount};
}

// Stored triangles of one instance, relative to its first vertex.
std::vector<glm::uvec3> trianglesOf(const Scene& s, uint32_t instance) {
  const Instance& in = s.instances.at(instance);
  std::vector<glm::uvec3> out;
  for (uint32_t t = 0; t < in.triangleCount; ++t)
    out.push_back(s.triangle(instance, t) - glm::uvec3(in.firstVertex));
  return out;
}

// The store's bookkeeping holds together: instances tile the vertex and
// triangle arrays in order and every index lies inside its instance.
void expectConsistentStore(const Scene& s) {
  ASSERT_EQ(s.normals.size(), s.positions.size());
  ASSERT_EQ(s.texcoords.size(), s.positions.size());
  uint32_t vertex = 0, triangle = 0;
  for (uint32_t i = 0; i < s.instances.size(); ++i) {
    const Instance& in = s.instances[i];
    EXPECT_EQ(in.firstVertex, vertex) << "instance " << i;
    EXPECT_EQ(in.firstTriangle, triangle) << "instance " << i;
    EXPECT_LT(in.material, s.materials.size()) << "instance " << i;
    for (uint32_t t = 0; t < in.triangleCount; ++t)
      for (int k = 0; k < 3; ++k) {
        EXPECT_GE(s.triangle(i, t)[k], in.firstVertex) << "instance " << i << " triangle " << t;
        EXPECT_LT(s.triangle(i, t)[k], in.firstVertex + in.vertexCount)
            << "instance " << i << " triangle " << t;
      }
    vertex += in.vertexCount;
    triangle += in.triangleCount;
  }
  EXPECT_EQ(vertex, s.positions.size());
  EXPECT_EQ(triangle, s.triangles.size());
}

void expectVec3Near(const glm::dvec3& actual, const glm::dvec3& expected, double tolerance,
                    const std::string& what) {
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(actual[k], expected[k], tolerance) << what << "[" << k << "]";
}

// Issue 13: a resource is looked for beside the glTF file only. tinygltf
// also searches the current directory; a file of the same name there must
// not stand in for the missing one.
TEST(SceneLoader, ResourcesResolveOnlyBesideTheFile) {
  namespace fs = std::filesystem;
  const fs::path dir = test::scratchDir();
  fs::remove_all(dir);
  fs::create_directories(dir / "scene");
  const fs::path gltf = dir / "scene" / "scene.gltf";
  fs::copy_file(kMalformed + "buffer-missing-file.gltf", gltf);
  std::ifstream in(gltf);
  const nlohmann::json doc = nlohmann::json::parse(in);
  const std::string uri = doc.at("buffers").at(0).at("uri");
  const size_t length = doc.at("buffers").at(0).at("byteLength");
  // The buffer, of the right length, in the current directory only.
  const fs::path cwd = fs::current_path();
  fs::current_path(dir);
  { std::ofstream(uri, std::ios::binary) << std::string(length, '\0'); }
  EXPECT_THROW(loadScene(gltf.string()), InputError);
  // Beside the file it is found.
  fs::copy_file(dir / uri, dir / "scene" / uri);
  EXPECT_NO_THROW(loadScene(gltf.string()));
  fs::current_path(cwd);
}

TEST(SceneLoader, NoMeshesLoadsAsBackgroundOnly) {
  const Scene s = load("no-meshes.gltf");
  expectConsistentStore(s);
  EXPECT_EQ(s.instances.size(), 0u);
  EXPECT_EQ(s.triangles.size(), 0u);
  EXPECT_EQ(s.positions.size(), 0u);
  EXPECT_TRUE(s.bounds.empty());
  EXPECT_EQ(s.stats.sceneIndex, 0);
  EXPECT_EQ(s.stats.nodes, 2u);
  EXPECT_EQ(s.stats.visitedNodes, 2u);
  EXPECT_FALSE(s.camera.has_value());

  // SPEC §2 default camera for empty bounds: a unit sphere at the origin.
  const CameraModel model = defaultCameraModel(s);
  const double distance = 1.0 / std::sin(22.5 * kPi / 180.0);
  EXPECT_EQ(model.projection, Projection::Perspective);
  EXPECT_NEAR(model.yfov, 45.0 * kPi / 180.0, 1e-15);
  expectVec3Near(glm::dvec3(model.worldFromCamera[3]), {0.0, 0.0, distance}, 1e-12, "eye");
  EXPECT_NEAR(model.znear, distance / 1000.0, 1e-15);
  EXPECT_TRUE(std::isinf(model.zfar));

  const Camera camera = makeCamera(s, {}, 64, 48);
  expectVec3Near(camera.eye(), {0.0, 0.0, distance}, 1e-12, "eye");
  expectVec3Near(camera.forward(), {0.0, 0.0, -1.0}, 1e-15, "forward");
  EXPECT_DOUBLE_EQ(camera.aspect, 64.0 / 48.0);
  EXPECT_EQ(camera.origin, "default");
}

TEST(SceneLoader, NoScenesWalksRootNodesInIndexOrder) {
  // Roots 1 (z 10) and 2 (z 20, child 0 at z 30 local): walk 1, 2, 0.
  const Scene s = load("no-scenes.gltf");
  expectConsistentStore(s);
  EXPECT_EQ(s.stats.sceneIndex, -1);
  EXPECT_EQ(s.stats.visitedNodes, 3u);
  ASSERT_EQ(s.instances.size(), 3u);
  const uint32_t nodes[] = {1, 2, 0};
  const float z[] = {10.0f, 20.0f, 50.0f};
  for (uint32_t i = 0; i < 3; ++i) {
    EXPECT_EQ(s.instances[i].node, nodes[i]) << "instance " << i;
    EXPECT_EQ(s.instances[i].mesh, 0u);
    EXPECT_EQ(positionsOf(s, i), (std::vector<glm::vec3>{{0, 0, z[i]}, {1, 0, z[i]}, {0, 1, z[i]}}))
        << "instance " << i;
    EXPECT_EQ(trianglesOf(s, i), std::vector<glm::uvec3>{glm::uvec3(0, 1, 2)});
  }
}

TEST(SceneLoader, PrimitiveWithoutPositionKeepsItsInstanceNumber) {
  const Scene s = load("no-position.gltf");
  expectConsistentStore(s);
  ASSERT_EQ(s.instances.size(), 2u);
  EXPECT_EQ(s.instances[0].primitive, 0u);
  EXPECT_EQ(s.instances[0].vertexCount, 0u);
  EXPECT_EQ(s.instances[0].triangleCount, 0u);
  EXPECT_EQ(s.instances[1].primitive, 1u);
  EXPECT_EQ(s.instances[1].vertexCount, 3u);
  EXPECT_EQ(s.instances[1].triangleCount, 1u);
  EXPECT_EQ(s.triangles.size(), 1u);
}

TEST(SceneLoader, SparseAccessorsSubstituteValues) {
  const Scene s = load("sparse-positions.gltf");
  expectConsistentStore(s);
  ASSERT_EQ(s.instances.size(), 2u);
  // Over a bufferView: vertex 2 (9, 9, 9) replaced by (0, 1, 0).
  EXPECT_EQ(positionsOf(s, 0), (std::vector<glm::vec3>{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}));
  // Without a bufferView: zeros, vertices 1 and 2 replaced.
  EXPECT_EQ(positionsOf(s, 1), (std::vector<glm::vec3>{{0, 0, 0}, {2, 0, 0}, {0, 2, 0}}));
}

TEST(SceneLoader, QuantizedNormalizedShortPositions) {
  // SHORT normalized (glTF: max(c / 32767, -1)), node scale 2; BYTE normals.
  const Scene s = load("quantized-positions.gltf");
  expectConsistentStore(s);
  ASSERT_EQ(s.instances.size(), 1u);
  const float z = float(2.0 * 16384.0 / 32767.0);
  EXPECT_EQ(positionsOf(s, 0), (std::vector<glm::vec3>{{0, 0, 0}, {2, 0, 0}, {0, -2, z}}));
  EXPECT_EQ(s.instances[0].normals, NormalSource::Authored);
  for (int v = 0; v < 3; ++v) EXPECT_EQ(s.normals[v], glm::vec3(0, 0, 1)) << "vertex " << v;
}

TEST(SceneLoader, DeepNodeChainDoesNotOverflowTheStack) {
  const Scene s = load("deep-chain.gltf");
  expectConsistentStore(s);
  EXPECT_EQ(s.stats.nodes, 10000u);
  EXPECT_EQ(s.stats.visitedNodes, 10000u);
  ASSERT_EQ(s.instances.size(), 1u);
  EXPECT_EQ(s.instances[0].node, 9999u);
  // Each of the 10000 nodes moves one unit along +x.
  EXPECT_EQ(positionsOf(s, 0), (std::vector<glm::vec3>{{10000, 0, 0}, {10001, 0, 0}, {10000, 1, 0}}));
}

TEST(SceneLoader, MirroredInstanceSwapsWinding) {
  const Scene s = load("mirrored.gltf");
  expectConsistentStore(s);
  ASSERT_EQ(s.instances.size(), 2u);
  EXPECT_FALSE(s.instances[0].mirrored);
  EXPECT_EQ(trianglesOf(s, 0), std::vector<glm::uvec3>{glm::uvec3(0, 1, 2)});
  EXPECT_TRUE(s.instances[1].mirrored);
  EXPECT_EQ(positionsOf(s, 1), (std::vector<glm::vec3>{{0, 0, 0}, {-1, 0, 0}, {0, 1, 0}}));
  // Second and third vertex swapped.
  EXPECT_EQ(trianglesOf(s, 1), std::vector<glm::uvec3>{glm::uvec3(0, 2, 1)});
  for (uint32_t i = 0; i < 2; ++i) {
    // CCW = front in world space: the face normal agrees with the authored
    // normal (0, 0, 1), which the mirror leaves unchanged (inverse transpose).
    EXPECT_EQ(faceNormal(s, i, 0), glm::dvec3(0, 0, 1)) << "instance " << i;
    EXPECT_EQ(s.instances[i].normals, NormalSource::Authored);
    for (uint32_t v = 0; v < 3; ++v)
      EXPECT_EQ(s.normals[s.instances[i].firstVertex + v], glm::vec3(0, 0, 1))
          << "instance " << i << " vertex " << v;
  }
}

TEST(SceneLoader, StripAndFanTriangleOrder) {
  const Scene s = load("strip-fan.gltf");
  expectConsistentStore(s);
  ASSERT_EQ(s.instances.size(), 2u);
  // Strip, 6 vertices: (i, i+1, i+2), odd i wound (i+1, i, i+2).
  EXPECT_EQ(s.instances[0].mode, 5);
  EXPECT_EQ(trianglesOf(s, 0), (std::vector<glm::uvec3>{{0, 1, 2}, {2, 1, 3}, {2, 3, 4}, {4, 3, 5}}));
  // Fan, 5 indices: (0, i+1, i+2).
  EXPECT_EQ(s.instances[1].mode, 6);
  EXPECT_EQ(trianglesOf(s, 1), (std::vector<glm::uvec3>{{0, 1, 2}, {0, 2, 3}, {0, 3, 4}}));
  // With that order every triangle of each primitive faces the same way.
  const double zSign[] = {-1.0, 1.0};
  for (uint32_t i = 0; i < 2; ++i)
    for (uint32_t t = 0; t < s.instances[i].triangleCount; ++t) {
      const glm::dvec3 n = faceNormal(s, i, t);
      EXPECT_EQ(n.x, 0.0);
      EXPECT_EQ(n.y, 0.0);
      EXPECT_EQ(n.z * zSign[i], 1.0) << "instance " << i << " triangle " << t;
    }

  // SPEC §2 default camera: looking down −Z at the centre of the bounding
  // sphere, from the distance at which the sphere fills yfov 45°.
  EXPECT_EQ(s.bounds.lo, glm::dvec3(-1, 0, 0));
  EXPECT_EQ(s.bounds.hi, glm::dvec3(2, 1, 0));
  const double radius = 0.5 * std::sqrt(10.0);
  const double distance = radius / std::sin(22.5 * kPi / 180.0);
  const Camera camera = makeCamera(s, {}, 200, 100);
  EXPECT_EQ(camera.projection, Projection::Perspective);
  EXPECT_NEAR(camera.yfov, 45.0 * kPi / 180.0, 1e-15);
  expectVec3Near(camera.eye(), {0.5, 0.5, distance}, 1e-12, "eye");
  expectVec3Near(camera.forward(), {0, 0, -1}, 1e-15, "forward");
  EXPECT_NEAR(camera.znear, distance / 1000.0, 1e-15);
  EXPECT_TRUE(std::isinf(camera.zfar));
  EXPECT_DOUBLE_EQ(camera.aspect, 2.0);
}

TEST(SceneLoader, TrsAndMatrixGiveTheSameWorldPositions) {
  const Scene s = load("trs-vs-matrix.gltf");
  expectConsistentStore(s);
  ASSERT_EQ(s.instances.size(), 2u);
  // T (1, 2, 3) · R (120° about (1, 1, 1): x → y → z → x) · S (2, 3, 4).
  const std::vector<glm::vec3> expected{{1, 4, 3}, {1, 2, 6}, {5, 2, 3}};
  EXPECT_EQ(positionsOf(s, 0), expected);
  EXPECT_EQ(positionsOf(s, 1), expected);
  EXPECT_FALSE(s.instances[0].mirrored);
  EXPECT_FALSE(s.instances[1].mirrored);
  // Normals by the inverse transpose: R · S⁻¹ · n, normalised.
  const glm::dvec3 n(0.6f, 0.8f, 0.0f);
  const glm::dvec3 scaled = n / glm::dvec3(2, 3, 4);
  const glm::dvec3 world = glm::normalize(glm::dvec3(scaled.z, scaled.x, scaled.y));
  for (uint32_t v = 0; v < 6; ++v)
    expectVec3Near(glm::dvec3(s.normals[v]), world, 1e-6, "normal " + std::to_string(v));
}

TEST(SceneLoader, DegenerateTrianglesAreCountedAndKept) {
  const Scene s = load("degenerate.gltf");
  expectConsistentStore(s);
  ASSERT_EQ(s.instances.size(), 1u);
  EXPECT_EQ(s.instances[0].triangleCount, 3u);
  EXPECT_EQ(s.instances[0].degenerateCount, 2u);
  EXPECT_EQ(trianglesOf(s, 0), (std::vector<glm::uvec3>{{0, 1, 2}, {0, 3, 4}, {1, 1, 2}}));
}

// The loader's error carries file, element and message separately.
void expectInputError(const std::string& name, const std::string& element, const std::string& message) {
  const std::string path = kMalformed + name;
  try {
    loadScene(path);
    ADD_FAILURE() << name << " loaded";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_EQ(e.element(), element) << e.what();
    EXPECT_EQ(e.message().rfind(message, 0), 0u) << e.what();
  }
}

TEST(SceneLoaderErrors, NameTheElement) {
  expectInputError("index-out-of-range.gltf", "accessor 3", "index 70000 out of range (24 vertices)");
  expectInputError("node-cycle.gltf", "node 0", "is its own ancestor");
  expectInputError("buffer-missing-file.gltf", "buffer 0", "File not found");
  expectInputError("image-garbage-png.gltf", "image 0", "");
  expectInputError("node-matrix-overflow.gltf", "node 0", "invalid JSON at line 30");
  expectInputError("glb-json-chunk-past-eof.glb", "GLB chunk 0", "length");
}

}  // namespace
}  // namespace rastray
