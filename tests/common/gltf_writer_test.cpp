// The glTF writer's optional parts (normals, texcoords, a base colour
// texture embedded as PNG, an orthographic camera) read back through the
// loader value by value: the stability study's generated scenes rely on
// them arriving exactly as written.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/gltf/loader.h"
#include "common/gltf/writer.h"
#include "common/scene.h"
#include "tests/test_files.h"

namespace rastray {
namespace {

std::string tempPath(const std::string& name) { return test::scratchPath(name); }

GltfScene texturedQuad() {
  GltfScene s;
  GltfTexture t;
  t.width = 3;
  t.height = 2;
  for (int i = 0; i < t.width * t.height; ++i)
    t.rgb.insert(t.rgb.end(),
                 {(unsigned char)(40 * i), (unsigned char)(255 - 40 * i), (unsigned char)(7 * i)});
  t.minFilter = 9728;  // NEAREST
  t.wrapS = 33071;     // CLAMP_TO_EDGE
  s.textures.push_back(t);
  GltfMaterial m;
  m.baseColorTexture = 0;
  s.materials.push_back(m);
  GltfMesh quad;
  quad.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  quad.indices = {0, 1, 2, 0, 2, 3};
  quad.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
  quad.texcoords = {{0.0f, 1.0f}, {1.0f, 1.0f}, {1.0f, 0.0f}, {0.0f, 0.0f}};
  s.meshes.push_back(quad);
  GltfCamera c;
  c.orthographic = true;
  c.xmag = 2.5;
  c.ymag = 1.25;
  c.znear = 0.5;
  c.zfar = 7.0;
  c.eye = {0, 0, 3};
  s.camera = c;
  return s;
}

TEST(GltfWriter, NormalsTexcoordsTextureAndOrthographicCameraReadBackExactly) {
  const std::string path = tempPath("textured.gltf");
  const GltfScene written = texturedQuad();
  written.write(path);
  const Scene s = loadScene(path);
  std::remove(path.c_str());

  ASSERT_EQ(s.instances.size(), 1u);
  EXPECT_TRUE(s.instances[0].hasTexcoords);
  EXPECT_EQ(s.instances[0].normals, NormalSource::Authored);
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(s.texcoords[i], written.meshes[0].texcoords[i]);
    EXPECT_EQ(s.normals[i], glm::vec3(0, 0, 1));
  }
  ASSERT_EQ(s.materials.size(), 1u);
  ASSERT_EQ(s.materials[0].baseColorTexture, 0);
  const Texture& tex = s.textures.at(0);
  EXPECT_EQ(tex.sampler.minFilter, 9728);
  EXPECT_EQ(tex.sampler.magFilter, 9729);
  EXPECT_EQ(tex.sampler.wrapS, 33071);
  EXPECT_EQ(tex.sampler.wrapT, 10497);
  const TextureImage& image = s.images.at(size_t(tex.image));
  ASSERT_EQ(image.width, 3);
  ASSERT_EQ(image.height, 2);
  for (int i = 0; i < 6; ++i)
    for (int c = 0; c < 3; ++c)
      EXPECT_EQ(image.rgba8[size_t(4 * i + c)], written.textures[0].rgb[size_t(3 * i + c)]) << i << " " << c;

