// Normal-map tangents (issue 22 item 2): the MikkTSpace-convention
// generator against hand-computed frames, the loader reading TANGENT (and
// refusing a bad one with one line), keeping tangents only where a normal
// map needs them, and moving them with the node's matrix.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <string>

#include "common/error.h"
#include "common/gltf/loader.h"
#include "common/gltf/tangents.h"
#include "common/gltf/writer.h"
#include "common/scene.h"
#include "tests/test_files.h"

namespace rastray {
namespace {

using json = nlohmann::json;

void expectTangent(const glm::dvec4& actual, const glm::dvec4& expected, const std::string& what) {
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(actual[k], expected[k], 1e-12) << what << " component " << k;
}

// The unit quad in z = 0 (normal +z), uv as an image maps onto it: u along
// +x, v down the image, so along −y.
struct Quad {
  std::vector<glm::dvec3> positions{{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  std::vector<glm::dvec3> normals{4, glm::dvec3(0, 0, 1)};
  std::vector<glm::dvec2> uvs{{0, 1}, {1, 1}, {1, 0}, {0, 0}};
  std::vector<glm::uvec3> triangles{{0, 1, 2}, {0, 2, 3}};
};

TEST(GenerateTangents, UvMappedQuadHasTangentAlongUAndGreenUp) {
  const Quad q;
  const auto t = generateTangents(q.positions, q.normals, q.uvs, q.triangles);
  ASSERT_EQ(t.size(), 6u);
  // By hand: T = +x (u grows along x); the uv area is negative (v runs
  // against y), so w = +1 and the bitangent cross(n, T)·w = +y: the normal
  // map's green (up the image, towards smaller v) points up the quad.
  for (size_t c = 0; c < t.size(); ++c) expectTangent(t[c], {1, 0, 0, 1}, "corner " + std::to_string(c));
}

TEST(GenerateTangents, RotatedUvsRotateTheTangent) {
  Quad q;
  // uv rotated a quarter turn: u = (1 − y)/2 grows along −y, v = (1 − x)/2
  // along −x. By hand: T = −y; e1 = (0, −1), e2 = (−1, −1), area −1, so
  // w = +1 and the bitangent cross(+z, −y) = +x points to smaller v.
  q.uvs = {{1, 1}, {1, 0}, {0, 0}, {0, 1}};
  const auto t = generateTangents(q.positions, q.normals, q.uvs, q.triangles);
  for (size_t c = 0; c < t.size(); ++c) expectTangent(t[c], {0, -1, 0, 1}, "corner " + std::to_string(c));
}

TEST(GenerateTangents, MirroredUvHalvesGetOppositeHandednessAndSplitAtTheSeam) {
  // Two quads side by side sharing the edge x = 0 (vertices 1 and 4 are
  // shared by index); the right one's uvs mirror the left one's in u, as a
  // symmetric model's halves share one half of a texture.
  const std::vector<glm::dvec3> p{{-1, -1, 0}, {0, -1, 0}, {-1, 1, 0}, {1, -1, 0}, {0, 1, 0}, {1, 1, 0}};
  const std::vector<glm::dvec3> n(6, glm::dvec3(0, 0, 1));
  // Left: u = x + 1 (0 at x = −1, 1 at the seam). Right: u = 1 − x (1 at the seam, 0 at x = 1).
  const std::vector<glm::dvec2> uv{{0, 1}, {1, 1}, {0, 0}, {0, 1}, {1, 0}, {0, 0}};
  const std::vector<glm::uvec3> tris{{0, 1, 4}, {0, 4, 2}, {1, 3, 5}, {1, 5, 4}};
  const auto t = generateTangents(p, n, uv, tris);
  // Left faces: T = +x, w = +1 (as the plain quad). Right faces: u grows
  // along −x, so T = −x, and the uv area flips sign: w = −1, giving the
  // same bitangent cross(n, −x)·(−1) = +y: green stays up on both halves.
  for (size_t c = 0; c < 6; ++c) expectTangent(t[c], {1, 0, 0, 1}, "left corner " + std::to_string(c));
  for (size_t c = 6; c < 12; ++c) expectTangent(t[c], {-1, 0, 0, -1}, "right corner " + std::to_string(c));
  // The seam's vertices 1 and 4 have one position, normal and uv on both
  // sides: only the orientation splits them (averaged, +x and −x cancel).
}

TEST(GenerateTangents, AngleWeightedAverageAtASharedVertex) {
  // Vertex 0 shared by triangle A (corner angle 90°, T = +x) and B (corner
  // angle 45°, T = +y), both with the same orientation. The average is
  // (90°·x + 45°·y) normalised = (2, 1, 0)/√5.
  const std::vector<glm::dvec3> p{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {1, -1, 0}};
  const std::vector<glm::dvec3> n(5, glm::dvec3(0, 0, 1));
  // A = (0, 1, 2): uv = (x, −y) there: T = +x, area < 0.
  // B = (0, 3, 4): angle at 0 between (0,−1) and (1,−1) is 45°; uv = (−y, −x)
  // there gives T = direction of growing u = −y... choose uv = (y, −x)?
  // u = y grows along +y: T = +y; v = −x; area sign: e1 = uv3 − uv0 = (−1, 0),
  // e2 = uv4 − uv0 = (−1, −1): area = (−1)(−1) − (−1)(0) = 1 > 0 — the other
  // orientation. Use v = x instead: e1 = (−1, 0), e2 = (−1, 1): area = −1.
  const std::vector<glm::dvec2> uv{{0, 0}, {1, 0}, {0, -1}, {-1, 0}, {-1, 1}};
  const std::vector<glm::uvec3> tris{{0, 1, 2}, {0, 3, 4}};
  const auto t = generateTangents(p, n, uv, tris);
  const double pi = std::acos(-1.0);
  const glm::dvec3 sum = (pi / 2) * glm::dvec3(1, 0, 0) + (pi / 4) * glm::dvec3(0, 1, 0);
  const glm::dvec3 expected = glm::normalize(sum);
  expectTangent(t[0], glm::dvec4(expected, 1), "A's corner at vertex 0");
  expectTangent(t[3], glm::dvec4(expected, 1), "B's corner at vertex 0");
  expectTangent(t[1], {1, 0, 0, 1}, "A's own corner");
  expectTangent(t[4], {0, 1, 0, 1}, "B's own corner");
}

TEST(GenerateTangents, TangentIsProjectedIntoTheVertexNormalsPlane) {
  Quad q;
  const glm::dvec3 tilted = glm::normalize(glm::dvec3(1, 0, 1));
  q.normals.assign(4, tilted);
  const auto t = generateTangents(q.positions, q.normals, q.uvs, q.triangles);
  const glm::dvec3 expected = glm::normalize(glm::dvec3(1, 0, -1));  // +x minus its part along n
  for (size_t c = 0; c < t.size(); ++c)
    expectTangent(t[c], glm::dvec4(expected, 1), "corner " + std::to_string(c));
}

TEST(GenerateTangents, DegenerateUvsGetAPerpendicularUnitTangent) {
  Quad q;
  q.uvs.assign(4, glm::dvec2(0.5));
  const auto t = generateTangents(q.positions, q.normals, q.uvs, q.triangles);
  for (const glm::dvec4& c : t) {
    EXPECT_NEAR(glm::length(glm::dvec3(c)), 1.0, 1e-12);
    EXPECT_NEAR(c.z, 0.0, 1e-12);
    EXPECT_EQ(c.w, 1.0);
  }
}

// A quad with a 2×2 normal map; a second quad without one.
GltfScene normalMappedScene(bool fileTangents) {
  GltfScene s;
  GltfTexture flat;
  flat.width = flat.height = 2;
  for (int i = 0; i < 4; ++i) flat.rgb.insert(flat.rgb.end(), {128, 128, 255});
  s.textures.push_back(flat);
  GltfMaterial mapped;
  mapped.normalTexture = 0;
  s.materials.push_back(mapped);
  s.materials.push_back(GltfMaterial{});
  GltfMesh quad;
  quad.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  quad.indices = {0, 1, 2, 0, 2, 3};
  quad.normals.assign(4, glm::vec3(0, 0, 1));
  quad.texcoords = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
  if (fileTangents) quad.tangents.assign(4, glm::vec4(0, 1, 0, -1));
  s.meshes.push_back(quad);
  quad.material = 1;
  quad.tangents.clear();
  quad.translation = {3, 0, 0};
  s.meshes.push_back(quad);
  return s;
}

Scene loadDocument(const json& doc, const std::string& path) {
  std::ofstream(path) << doc.dump();
  return loadScene(path);
}

json documentOf(const GltfScene& s, const std::string& path) {
  s.write(path);
  std::ifstream in(path);
  return json::parse(in);
}

TEST(LoadedTangents, OnlyNormalMappedInstancesCarryThem) {
  const std::string path = test::scratchPath("tangents.gltf");
  normalMappedScene(false).write(path);
  const Scene s = loadScene(path);
  ASSERT_EQ(s.instances.size(), 2u);
  EXPECT_EQ(s.instances[0].firstTangent, 0u);
  EXPECT_TRUE(s.instances[0].generatedTangents);
  EXPECT_EQ(s.instances[1].firstTangent, kNoId);
  EXPECT_EQ(s.tangents.size(), 6u);  // 3 corners × 2 triangles of the mapped quad only
  for (const glm::vec4& t : s.tangents) EXPECT_EQ(t, glm::vec4(1, 0, 0, 1));
  for (const IgnoredFeature& f : s.ignored)
    EXPECT_EQ(f.feature.find("normal"), std::string::npos) << f.describe();
}

TEST(LoadedTangents, FileTangentsAreReadAndFollowAMirroringNode) {
  const std::string path = test::scratchPath("tangents.gltf");
  json doc = documentOf(normalMappedScene(true), path);
  {
    const Scene s = loadDocument(doc, path);
    EXPECT_FALSE(s.instances[0].generatedTangents);
    for (size_t c = 0; c < 6; ++c) EXPECT_EQ(s.tangents[c], glm::vec4(0, 1, 0, -1)) << c;
  }
  // Scale (1, −1, 1) mirrors: the tangent (0, 1, 0) becomes (0, −1, 0) and
  // the handedness flips, so the bitangent cross(n, T)·w keeps its side.
  doc["nodes"][0]["scale"] = {1, -1, 1};
  const Scene s = loadDocument(doc, path);
  ASSERT_TRUE(s.instances[0].mirrored);
  for (size_t c = 0; c < 6; ++c) EXPECT_EQ(s.tangents[c], glm::vec4(0, -1, 0, 1)) << c;
}

void expectRefused(const json& doc, const std::string& path, const std::string& element,
                   const std::string& message) {
  try {
    loadDocument(doc, path);
    ADD_FAILURE() << "loaded; expected: " << element << ": " << message;
  } catch (const InputError& e) {
    EXPECT_EQ(e.element(), element) << e.what();
    EXPECT_NE(e.message().find(message), std::string::npos) << e.what();
  }
}

TEST(LoadedTangents, BadTangentAccessorIsRefusedNamingIt) {
  const std::string path = test::scratchPath("tangents.gltf");
  const json good = documentOf(normalMappedScene(true), path);
  const size_t accessor = good["meshes"][0]["primitives"][0]["attributes"]["TANGENT"].get<size_t>();
  const std::string element = "mesh 0 primitive 0 TANGENT (accessor " + std::to_string(accessor) + ")";
  json doc = good;
  doc["accessors"][accessor]["type"] = "VEC3";
  expectRefused(doc, path, element, "type VEC3 is not allowed here");
  doc = good;
  doc["accessors"][accessor]["count"] = 3;
  expectRefused(doc, path, element, "has 3 elements, POSITION 4");
  doc = good;
  doc["accessors"][accessor]["componentType"] = 5121;
  doc["accessors"][accessor]["normalized"] = true;
  expectRefused(doc, path, element, "componentType 5121 must be 5126");
  // A NaN component, written by the writer as it is.
  GltfScene nan = normalMappedScene(true);
  nan.meshes[0].tangents[2].y = std::nanf("");
  nan.write(path);
  try {
    loadScene(path);
    ADD_FAILURE() << "loaded a NaN tangent";
  } catch (const InputError& e) {
    EXPECT_EQ(e.element(), element) << e.what();
    EXPECT_NE(e.message().find("element 2 component 1 is NaN"), std::string::npos) << e.what();
  }
}

TEST(LoadedTangents, MorphDeltasMoveThemAndTheSkinTurnsThem) {
  // tests/data/malformed/generate.py: TANGENT (1, 0, 0, 1), a morph delta
  // (−1, 1, 0) at weight 1, one joint turned 90° about z (the joint matrix
  // itself, not its inverse transpose).
  const Scene s = loadScene(test::testDataPath("malformed/valid/normal-mapped-skinned-morphed.gltf"));
  ASSERT_EQ(s.instances.size(), 1u);
  EXPECT_TRUE(s.instances[0].skinned);
  EXPECT_TRUE(s.instances[0].morphed);
  ASSERT_EQ(s.tangents.size(), 6u);
  for (size_t c = 0; c < 6; ++c) {
    EXPECT_NEAR(s.tangents[c].x, -1.0f, 1e-6f) << c;
    EXPECT_NEAR(s.tangents[c].y, 0.0f, 1e-6f) << c;
    EXPECT_NEAR(s.tangents[c].z, 0.0f, 1e-6f) << c;
    EXPECT_EQ(s.tangents[c].w, 1.0f) << c;
  }
}

TEST(LoadedTangents, MapOnAnotherUvSetIsDroppedAndListed) {
  const std::string path = test::scratchPath("tangents.gltf");
  GltfScene scene = normalMappedScene(false);
  scene.materials[0].baseColorTexture = 0;
  json doc = documentOf(scene, path);
  doc["materials"][0]["normalTexture"]["texCoord"] = 1;
  const Scene s = loadDocument(doc, path);
  EXPECT_EQ(s.materials[0].normalTexture, -1);
  EXPECT_EQ(s.instances[0].firstTangent, kNoId);
  EXPECT_TRUE(s.tangents.empty());
  ASSERT_EQ(s.ignored.size(), 1u);
  EXPECT_EQ(s.ignored[0].describe(),
            "normal texture on another texCoord set than the base colour texture on 1 material");
}

}  // namespace
}  // namespace rastray
