#include "common/gltf_writer.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>

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

std::string GltfScene::toJson() const {
  using nlohmann::json;
  std::vector<unsigned char> bytes;
  json accessors = json::array(), views = json::array(), meshesJson = json::array(), nodes = json::array();
  json sceneNodes = json::array();
  for (const GltfMesh& m : meshes) {
    if (m.positions.empty() || m.indices.empty()) throw std::runtime_error("gltf_writer: empty mesh");
    glm::vec3 lo(INFINITY), hi(-INFINITY);
    for (const glm::vec3& p : m.positions) {
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
    const size_t positionOffset = bytes.size();
    append(&bytes, &m.positions[0].x, m.positions.size() * 3);
    views.push_back({{"buffer", 0}, {"byteOffset", positionOffset}, {"byteLength", m.positions.size() * 12}});
    accessors.push_back({{"bufferView", views.size() - 1},
                         {"componentType", 5126},
                         {"count", m.positions.size()},
                         {"type", "VEC3"},
                         {"min", {lo.x, lo.y, lo.z}},
                         {"max", {hi.x, hi.y, hi.z}}});
    const size_t indexOffset = bytes.size();
    append(&bytes, m.indices.data(), m.indices.size());
    views.push_back({{"buffer", 0}, {"byteOffset", indexOffset}, {"byteLength", m.indices.size() * 4}});
    accessors.push_back({{"bufferView", views.size() - 1},
                         {"componentType", 5125},
                         {"count", m.indices.size()},
                         {"type", "SCALAR"}});
    meshesJson.push_back({{"primitives",
                           {{{"attributes", {{"POSITION", accessors.size() - 2}}},
                             {"indices", accessors.size() - 1},
                             {"material", m.material}}}}});
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
    if (m.transmission > 0.0f) {
      transmission = true;
      j["extensions"] = {{"KHR_materials_transmission", {{"transmissionFactor", m.transmission}}},
                         {"KHR_materials_ior", {{"ior", m.ior}}}};
    }
    materialsJson.push_back(j);
  }
  json doc = {
      {"asset", {{"version", "2.0"}, {"generator", "rastray tests/app/gltf_writer"}}},
      {"scene", 0},
      {"materials", materialsJson},
      {"meshes", meshesJson},
      {"accessors", accessors},
      {"bufferViews", views},
      {"buffers",
       {{{"byteLength", bytes.size()}, {"uri", "data:application/octet-stream;base64," + base64(bytes)}}}}};
  json used = json::array();
  if (transmission) used.insert(used.end(), {"KHR_materials_transmission", "KHR_materials_ior"});
  if (camera) {
    json perspective = {{"yfov", camera->yfov}, {"znear", camera->znear}};
    if (camera->zfar) perspective["zfar"] = *camera->zfar;
    doc["cameras"] = {{{"type", "perspective"}, {"perspective", perspective}}};
    nodes.push_back(
        {{"camera", 0}, {"matrix", lookAtNodeMatrix(camera->eye, camera->target - camera->eye, camera->up)}});
    sceneNodes.push_back(nodes.size() - 1);
  }
  if (!lights.empty()) {
    json lightsJson = json::array();
    for (size_t i = 0; i < lights.size(); ++i) {
      const GltfLight& l = lights[i];
      lightsJson.push_back({{"type", l.type}, {"intensity", l.intensity}});
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
  return doc.dump(1);
}

void GltfScene::write(const std::string& path) const {
  std::ofstream out(path, std::ios::binary);
  out << toJson();
  if (!out) throw std::runtime_error("cannot write " + path);
}

}  // namespace rastray
