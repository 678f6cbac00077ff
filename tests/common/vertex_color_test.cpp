// COLOR_0, the emissive texture and the list of ignored features: what the
// loader reads (from glTF documents written here), how makeSurfacePoint
// interpolates the vertex colour, how the shader multiplies it into the
// base colour and coverage, and how the emissive texture is looked up.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/analysis.h"
#include "common/error.h"
#include "common/gltf/loader.h"
#include "common/image.h"
#include "common/scene.h"
#include "common/shading.h"
#include "common/surface.h"
#include "tests/test_files.h"

namespace rastray {
namespace {

using json = nlohmann::json;

std::string base64(const std::vector<uint8_t>& bytes) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const uint32_t n = uint32_t(bytes[i]) << 16 | (i + 1 < bytes.size() ? uint32_t(bytes[i + 1]) << 8 : 0u) |
                       (i + 2 < bytes.size() ? uint32_t(bytes[i + 2]) : 0u);
    out += table[n >> 18 & 63];
    out += table[n >> 12 & 63];
    out += i + 1 < bytes.size() ? table[n >> 6 & 63] : '=';
    out += i + 2 < bytes.size() ? table[n & 63] : '=';
  }
  return out;
}

// A glTF document with one embedded buffer, built accessor by accessor.
class GltfDoc {
 public:
  GltfDoc() {
    doc_ = {{"asset", {{"version", "2.0"}}},
            {"scene", 0},
            {"scenes", {{{"nodes", json::array()}}}},
            {"nodes", json::array()},
            {"meshes", json::array()},
            {"accessors", json::array()},
            {"bufferViews", json::array()}};
  }
  template <typename T>
  int accessor(const std::vector<T>& values, int componentType, const char* type, bool normalized = false) {
    while (data_.size() % 4) data_.push_back(0);
    const size_t components = std::string(type) == "VEC2" ? 2 : std::string(type) == "VEC3" ? 3 : 4;
    doc_["bufferViews"].push_back(
        {{"buffer", 0}, {"byteOffset", data_.size()}, {"byteLength", values.size() * sizeof(T)}});
    const size_t at = data_.size();
    data_.resize(at + values.size() * sizeof(T));
    std::memcpy(data_.data() + at, values.data(), values.size() * sizeof(T));
    json a = {{"bufferView", doc_["bufferViews"].size() - 1},
              {"componentType", componentType},
              {"count", values.size() / components},
              {"type", type}};
    if (normalized) a["normalized"] = true;
    doc_["accessors"].push_back(a);
    return int(doc_["accessors"].size() - 1);
  }
  // One triangle at z = −1 (one node, one mesh); `color` (COLOR_0
  // accessor) may be −1.
  void triangle(int color, int material = -1) {
    const int pos = accessor(std::vector<float>{0, 0, -1, 1, 0, -1, 0, 1, -1}, 5126, "VEC3");
    json prim = {{"attributes", {{"POSITION", pos}}}};
    if (color >= 0) prim["attributes"]["COLOR_0"] = color;
    if (material >= 0) prim["material"] = material;
    doc_["meshes"].push_back({{"primitives", {prim}}});
    doc_["nodes"].push_back({{"mesh", doc_["meshes"].size() - 1}});
    doc_["scenes"][0]["nodes"].push_back(doc_["nodes"].size() - 1);
  }
  json& doc() { return doc_; }
  Scene load(const std::string& name) {
    while (data_.size() % 4) data_.push_back(0);
    json d = doc_;
    if (!data_.empty())
      d["buffers"] = {
          {{"byteLength", data_.size()}, {"uri", "data:application/octet-stream;base64," + base64(data_)}}};
    const std::string path = test::scratchPath("vertex_color_test_" + name + ".gltf");
    std::ofstream(path) << d.dump();
    return loadScene(path);
  }

 private:
  json doc_;
  std::vector<uint8_t> data_;
};

void expectColor(const glm::vec4& got, const glm::vec4& want, const std::string& what) {
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(got[k], want[k], 1e-6f) << what << " component " << k;
}

