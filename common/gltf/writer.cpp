#include "common/gltf/writer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "common/math_constants.h"
#include "common/oiio_module.h"

namespace rastray {

namespace {

std::string base64(const std::vector<unsigned char>& bytes) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const uint32_t b0 = bytes[i], b1 = i + 1 < bytes.size() ? bytes[i + 1] : 0,
                   b2 = i + 2 < bytes.size() ? bytes[i + 2] : 0;
    const uint32_t n = (b0 << 16) | (b1 << 8) | b2;
    out += table[(n >> 18) & 63];
    out += table[(n >> 12) & 63];
    out += i + 1 < bytes.size() ? table[(n >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? table[n & 63] : '=';
  }
  return out;
}

template <typename T>
void append(std::vector<unsigned char>* bytes, const T* data, size_t count) {
  const size_t at = bytes->size();
  bytes->resize(at + count * sizeof(T));
  std::memcpy(bytes->data() + at, data, count * sizeof(T));
}

// An 8-bit RGB PNG in memory (OpenImageIO, no file).
std::vector<unsigned char> encodePng(const GltfTexture& t) {
  if (t.width < 1 || t.height < 1 || t.rgb.size() != size_t(t.width) * size_t(t.height) * 3)
    throw std::runtime_error("gltf_writer: texture size does not match its pixels");
  return oiioModule().encodePng(t.width, t.height, 3, t.rgb.data());
}

}  // namespace

std::vector<double> lookAtNodeMatrix(const glm::dvec3& eye, const glm::dvec3& forward, glm::dvec3 up) {
  const glm::dvec3 f = glm::normalize(forward);
  if (glm::length(glm::cross(f, up)) < 1e-6)
    up = std::fabs(f.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 0, 1);
  const glm::dvec3 x = glm::normalize(glm::cross(f, up));
  const glm::dvec3 y = glm::cross(x, f);
  const glm::dvec3 z = -f;
  return {x.x, x.y, x.z, 0.0, y.x, y.y, y.z, 0.0, z.x, z.y, z.z, 0.0, eye.x, eye.y, eye.z, 1.0};
}

namespace {

// The document without its buffer; the buffer's bytes go to `bytes` (a
// data URI for .gltf, the BIN chunk for .glb).
nlohmann::json buildDocument(const GltfScene& scene, std::vector<unsigned char>& bytes) {
  using nlohmann::json;
  const auto& meshes = scene.meshes;
  const auto& materials = scene.materials;
  const auto& textures = scene.textures;
  const auto& camera = scene.camera;
  const auto& lights = scene.lights;
  json accessors = json::array(), views = json::array(), meshesJson = json::array(), nodes = json::array();
  json sceneNodes = json::array();
  // One float accessor over `count` elements of `components` floats.
  auto floatAccessor = [&](const float* data, size_t count, int components, const char* type, bool bounds) {
    const size_t offset = bytes.size();
    append(&bytes, data, count * size_t(components));
    views.push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", count * size_t(components) * 4}});
    json a = {{"bufferView", views.size() - 1}, {"componentType", 5126}, {"count", count}, {"type", type}};
    if (bounds) {
      std::vector<float> lo(size_t(components), INFINITY), hi(size_t(components), -INFINITY);
      for (size_t i = 0; i < count; ++i)
        for (int c = 0; c < components; ++c) {
          lo[size_t(c)] = std::min(lo[size_t(c)], data[i * size_t(components) + size_t(c)]);
          hi[size_t(c)] = std::max(hi[size_t(c)], data[i * size_t(components) + size_t(c)]);
        }
      a["min"] = lo;
      a["max"] = hi;
    }
    accessors.push_back(a);
    return accessors.size() - 1;
  };
  for (const GltfMesh& m : meshes) {
    if (m.positions.empty() || m.indices.empty()) throw std::runtime_error("gltf_writer: empty mesh");
    if ((!m.normals.empty() && m.normals.size() != m.positions.size()) ||
        (!m.texcoords.empty() && m.texcoords.size() != m.positions.size()))
      throw std::runtime_error("gltf_writer: normals or texcoords do not match the positions");
    json attributes = {{"POSITION", floatAccessor(&m.positions[0].x, m.positions.size(), 3, "VEC3", true)}};
    if (!m.normals.empty())
      attributes["NORMAL"] = floatAccessor(&m.normals[0].x, m.normals.size(), 3, "VEC3", false);
    if (!m.texcoords.empty())
      attributes["TEXCOORD_0"] = floatAccessor(&m.texcoords[0].x, m.texcoords.size(), 2, "VEC2", false);
    if (!m.tangents.empty()) {
      if (m.tangents.size() != m.positions.size())
        throw std::runtime_error("gltf_writer: tangents do not match the positions");
      attributes["TANGENT"] = floatAccessor(&m.tangents[0].x, m.tangents.size(), 4, "VEC4", false);
    }
    const size_t indexOffset = bytes.size();
    append(&bytes, m.indices.data(), m.indices.size());
    views.push_back({{"buffer", 0}, {"byteOffset", indexOffset}, {"byteLength", m.indices.size() * 4}});
    accessors.push_back({{"bufferView", views.size() - 1},
                         {"componentType", 5125},
                         {"count", m.indices.size()},
                         {"type", "SCALAR"}});
    meshesJson.push_back(
        {{"primitives",
          {{{"attributes", attributes}, {"indices", accessors.size() - 1}, {"material", m.material}}}}});
    json node = {{"mesh", meshesJson.size() - 1}};
    if (m.translation != glm::dvec3(0.0))
      node["translation"] = {m.translation.x, m.translation.y, m.translation.z};
    nodes.push_back(node);
    sceneNodes.push_back(nodes.size() - 1);
  }
  json materialsJson = json::array();
  bool transmission = false;
  for (const GltfMaterial& m : materials) {
    json j = {{"pbrMetallicRoughness",
               {{"baseColorFactor", {m.baseColor.r, m.baseColor.g, m.baseColor.b, m.baseColor.a}},
                {"metallicFactor", m.metallic},
                {"roughnessFactor", m.roughness}}},
              {"alphaMode", m.alphaMode},
              {"doubleSided", m.doubleSided}};
    if (m.alphaMode == "MASK") j["alphaCutoff"] = m.alphaCutoff;
    if (m.emissive != glm::vec3(0.0f)) j["emissiveFactor"] = {m.emissive.r, m.emissive.g, m.emissive.b};
    if (m.baseColorTexture >= 0) {
      if (size_t(m.baseColorTexture) >= textures.size())
        throw std::runtime_error("gltf_writer: material names a texture that does not exist");
      j["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", m.baseColorTexture}, {"texCoord", 0}};
    }
    for (const int texture : {m.normalTexture, m.occlusionTexture, m.metallicRoughnessTexture})
      if (texture >= 0 && size_t(texture) >= textures.size())
        throw std::runtime_error("gltf_writer: material names a texture that does not exist");
    if (m.normalTexture >= 0) j["normalTexture"] = {{"index", m.normalTexture}, {"scale", m.normalScale}};
    if (m.occlusionTexture >= 0)
      j["occlusionTexture"] = {{"index", m.occlusionTexture}, {"strength", m.occlusionStrength}};
    if (m.metallicRoughnessTexture >= 0)
      j["pbrMetallicRoughness"]["metallicRoughnessTexture"] = {{"index", m.metallicRoughnessTexture}};
    if (m.transmission > 0.0f) {
      transmission = true;
      j["extensions"] = {{"KHR_materials_transmission", {{"transmissionFactor", m.transmission}}},
                         {"KHR_materials_ior", {{"ior", m.ior}}}};
    }
    materialsJson.push_back(j);
  }
  json doc = {{"asset", {{"version", "2.0"}, {"generator", "rastray tests/app/gltf_writer"}}},
              {"scene", 0},
              {"materials", materialsJson},
              {"meshes", meshesJson},
              {"accessors", accessors},
              {"bufferViews", views}};
  if (!textures.empty()) {
    json images = json::array(), samplers = json::array(), texturesJson = json::array();
    for (const GltfTexture& t : textures) {
      images.push_back({{"mimeType", "image/png"}, {"uri", "data:image/png;base64," + base64(encodePng(t))}});
      samplers.push_back(
          {{"magFilter", t.magFilter}, {"minFilter", t.minFilter}, {"wrapS", t.wrapS}, {"wrapT", t.wrapT}});
      texturesJson.push_back({{"sampler", samplers.size() - 1}, {"source", images.size() - 1}});
    }
    doc["images"] = images;
    doc["samplers"] = samplers;
    doc["textures"] = texturesJson;
  }
  json used = json::array();
  if (transmission) used.insert(used.end(), {"KHR_materials_transmission", "KHR_materials_ior"});
  if (camera) {
    if (camera->orthographic) {
      if (!camera->zfar) throw std::runtime_error("gltf_writer: an orthographic camera needs zfar");
      json orthographic = {
          {"xmag", camera->xmag}, {"ymag", camera->ymag}, {"znear", camera->znear}, {"zfar", *camera->zfar}};
      doc["cameras"] = {{{"type", "orthographic"}, {"orthographic", orthographic}}};
    } else {
      json perspective = {{"yfov", camera->yfov}, {"znear", camera->znear}};
      if (camera->zfar) perspective["zfar"] = *camera->zfar;
      doc["cameras"] = {{{"type", "perspective"}, {"perspective", perspective}}};
    }
    nodes.push_back(
        {{"camera", 0}, {"matrix", lookAtNodeMatrix(camera->eye, camera->target - camera->eye, camera->up)}});
    sceneNodes.push_back(nodes.size() - 1);
  }
  if (!lights.empty()) {
    json lightsJson = json::array();
    for (size_t i = 0; i < lights.size(); ++i) {
      const GltfLight& l = lights[i];
      lightsJson.push_back({{"type", l.type}, {"intensity", l.intensity}});
      if (l.type == "spot")
        lightsJson.back()["spot"] = {{"innerConeAngle", l.innerConeAngle},
                                     {"outerConeAngle", l.outerConeAngle}};
      nodes.push_back({{"extensions", {{"KHR_lights_punctual", {{"light", i}}}}},
                       {"matrix", lookAtNodeMatrix(l.position, l.direction, glm::dvec3(0, 1, 0))}});
      sceneNodes.push_back(nodes.size() - 1);
    }
    doc["extensions"] = {{"KHR_lights_punctual", {{"lights", lightsJson}}}};
    used.push_back("KHR_lights_punctual");
  }
  if (!used.empty()) doc["extensionsUsed"] = used;
  doc["nodes"] = nodes;
  doc["scenes"] = {{{"nodes", sceneNodes}}};
  return doc;
}

void putU32(std::ostream& out, uint32_t v) {
  const unsigned char b[4] = {static_cast<unsigned char>(v), static_cast<unsigned char>(v >> 8),
                              static_cast<unsigned char>(v >> 16), static_cast<unsigned char>(v >> 24)};
  out.write(reinterpret_cast<const char*>(b), 4);
}

}  // namespace