  ASSERT_TRUE(s.camera.has_value());
  EXPECT_EQ(s.camera->projection, Projection::Orthographic);
  EXPECT_EQ(s.camera->xmag, 2.5);
  EXPECT_EQ(s.camera->ymag, 1.25);
  EXPECT_EQ(s.camera->znear, 0.5);
  EXPECT_EQ(s.camera->zfar, 7.0);
  EXPECT_EQ(glm::dvec3(s.camera->worldFromCamera[3]), glm::dvec3(0, 0, 3));
}

TEST(GltfWriter, EmissiveFactorReadsBackExactly) {
  const std::string path = tempPath("emissive.gltf");
  GltfScene written = texturedQuad();
  written.materials[0].baseColorTexture = -1;
  written.materials[0].emissive = {0.1f, 1.0f, 1e-6f};  // float values, not decimal ones
  written.materials.push_back(GltfMaterial{});          // black: no emissiveFactor written
  written.meshes.push_back(written.meshes[0]);
  written.meshes[1].material = 1;
  written.write(path);
  const Scene s = loadScene(path);
  std::remove(path.c_str());
  ASSERT_EQ(s.materials.size(), 2u);
  EXPECT_EQ(s.materials[0].emissive, glm::vec3(0.1f, 1.0f, 1e-6f));
  EXPECT_EQ(s.materials[1].emissive, glm::vec3(0.0f));
}

// .glb: the same scene loads the same as its .gltf, the container is laid
// out as glTF 2.0 says (12-byte header, JSON then BIN chunk, each padded to 4
// bytes), and buffer 0 has no uri.
TEST(GltfWriter, GlbLoadsLikeTheGltf) {
  GltfScene written = texturedQuad();
  // Three triangles' worth of indices plus odd-sized texcoords: the BIN
  // chunk needs padding.
  written.meshes[0].positions.push_back({0.5f, 0.25f, 0.125f});
  written.meshes[0].normals.push_back({0, 0, 1});
  written.meshes[0].texcoords.push_back({0.5f, 0.5f});
  written.meshes[0].indices.insert(written.meshes[0].indices.end(), {0, 1, 4});
  GltfLight light;
  written.lights.push_back(light);
  const std::string gltfPath = tempPath("same.gltf"), glbPath = tempPath("same.glb");
  written.write(gltfPath);
  written.writeGlb(glbPath);
  const Scene a = loadScene(gltfPath), b = loadScene(glbPath);

  std::FILE* f = std::fopen(glbPath.c_str(), "rb");
  ASSERT_NE(f, nullptr);
  std::vector<unsigned char> bytes;
  for (int c; (c = std::fgetc(f)) != EOF;) bytes.push_back(static_cast<unsigned char>(c));
  std::fclose(f);
  std::remove(gltfPath.c_str());
  std::remove(glbPath.c_str());
  auto u32 = [&](size_t at) {
    return uint32_t(bytes[at]) | uint32_t(bytes[at + 1]) << 8 | uint32_t(bytes[at + 2]) << 16 |
           uint32_t(bytes[at + 3]) << 24;
  };
  ASSERT_GE(bytes.size(), 28u);
  EXPECT_EQ(u32(0), 0x46546C67u);
  EXPECT_EQ(u32(4), 2u);
  EXPECT_EQ(u32(8), bytes.size());
  const uint32_t jsonLength = u32(12);
  EXPECT_EQ(u32(16), 0x4E4F534Au);
  EXPECT_EQ(jsonLength % 4, 0u);
  const std::string json(bytes.begin() + 20, bytes.begin() + 20 + jsonLength);
  EXPECT_EQ(json.find("\"uri\":\"data:application"), std::string::npos);
  const size_t bin = 20 + jsonLength;
  EXPECT_EQ(u32(bin + 4), 0x004E4942u);
  EXPECT_EQ(u32(bin) % 4, 0u);
  EXPECT_EQ(bin + 8 + u32(bin), bytes.size());

  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.normals, b.normals);
  EXPECT_EQ(a.texcoords, b.texcoords);
  EXPECT_EQ(a.triangles, b.triangles);
  ASSERT_EQ(b.triangles.size(), 3u);
  EXPECT_EQ(a.lights.size(), b.lights.size());
  ASSERT_EQ(b.images.size(), 1u);
  EXPECT_EQ(a.images[0].rgba8, b.images[0].rgba8);
}

TEST(GltfWriter, RefusesWhatGltfCannotSay) {
  GltfScene s = texturedQuad();
  s.camera->zfar.reset();  // orthographic cameras have a far plane in glTF
  EXPECT_THROW(s.toJson(), std::runtime_error);
  s = texturedQuad();
  s.meshes[0].texcoords.pop_back();
  EXPECT_THROW(s.toJson(), std::runtime_error);
  s = texturedQuad();
  s.materials[0].baseColorTexture = 1;
  EXPECT_THROW(s.toJson(), std::runtime_error);
}

}  // namespace
}  // namespace rastray