TEST(VertexColors, LoaderReadsColor0InEachComponentType) {
  GltfDoc g;
  g.triangle(-1);  // no COLOR_0 first: back-filled with white
  g.triangle(g.accessor(std::vector<float>{1, 0, 0, 0, 1, 0, 0.25f, 0.5f, 1}, 5126, "VEC3"));
  g.triangle(g.accessor(std::vector<float>{1, 0, 0, 0.5f, 0, 1, 0, 1, 0, 0, 1, 0.25f}, 5126, "VEC4"));
  g.triangle(
      g.accessor(std::vector<uint8_t>{255, 0, 0, 51, 0, 255, 0, 102, 0, 0, 255, 255}, 5121, "VEC4", true));
  g.triangle(g.accessor(std::vector<uint16_t>{65535, 0, 0, 0, 65535, 0, 0, 0, 13107}, 5123, "VEC3", true));
  g.triangle(-1);  // and after
  const Scene s = g.load("types");
  ASSERT_EQ(s.instances.size(), 6u);
  ASSERT_EQ(s.colors.size(), s.positions.size());
  const std::vector<std::vector<glm::vec4>> want = {
      {glm::vec4(1), glm::vec4(1), glm::vec4(1)},        {{1, 0, 0, 1}, {0, 1, 0, 1}, {0.25f, 0.5f, 1, 1}},
      {{1, 0, 0, 0.5f}, {0, 1, 0, 1}, {0, 0, 1, 0.25f}}, {{1, 0, 0, 0.2f}, {0, 1, 0, 0.4f}, {0, 0, 1, 1}},
      {{1, 0, 0, 1}, {0, 1, 0, 1}, {0, 0, 0.2f, 1}},     {glm::vec4(1), glm::vec4(1), glm::vec4(1)},
  };
  for (uint32_t i = 0; i < 6; ++i) {
    EXPECT_EQ(s.instances[i].hasColors, i >= 1 && i <= 4) << "instance " << i;
    for (uint32_t v = 0; v < 3; ++v)
      expectColor(s.colors[s.instances[i].firstVertex + v], want[i][v],
                  "instance " + std::to_string(i) + " vertex " + std::to_string(v));
  }
}

TEST(VertexColors, NoColor0LeavesTheColourStoreEmpty) {
  GltfDoc g;
  g.triangle(-1);
  EXPECT_TRUE(g.load("none").colors.empty());
}

TEST(VertexColors, IntegerColoursMustBeNormalized) {
  GltfDoc g;
  g.triangle(g.accessor(std::vector<uint8_t>{255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255}, 5121, "VEC4"));
  try {
    g.load("unnormalized");
    FAIL() << "non-normalized unsigned byte COLOR_0 was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("COLOR_0"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("normalized"), std::string::npos) << e.what();
  }
}

// One triangle in the z = 0 plane facing +Z with per-vertex colours.
Scene colouredTriangle(const Material& m, const std::vector<glm::vec4>& colors) {
  Scene s;
  s.positions = {{-1, -1, 0}, {1, -1, 0}, {0, 1, 0}};
  s.normals = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  s.texcoords = {{0, 0}, {1, 0}, {0, 1}};
  s.colors = colors;
  s.triangles = {{0, 1, 2}};
  Instance inst;
  inst.vertexCount = 3;
  inst.triangleCount = 1;
  inst.hasColors = !colors.empty();
  inst.hasTexcoords = true;
  s.instances.push_back(inst);
  s.materials.push_back(m);
  s.bounds.extend({-1, -1, 0});
  s.bounds.extend({1, 1, 0});
  return s;
}

SurfacePoint pointAt(const Scene& s, float b1, float b2) {
  SampleHit hit;
  hit.instance = 0;
  hit.triangle = 0;
  hit.b1 = b1;
  hit.b2 = b2;
  return makeSurfacePoint(s, hit);
}