std::string GltfScene::toJson() const {
  std::vector<unsigned char> bytes;
  nlohmann::json doc = buildDocument(*this, bytes);
  doc["buffers"] = {
      {{"byteLength", bytes.size()}, {"uri", "data:application/octet-stream;base64," + base64(bytes)}}};
  return doc.dump(1);
}

void GltfScene::write(const std::string& path) const {
  std::ofstream out(path, std::ios::binary);
  out << toJson();
  if (!out) throw std::runtime_error("cannot write " + path);
}

void GltfScene::writeGlb(const std::string& path) const {
  std::vector<unsigned char> bytes;
  nlohmann::json doc = buildDocument(*this, bytes);
  doc["buffers"] = {{{"byteLength", bytes.size()}}};  // no uri: the BIN chunk
  std::string text = doc.dump();
  // Chunks end on 4-byte boundaries: JSON padded with spaces, BIN with zeros.
  text.append((4 - text.size() % 4) % 4, ' ');
  const size_t binPadded = (bytes.size() + 3) / 4 * 4;
  const uint64_t total = 12 + 8 + uint64_t(text.size()) + 8 + uint64_t(binPadded);
  if (total > 0xFFFFFFFFull)
    throw std::runtime_error("gltf_writer: " + path + ": a .glb holds at most 4 GiB");
  std::ofstream out(path, std::ios::binary);
  putU32(out, 0x46546C67);  // "glTF"
  putU32(out, 2);
  putU32(out, uint32_t(total));
  putU32(out, uint32_t(text.size()));
  putU32(out, 0x4E4F534A);  // "JSON"
  out.write(text.data(), std::streamsize(text.size()));
  putU32(out, uint32_t(binPadded));
  putU32(out, 0x004E4942);  // "BIN\0"
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  const char zeros[3] = {0, 0, 0};
  out.write(zeros, std::streamsize(binPadded - bytes.size()));
  if (!out) throw std::runtime_error("cannot write " + path);
}

GltfMesh uvSphereMesh(glm::vec3 centre, float radius, int rings, int segments, int material) {
  GltfMesh m;
  m.material = material;
  for (int r = 0; r <= rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const double theta = kPi * r / rings, phi = 2.0 * kPi * s / segments;
      m.positions.push_back(centre + radius * glm::vec3(std::sin(theta) * std::cos(phi), std::cos(theta),
                                                        std::sin(theta) * std::sin(phi)));
    }
  auto at = [&](int r, int s) { return uint32_t(r * segments + (s % segments)); };
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const uint32_t a = at(r, s), b = at(r, s + 1), c = at(r + 1, s), d = at(r + 1, s + 1);
      if (r > 0) m.indices.insert(m.indices.end(), {a, b, c});
      if (r + 1 < rings) m.indices.insert(m.indices.end(), {b, d, c});
    }
  return m;
}

}  // namespace rastray
