// KHR_texture_transform (issue 22 item 2, in part): the transform's math,
// the loader giving a transformed textureInfo a texture of its own (and
// honouring its texCoord override), and TextureSet sampling through it,
// the one function both renderers sample with.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <string>

#include "common/error.h"
#include "common/gltf/loader.h"
#include "common/gltf/writer.h"
#include "common/math_constants.h"
#include "common/scene.h"
#include "common/texture.h"
#include "tests/test_files.h"

namespace rastray {
namespace {

using json = nlohmann::json;

void expectNear(glm::vec2 actual, glm::vec2 expected, const char* what) {
  EXPECT_NEAR(actual.x, expected.x, 1e-6f) << what;
  EXPECT_NEAR(actual.y, expected.y, 1e-6f) << what;
}

TEST(TextureTransform, ScalesThenRotatesThenOffsets) {
  expectNear(TextureTransform().apply({0.3f, 0.7f}), {0.3f, 0.7f}, "identity");
  EXPECT_TRUE(TextureTransform({0.0, 0.0}, 0.0, {1.0, 1.0}).identity);
  // u' = cos·u + sin·v, v' = −sin·u + cos·v (glTF Sample Viewer, three.js).
  const TextureTransform quarter({0.0, 0.0}, kPi / 2, {1.0, 1.0});
  expectNear(quarter.apply({1.0f, 0.0f}), {0.0f, -1.0f}, "rotate u");
  expectNear(quarter.apply({0.0f, 1.0f}), {1.0f, 0.0f}, "rotate v");
  // T·R·S: scale (2, 1) first, then the rotation, then the offset.
  const TextureTransform all({0.5, 0.25}, kPi / 2, {2.0, 1.0});
  expectNear(all.apply({1.0f, 0.0f}), {0.5f, -1.75f}, "all");
  expectNear(all.applyLinear({1.0f, 0.0f}), {0.0f, -2.0f}, "derivative: no offset");
}

// A 4×4 texture whose texels are all different, on a quad with uv over
// [0, 1]², written by the glTF writer; the JSON is then edited.
json texturedQuadDocument(const std::string& path) {
  GltfScene s;
  GltfTexture t;
  t.width = t.height = 4;
  for (int i = 0; i < 16; ++i)
    t.rgb.insert(t.rgb.end(), {(unsigned char)(16 * i), (unsigned char)(255 - 16 * i), 40});
  t.minFilter = t.magFilter = 9728;  // NEAREST
  s.textures.push_back(t);
  GltfMaterial m;
  m.baseColorTexture = 0;
  s.materials.push_back(m);
  GltfMesh quad;
  quad.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  quad.indices = {0, 1, 2, 0, 2, 3};
  quad.texcoords = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
  s.meshes.push_back(quad);
  s.write(path);
  std::ifstream in(path);
  return json::parse(in);
}

Scene loadDocument(const json& doc, const std::string& path) {
  std::ofstream(path) << doc.dump();
  return loadScene(path);
}

TEST(TextureTransform, LoaderGivesTheTextureInfoATextureOfItsOwn) {
  const std::string path = test::scratchPath("quad.gltf");
  json doc = texturedQuadDocument(path);
  json& info = doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"];
  info["extensions"]["KHR_texture_transform"] = {
      {"offset", {0.25, 0.5}}, {"rotation", 0.3}, {"scale", {2, 3}}};
  doc["extensionsUsed"] = {"KHR_texture_transform"};
  doc["extensionsRequired"] = {"KHR_texture_transform"};
  const Scene s = loadDocument(doc, path);
  ASSERT_EQ(s.textures.size(), 2u);
  const int32_t t = s.materials[0].baseColorTexture;
  ASSERT_EQ(t, 1);
  EXPECT_EQ(s.textures[1].image, s.textures[0].image);
  EXPECT_TRUE(s.textures[0].transform.identity);
  const TextureTransform expected({0.25, 0.5}, 0.3, {2.0, 3.0});
  expectNear(s.textures[1].transform.apply({0.4f, 0.9f}), expected.apply({0.4f, 0.9f}), "loaded transform");
  for (const IgnoredFeature& f : s.ignored) EXPECT_NE(f.feature, "KHR_texture_transform") << f.describe();

  // Sampling the transformed texture at uv is sampling the plain one at
  // the transformed uv, and the footprint scales the level of detail. A
  // second material reads the plain texture, so both have chains.
  Scene both = s;
  both.materials.push_back(s.materials[0]);
  both.materials.back().baseColorTexture = 0;
  const TextureSet set(both);
  const glm::vec2 uv(0.3f, 0.6f);
  EXPECT_EQ(set.sample(t, uv, {}, TextureFilter::Nearest),
            set.sample(0, expected.apply(uv), {}, TextureFilter::Nearest));
  const TextureFootprint fp{{0.01f, 0.0f}, {0.0f, 0.01f}};
  EXPECT_NEAR(set.levelOfDetail(t, fp), set.levelOfDetail(0, fp) + std::log2(3.0f), 1e-4f);
  // The image's mip chain is shared, not built twice.
  EXPECT_EQ(&set.levels(t), &set.levels(0));

  // Without the extension the same file samples untransformed.
  info.erase("extensions");
  const Scene untransformed = loadDocument(doc, path);
  EXPECT_EQ(untransformed.textures.size(), 1u);
  EXPECT_EQ(untransformed.materials[0].baseColorTexture, 0);
}

TEST(TextureTransform, TexCoordOverrideSelectsTheSet) {
  const std::string path = test::scratchPath("quad.gltf");
  json doc = texturedQuadDocument(path);
  // TEXCOORD_1: the same accessor layout, another set of values.
  json& attributes = doc["meshes"][0]["primitives"][0]["attributes"];
  json accessor = doc["accessors"][attributes["TEXCOORD_0"].get<size_t>()];
  // Reuse the POSITION accessor's bytes read as VEC2 (x, y of each vertex).
  accessor["bufferView"] = doc["accessors"][attributes["POSITION"].get<size_t>()]["bufferView"];
  accessor.erase("min");
  accessor.erase("max");
  doc["bufferViews"].push_back(doc["bufferViews"][accessor["bufferView"].get<size_t>()]);
  doc["bufferViews"].back()["byteStride"] = 12;
  accessor["bufferView"] = doc["bufferViews"].size() - 1;
  doc["accessors"].push_back(accessor);
  attributes["TEXCOORD_1"] = doc["accessors"].size() - 1;
  json& info = doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"];
  info["extensions"]["KHR_texture_transform"] = {{"texCoord", 1}};
  const Scene s = loadDocument(doc, path);
  ASSERT_TRUE(s.instances[0].hasTexcoords);
  // TEXCOORD_1 holds the positions' x and y: vertex 1 is (1, -1).
  EXPECT_EQ(s.texcoords[s.instances[0].firstVertex + 1], glm::vec2(1.0f, -1.0f));
  // The override alone (no offset, rotation or scale) needs no texture of its own.
  EXPECT_EQ(s.materials[0].baseColorTexture, 0);
}

TEST(TextureTransform, MalformedTransformIsRefusedNamingTheTextureInfo) {
  const std::string path = test::scratchPath("quad.gltf");
  json doc = texturedQuadDocument(path);
  doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"]["KHR_texture_transform"] = {
      {"offset", {0.25}}};
  try {
    loadDocument(doc, path);
    ADD_FAILURE() << "loaded";
  } catch (const InputError& e) {
    EXPECT_EQ(e.element(), "material 0 pbrMetallicRoughness baseColorTexture KHR_texture_transform")
        << e.what();
    EXPECT_NE(e.message().find("\"offset\" has 1 entries, expected 2"), std::string::npos) << e.what();
  }
}

TEST(TextureTransform, AppliesToTheDataMapsTooWhichReadLinearly) {
  // tests/data/malformed/generate.py: normal, occlusion and metallic-
  // roughness textureInfos of one 1×1 image (128, 128, 255), each with the
  // transform offset (0.5, 0), rotation 0.5, scale (2, 2).
  const Scene s = loadScene(test::testDataPath("malformed/valid/material-maps-generated-tangents.gltf"));
  EXPECT_TRUE(s.ignored.empty()) << s.ignored[0].describe();
  const Material& m = s.materials[0];
  const TextureTransform expected({0.5, 0.0}, 0.5, {2.0, 2.0});
  const TextureSet set(s);
  for (const int32_t t : {m.normalTexture, m.occlusionTexture, m.metallicRoughnessTexture}) {
    ASSERT_GE(t, 0);
    EXPECT_TRUE(s.textures[size_t(t)].data);
    expectNear(s.textures[size_t(t)].transform.apply({0.4f, 0.9f}), expected.apply({0.4f, 0.9f}),
               "transform");
    // Linear, not sRGB-decoded: 128/255, not 0.216.
    const glm::vec4 texel = set.sample(t, {0.3f, 0.3f}, {}, TextureFilter::Nearest);
    EXPECT_NEAR(texel.r, 128.0f / 255.0f, 1e-6f);
    EXPECT_NEAR(texel.b, 1.0f, 1e-6f);
  }
  EXPECT_EQ(m.normalScale, 0.5f);
  EXPECT_EQ(m.occlusionStrength, 0.5f);
  // The three share the image's one linear chain.
  EXPECT_EQ(&set.levels(m.normalTexture), &set.levels(m.occlusionTexture));
}

}  // namespace
}  // namespace rastray