TEST(VertexColors, SurfacePointInterpolatesWithTheBarycentrics) {
  const Scene s = colouredTriangle(Material{}, {{1, 0, 0, 1}, {0, 1, 0, 0.5f}, {0, 0, 1, 0}});
  expectColor(pointAt(s, 0.0f, 0.0f).color, {1, 0, 0, 1}, "vertex 0");
  expectColor(pointAt(s, 0.25f, 0.5f).color, {0.25f, 0.25f, 0.5f, 0.375f}, "(0.25, 0.5)");
  const Scene plain = colouredTriangle(Material{}, {});
  expectColor(pointAt(plain, 0.25f, 0.5f).color, glm::vec4(1.0f), "no COLOR_0");
}

TEST(VertexColors, MultiplyIntoBaseColourAndCoverage) {
  Material m;
  m.metallic = 0.0f;
  m.baseColorFactor = {0.5f, 1.0f, 1.0f, 1.0f};
  m.alphaMode = AlphaMode::Mask;
  const Scene s = colouredTriangle(m, {{1, 1, 1, 0}, {1, 1, 1, 1}, {1, 0, 1, 1}});
  const Camera cam = makeCamera(s, {}, 8, 8);
  const Shader shader(s, analyzeScene(s), cam, {}, nullptr, nullptr);
  const SurfacePoint p = pointAt(s, 0.25f, 0.5f);  // colour (1, 0.5, 1, 0.75)
  expectColor(shader.baseColor(p, {}), {0.5f, 0.5f, 1.0f, 0.75f}, "factor × COLOR_0");
  EXPECT_NEAR(shader.coverageAlpha(p, {}), 0.75f, 1e-6f);
  EXPECT_NEAR(shader.coverageAlpha(pointAt(s, 0.0f, 0.0f), {}), 0.0f, 1e-6f);  // vertex 0: alpha 0
  // The eye light sees the base colour (n·d = 1).
  const glm::vec4 c = shader.shade(p, {0, 0, -1}, {});
  EXPECT_NEAR(c.r, 0.5f, 1e-6f);
  EXPECT_NEAR(c.g, 0.5f, 1e-6f);
  EXPECT_NEAR(c.b, 1.0f, 1e-6f);
}

TEST(VertexColors, BlendShadowTransmittanceUsesVertexAlpha) {
  Material m;
  m.metallic = 0.0f;
  m.alphaMode = AlphaMode::Blend;
  const Scene s = colouredTriangle(m, {{1, 1, 1, 0.2f}, {1, 1, 1, 0.2f}, {1, 1, 1, 0.2f}});
  const Camera cam = makeCamera(s, {}, 8, 8);
  const Shader shader(s, analyzeScene(s), cam, {}, nullptr, nullptr);
  EXPECT_NEAR(shader.shadowTransmittance(pointAt(s, 0.3f, 0.3f)).g, 0.8f, 1e-6f);
  EXPECT_NEAR(shader.shade(pointAt(s, 0.3f, 0.3f), {0, 0, -1}, {}).a, 0.2f, 1e-6f);
}

// A 2×2 texture: row 0 (top, v = 0) red, green; row 1 blue, white.
void addTexture(Scene& s) {
  TextureImage img;
  img.width = img.height = 2;
  img.rgba8 = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255};
  s.images.push_back(img);
  Texture t;
  t.image = 0;
  t.sampler.magFilter = t.sampler.minFilter = 9728;  // NEAREST
  s.textures.push_back(t);
}

TEST(EmissiveTexture, MultipliesTheEmissiveFactor) {
  Material m;
  m.metallic = 0.0f;
  m.baseColorFactor = {0, 0, 0, 1};
  m.emissive = {2.0f, 1.0f, 0.5f};
  m.emissiveTexture = 0;
  Scene s = colouredTriangle(m, {});
  addTexture(s);
  const SceneAnalysis analysis = analyzeScene(s);
  ASSERT_TRUE(analysis.textures) << "an emissive texture alone must switch textures on";
  const Camera cam = makeCamera(s, {}, 8, 8);
  const Shader shader(s, analysis, cam, {}, nullptr, nullptr);
  // uv = b1·(1, 0) + b2·(0, 1).
  const glm::vec3 green = shader.emission(pointAt(s, 0.8f, 0.1f), {});  // uv (0.8, 0.1): texel (1, 0)
  EXPECT_NEAR(green.r, 0.0f, 1e-6f);
  EXPECT_NEAR(green.g, 1.0f, 1e-6f);
  EXPECT_NEAR(green.b, 0.0f, 1e-6f);
  const glm::vec3 blue = shader.emission(pointAt(s, 0.1f, 0.8f), {});  // texel (0, 1)
  EXPECT_NEAR(blue.b, 0.5f, 1e-6f);
  EXPECT_NEAR(blue.r + blue.g, 0.0f, 1e-6f);
  // shade() adds it: a black base colour shows the emission alone.
  const glm::vec4 c = shader.shade(pointAt(s, 0.1f, 0.1f), {0, 0, -1}, {});  // texel (0, 0): red
  EXPECT_NEAR(c.r, 2.0f, 1e-6f);
  EXPECT_NEAR(c.g, 0.0f, 1e-6f);
}

TEST(EmissiveTexture, LoadedWithTheBaseColourUvSet) {
  GltfDoc g;
  writePng(test::scratchPath("vertex_color_test_1x1.png"), FlatImage(1, 1));
  g.doc()["images"] = {{{"uri", "vertex_color_test_1x1.png"}}};
  g.doc()["textures"] = {{{"source", 0}}};
  g.doc()["materials"] = {{{"emissiveFactor", {1, 1, 1}}, {"emissiveTexture", {{"index", 0}}}},
                          {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}},
                           {"emissiveTexture", {{"index", 0}, {"texCoord", 1}}}}};
  g.triangle(-1, 0);
  const Scene s = g.load("emissive");
  EXPECT_EQ(s.materials[0].emissiveTexture, 0);
  EXPECT_EQ(s.materials[1].emissiveTexture, -1);
  ASSERT_EQ(s.ignored.size(), 1u);
  EXPECT_EQ(s.ignored[0].describe(),
            "emissive texture on another texCoord set than the base colour texture on 1 material");
}

TEST(IgnoredFeatures, ListedWithTheirCounts) {
  // An extension on textureInfos that rastray does not implement (a made-up
  // vendor name: KHR_texture_transform, the real one, is implemented now),
  // and normal, occlusion and metallic-roughness maps (rendered now) whose
  // texture has no image: listed per textureInfo, their factors apply alone.
  GltfDoc g;
  const json transform = {{"EXT_vendor_texture_info", {{"scale", {2, 2}}}}};
  g.doc()["textures"] = {json::object()};  // no source: not decodable
  g.doc()["materials"] = {
      {{"occlusionTexture", {{"index", 0}}},
       {"normalTexture", {{"index", 0}, {"extensions", transform}}},
       {"pbrMetallicRoughness", {{"metallicRoughnessTexture", {{"index", 0}, {"extensions", transform}}}}}},
      {{"occlusionTexture", {{"index", 0}}}, {"extensions", {{"KHR_materials_volume", json::object()}}}},
      {{"occlusionTexture", {{"index", 0}}}}};
  g.doc()["extensionsUsed"] = {"EXT_vendor_texture_info", "KHR_materials_volume"};
  g.doc()["animations"] = {{{"channels", json::array()}, {"samplers", json::array()}}};
  g.triangle(-1, 0);
  const Scene s = g.load("ignored");
  std::vector<std::string> got;
  for (const IgnoredFeature& f : s.ignored) got.push_back(f.describe());
  const std::vector<std::string> want = {"texture without a decodable image on 5 textureInfos",
                                         "EXT_vendor_texture_info on 2 textureInfos",
                                         "KHR_materials_volume on 1 material"};
  EXPECT_EQ(got, want);
}

TEST(IgnoredFeatures, NothingListedForWhatIsRendered) {
  GltfDoc g;
  g.doc()["materials"] = {{{"emissiveFactor", {1, 0, 0}},
                           {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 2}}}}}}};
  g.doc()["extensionsUsed"] = {"KHR_materials_emissive_strength"};
  g.triangle(g.accessor(std::vector<float>{1, 0, 0, 0, 1, 0, 0, 0, 1}, 5126, "VEC3"), 0);
  EXPECT_TRUE(g.load("clean").ignored.empty());
}

}  // namespace
}  // namespace rastray
