// glTF 2.0 → the flattened scene of common/scene.h.
//
// Three steps, each refusing bad input with the element named:
// 1. read the file; for .glb, check the container (header, chunk lengths);
// 2. parse the JSON and check its structure (check.h): types,
//    references, byte ranges;
// 3. let tinygltf load the resources (buffers from data URIs, external
//    files or the BIN chunk; images decoded by stb), then walk the scene
//    from the checked JSON, reading accessors with bounds already proven
//    and rejecting NaN/Inf data.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <tiny_gltf.h>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <nlohmann/json.hpp>

#include "common/error.h"
#include "common/gltf/check.h"
#include "common/gltf/loader.h"
#include "common/scene.h"

namespace rastray {

namespace {

using json = nlohmann::json;

constexpr double kPi = 3.14159265358979323846;
constexpr uint32_t kGlbMagic = 0x46546C67;   // "glTF"
constexpr uint32_t kChunkJson = 0x4E4F534A;  // "JSON"
constexpr uint32_t kChunkBin = 0x004E4942;   // "BIN\0"

uint32_t readU32(const std::vector<uint8_t>& bytes, size_t offset) {
  uint32_t v;
  std::memcpy(&v, bytes.data() + offset, 4);
  return v;  // glTF is little-endian, as is every platform we build for
}

std::string firstLine(const std::string& text) {
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line))
    if (!line.empty()) return line;
  return "unknown error";
}

// Keeps a message from tinygltf readable on one line: data URIs can be
// megabytes long.
std::string shortened(std::string text) {
  constexpr size_t kMaxLength = 200;
  if (text.size() > kMaxLength) text = text.substr(0, kMaxLength) + "...";
  return text;
}

// The glTF top-level arrays whose entries messages name as elements.
constexpr const char* kElementArrays[] = {"accessors", "animations", "buffers", "bufferViews", "cameras",
                                          "images",    "materials",  "meshes",  "nodes",       "samplers",
                                          "scenes",    "skins",      "textures"};

// "nodes" -> "node"; empty for a key that is not one of kElementArrays.
std::string singular(const std::string& key) {
  for (const char* plural : kElementArrays)
    if (key == plural) return key == "meshes" ? "mesh" : key.substr(0, key.size() - 1);
  return "";
}

// A real glTF nests about ten levels (material > extensions > texture info
// > extensions > ...); tinygltf copies "extras" and "extensions" with a
// recursive function, so a deeper document could overflow the stack.
constexpr size_t kMaxJsonDepth = 64;

// nlohmann's DOM parser, plus where it is in the document (for messages
// about syntax errors and numbers that overflow a double, which have no
// element yet) and a nesting limit.
class TrackingJsonParser : public nlohmann::detail::json_sax_dom_parser<json> {
  using Base = nlohmann::detail::json_sax_dom_parser<json>;

 public:
  TrackingJsonParser(json& document, const std::string& path, const std::string& text)
      : Base(document, true), path_(path), text_(text) {}

  bool null() { return value(), Base::null(); }
  bool boolean(bool v) { return value(), Base::boolean(v); }
  bool number_integer(json::number_integer_t v) { return value(), Base::number_integer(v); }
  bool number_unsigned(json::number_unsigned_t v) { return value(), Base::number_unsigned(v); }
  bool number_float(json::number_float_t v, const std::string& s) {
    return value(), Base::number_float(v, s);
  }
  bool string(std::string& v) { return value(), Base::string(v); }
  bool binary(json::binary_t& v) { return value(), Base::binary(v); }
  bool start_object(size_t n) { return open(false), Base::start_object(n); }
  bool key(std::string& k) {
    frames_.back().key = k;
    return Base::key(k);
  }
  bool end_object() { return frames_.pop_back(), Base::end_object(); }
  bool start_array(size_t n) { return open(true), Base::start_array(n); }
  bool end_array() { return frames_.pop_back(), Base::end_array(); }

  template <class Exception>
  bool parse_error(size_t position, const std::string&, const Exception& ex) {
    // ex.what(): "[json.exception.KIND.ID] [parse error at line L, column C: ]DETAIL".
    std::string detail = ex.what();
    size_t at = detail.find("] ");
    if (at != std::string::npos) detail.erase(0, at + 2);
    if (detail.rfind("parse error", 0) == 0 && (at = detail.find(": ")) != std::string::npos)
      detail.erase(0, at + 2);
    // Line and column as nlohmann counts them: `position` characters read.
    size_t line = 1, column = 0;
    for (size_t i = 0; i < position && i < text_.size(); ++i) {
      column = text_[i] == '\n' ? 0 : column + 1;
      line += text_[i] == '\n';
    }
    throw InputError(path_, element(),
                     "invalid JSON at line " + std::to_string(line) + ", column " + std::to_string(column) +
                         where() + ": " + detail);
  }

 private:
  struct Frame {
    bool isArray = false;
    std::string key;   // objects: the last key read
    size_t count = 0;  // arrays: elements begun so far
  };

  void value() {
    if (!frames_.empty() && frames_.back().isArray) ++frames_.back().count;
  }
  void open(bool isArray) {
    value();
    if (frames_.size() >= kMaxJsonDepth)
      throw InputError(path_, element(),
                       "JSON nesting is deeper than " + std::to_string(kMaxJsonDepth) + " levels");
    frames_.push_back({isArray, "", 0});
  }
  // Position of frame i's current member: a key, or the index of the
  // element begun last (the next one, for the innermost array).
  std::string step(size_t i) const {
    const Frame& f = frames_[i];
    if (!f.isArray) return f.key;
    return std::to_string(i + 1 == frames_.size() ? f.count : f.count - 1);
  }
  // Whether the path starts in an entry of a glTF array ("nodes"[3]).
  bool inArrayEntry() const {
    return frames_.size() >= 2 && frames_[1].isArray && !singular(frames_[0].key).empty();
  }
  // The glTF element: "node 3" for the root's "nodes"[3], else the top-level key.
  std::string element() const {
    if (frames_.empty() || frames_[0].isArray) return "";
    if (inArrayEntry()) return singular(frames_[0].key) + " " + step(1);
    return frames_[0].key;
  }
  // The rest of the path inside the element, e.g. ' ("matrix"[12])'.
  std::string where() const {
    std::string s;
    for (size_t i = inArrayEntry() ? 2 : 1; i < frames_.size(); ++i)
      s += frames_[i].isArray ? "[" + step(i) + "]" : (s.empty() ? "" : ".") + ("\"" + step(i) + "\"");
    return s.empty() ? s : " (" + s + ")";
  }

  const std::string& path_;
  const std::string& text_;
  std::vector<Frame> frames_;
};

// tinygltf's default ExpandFilePath is a no-op on modern versions; ours
// states it: URIs are file names relative to the glTF file, nothing more.
std::string expandNothing(const std::string& path, void*) { return path; }

// Only regular files count as found: tinygltf would take the seek size of
// a directory (2^63 - 1 on some file systems) as its length.
bool isRegularFile(const std::string& path, void*) {
  std::error_code ec;
  return std::filesystem::is_regular_file(path, ec);
}

class SceneBuilder {
 public:
  SceneBuilder(const std::string& path, const json& doc, const tinygltf::Model& model)
      : path_(path), doc_(doc), model_(model) {}

  Scene build();

 private:
  [[noreturn]] void fail(const std::string& element, const std::string& message) const {
    throw InputError(path_, element, message);
  }
  const json& array(const char* key) const {
    static const json empty = json::array();
    auto it = doc_.find(key);
    return it == doc_.end() ? empty : *it;
  }
  template <typename T>
  T get(const json& obj, const char* key, T fallback) const {
    auto it = obj.find(key);
    return it == obj.end() ? fallback : it->get<T>();
  }

  glm::dmat4 localMatrix(size_t node) const;
  void checkNodeGraph(std::vector<int64_t>& parent) const;
  std::vector<size_t> rootNodes(const std::vector<int64_t>& parent);
  void walk(const std::vector<size_t>& roots);
  void addPrimitive(size_t node, size_t mesh, size_t primitive, const glm::dmat4& world);
  void addCamera(size_t node, const glm::dmat4& world);
  void addLight(size_t node, const glm::dmat4& world);
  void loadMaterials();
  void loadTextures();
  // Records one more occurrence of a feature nothing renders (Scene::ignored).
  void noteIgnored(const std::string& feature, const std::string& unit);
  void noteIgnoredFeatures();
  void noteIgnoredExtensions(const json& value, std::vector<std::string>& path);
  // The texture a textureInfo names, or -1 when its texture has no image
  // we could decode (e.g. only a KTX2 source through an extension).
  int32_t decodableTexture(const json& textureInfo);
  std::vector<glm::vec4> readColors(const json& attributes, const std::string& element,
                                    size_t vertexCount) const;

  // Reads accessor `index` as doubles (components × count), applying
  // normalisation and sparse substitution. Ranges were checked before.
  std::vector<double> readAccessor(int64_t index, const std::string& element,
                                   std::initializer_list<const char*> types, size_t* components) const;
  std::vector<uint32_t> readIndices(int64_t index, const std::string& element) const;

  const std::string& path_;
  const json& doc_;
  const tinygltf::Model& model_;
  Scene scene_;
  int64_t defaultMaterial_ = -1;
};

// Component read with glTF normalisation rules (glTF 2.0 §3.11).
double readComponent(const uint8_t* p, int64_t componentType, bool normalized) {
  switch (componentType) {
    case 5120: {
      int8_t v;
      std::memcpy(&v, p, 1);
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case 5121: {
      uint8_t v;
      std::memcpy(&v, p, 1);
      return normalized ? v / 255.0 : v;
    }
    case 5122: {
      int16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case 5123: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? v / 65535.0 : v;
    }
    case 5125: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return normalized ? v / 4294967295.0 : v;
    }
    case 5126: {
      float v;
      std::memcpy(&v, p, 4);
      return v;
    }
    default:
      return 0.0;
  }
}

// Types and component types were checked (check.cpp), so both are > 0.
size_t componentBytes(int64_t componentType) { return size_t(componentSize(componentType)); }
size_t typeComponents(const std::string& type) { return size_t(componentCount(type)); }

std::vector<double> SceneBuilder::readAccessor(int64_t index, const std::string& element,
                                               std::initializer_list<const char*> types,
                                               size_t* components) const {
  const json& a = array("accessors")[size_t(index)];
  const std::string ae = element + " (accessor " + std::to_string(index) + ")";
  const std::string type = a.at("type").get<std::string>();
  if (std::find_if(types.begin(), types.end(), [&](const char* t) { return type == t; }) == types.end())
    fail(ae, "type " + type + " is not allowed here");
  const int64_t componentType = a.at("componentType").get<int64_t>();
  const bool normalized = get(a, "normalized", false);
  const size_t count = a.at("count").get<size_t>();
  const size_t n = typeComponents(type);
  const size_t cbytes = componentBytes(componentType);
  *components = n;
  std::vector<double> out(count * n, 0.0);  // no bufferView: zeros (glTF)

  auto readView = [&](int64_t view, size_t byteOffset, size_t stride, size_t elements,
                      size_t elementComponents, int64_t ctype, bool norm, double* dst) {
    const json& v = array("bufferViews")[size_t(view)];
    const auto& data = model_.buffers[v.at("buffer").get<size_t>()].data;
    const size_t base = get<size_t>(v, "byteOffset", 0) + byteOffset;
    for (size_t e = 0; e < elements; ++e)
      for (size_t c = 0; c < elementComponents; ++c)
        dst[e * elementComponents + c] =
            readComponent(data.data() + base + e * stride + c * componentBytes(ctype), ctype, norm);
  };

  if (a.contains("bufferView")) {
    const int64_t view = a.at("bufferView").get<int64_t>();
    const size_t stride = get<size_t>(array("bufferViews")[size_t(view)], "byteStride", 0);
    readView(view, get<size_t>(a, "byteOffset", 0), stride ? stride : n * cbytes, count, n, componentType,
             normalized, out.data());
  }
  if (a.contains("sparse")) {
    const json& s = a.at("sparse");
    const size_t sparseCount = s.at("count").get<size_t>();
    const json& si = s.at("indices");
    const json& sv = s.at("values");
    std::vector<double> indices(sparseCount), values(sparseCount * n);
    const int64_t ict = si.at("componentType").get<int64_t>();
    readView(si.at("bufferView").get<int64_t>(), get<size_t>(si, "byteOffset", 0), componentBytes(ict),
             sparseCount, 1, ict, false, indices.data());
    readView(sv.at("bufferView").get<int64_t>(), get<size_t>(sv, "byteOffset", 0), n * cbytes, sparseCount, n,
             componentType, normalized, values.data());
    for (size_t k = 0; k < sparseCount; ++k) {
      const double i = indices[k];
      if (!(i < double(count)))
        fail(ae, "sparse index " + std::to_string(uint64_t(i)) + " out of range (" + std::to_string(count) +
                     " elements)");
      std::copy_n(values.data() + k * n, n, out.data() + size_t(i) * n);
    }
  }
  for (size_t i = 0; i < out.size(); ++i)
    if (!std::isfinite(out[i]))
      fail(ae, "element " + std::to_string(i / n) + " component " + std::to_string(i % n) + " is " +
                   (std::isnan(out[i]) ? "NaN" : "infinite"));
  return out;
}

std::vector<uint32_t> SceneBuilder::readIndices(int64_t index, const std::string& element) const {
  const json& a = array("accessors")[size_t(index)];
  const std::string ae = element + " (accessor " + std::to_string(index) + ")";
  const int64_t ct = a.at("componentType").get<int64_t>();
  if (ct != 5121 && ct != 5123 && ct != 5125)
    fail(ae, "index componentType " + std::to_string(ct) + " must be 5121, 5123 or 5125");
  if (get(a, "normalized", false)) fail(ae, "indices must not be normalized");
  size_t components = 0;
  const std::vector<double> values = readAccessor(index, element, {"SCALAR"}, &components);
  std::vector<uint32_t> out(values.size());
  for (size_t i = 0; i < values.size(); ++i) out[i] = uint32_t(values[i]);
  return out;
}

glm::dmat4 SceneBuilder::localMatrix(size_t node) const {
  const json& n = array("nodes")[node];
  if (n.contains("matrix")) {
    std::vector<double> m = n.at("matrix").get<std::vector<double>>();
    return glm::make_mat4(m.data());  // glTF matrices are column-major, as GLM's
  }
  glm::dmat4 result(1.0);
  if (n.contains("translation")) {
    const auto t = n.at("translation").get<std::vector<double>>();
    result = glm::translate(result, glm::dvec3(t[0], t[1], t[2]));
  }
  if (n.contains("rotation")) {
    const auto r = n.at("rotation").get<std::vector<double>>();
    glm::dquat q(r[3], r[0], r[1], r[2]);  // glTF stores (x, y, z, w)
    const double length = glm::length(q);
    if (!(length > 0.0)) fail("node " + std::to_string(node), "\"rotation\" is a zero quaternion");
    result = result * glm::mat4_cast(q / length);  // exporters round: renormalise
  }
  if (n.contains("scale")) {
    const auto s = n.at("scale").get<std::vector<double>>();
    result = glm::scale(result, glm::dvec3(s[0], s[1], s[2]));
  }
  return result;
}

void SceneBuilder::checkNodeGraph(std::vector<int64_t>& parent) const {
  const json& nodes = array("nodes");
  parent.assign(nodes.size(), -1);
  for (size_t i = 0; i < nodes.size(); ++i) {
    if (!nodes[i].contains("children")) continue;
    for (const json& c : nodes[i].at("children")) {
      const size_t child = c.get<size_t>();
      if (child == i) fail("node " + std::to_string(i), "lists itself as a child (cycle)");
      if (parent[child] >= 0)
        fail("node " + std::to_string(child), "is a child of both node " + std::to_string(parent[child]) +
                                                  " and node " + std::to_string(i) +
                                                  " (glTF nodes form trees)");
      parent[child] = int64_t(i);
    }
  }
  // With one parent per node, a cycle is a parent chain that never ends:
  // follow each chain, marking nodes by the walk that reached them.
  std::vector<size_t> seenBy(nodes.size(), SIZE_MAX);
  for (size_t start = 0; start < nodes.size(); ++start) {
    size_t i = start;
    while (parent[i] >= 0 && seenBy[i] == SIZE_MAX) {
      seenBy[i] = start;
      i = size_t(parent[i]);
      if (seenBy[i] == start)
        fail("node " + std::to_string(i), "is its own ancestor (cycle in the node graph)");
    }
  }
}

std::vector<size_t> SceneBuilder::rootNodes(const std::vector<int64_t>& parent) {
  const json& scenes = array("scenes");
  std::vector<size_t> roots;
  if (scenes.empty()) {
    // No scenes: every root node, in index order (SPEC §1).
    scene_.stats.sceneIndex = -1;
    for (size_t i = 0; i < parent.size(); ++i)
      if (parent[i] < 0) roots.push_back(i);
    return roots;
  }
  const size_t index = get<size_t>(doc_, "scene", 0);
  scene_.stats.sceneIndex = int(index);
  const json& s = scenes[index];
  const std::string e = "scene " + std::to_string(index);
  std::vector<bool> listed(parent.size(), false);
  if (s.contains("nodes")) {
    for (const json& n : s.at("nodes")) {
      const size_t node = n.get<size_t>();
      if (parent[node] >= 0)
        fail(e, "node " + std::to_string(node) + " is not a root node (child of node " +
                    std::to_string(parent[node]) + ")");
      if (listed[node]) fail(e, "lists node " + std::to_string(node) + " twice");
      listed[node] = true;
      roots.push_back(node);
    }
  }
  return roots;
}

void SceneBuilder::walk(const std::vector<size_t>& roots) {
  // Depth-first, children in order, with an explicit stack: a deep
  // hierarchy must not overflow the call stack.
  struct Item {
    size_t node;
    glm::dmat4 parentWorld;
  };
  std::vector<Item> stack;
  for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.push_back({*it, glm::dmat4(1.0)});
  const json& nodes = array("nodes");
  while (!stack.empty()) {
    const Item item = stack.back();
    stack.pop_back();
    const json& n = nodes[item.node];
    const glm::dmat4 world = item.parentWorld * localMatrix(item.node);
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r)
        if (!std::isfinite(world[c][r]))
          fail("node " + std::to_string(item.node), "world matrix is not finite");
    ++scene_.stats.visitedNodes;
    if (n.contains("mesh")) {
      const size_t mesh = n.at("mesh").get<size_t>();
      const json& prims = array("meshes")[mesh].at("primitives");
      for (size_t p = 0; p < prims.size(); ++p) {
        const int64_t mode = get<int64_t>(prims[p], "mode", 4);
        if (mode < 4) {
          ++scene_.stats.skippedPrimitives;  // points and lines: no instance number
          continue;
        }
        addPrimitive(item.node, mesh, p, world);
      }
    }
    if (n.contains("camera")) addCamera(item.node, world);
    if (n.contains("extensions") && n.at("extensions").contains("KHR_lights_punctual"))
      addLight(item.node, world);
    if (n.contains("children")) {
      const json& children = n.at("children");
      for (auto it = children.rbegin(); it != children.rend(); ++it)
        stack.push_back({it->get<size_t>(), world});
    }
  }
}

void SceneBuilder::addPrimitive(size_t node, size_t mesh, size_t primitive, const glm::dmat4& world) {
  const json& prim = array("meshes")[mesh].at("primitives")[primitive];
  const std::string e = "mesh " + std::to_string(mesh) + " primitive " + std::to_string(primitive);
  const json& attributes = prim.at("attributes");

  if (scene_.instances.size() >= kNoId - 1) fail(e, "too many instances");
  Instance inst;
  inst.node = uint32_t(node);
  inst.mesh = uint32_t(mesh);
  inst.primitive = uint32_t(primitive);
  inst.mode = int(get<int64_t>(prim, "mode", 4));
  inst.worldFromObject = world;
  inst.mirrored = glm::determinant(glm::dmat3(world)) < 0.0;
  if (prim.contains("material")) {
    inst.material = prim.at("material").get<uint32_t>();
  } else {
    if (defaultMaterial_ < 0) {
      Material m;
      m.name = "default";
      m.isDefault = true;
      defaultMaterial_ = int64_t(scene_.materials.size());
      scene_.materials.push_back(m);
    }
    inst.material = uint32_t(defaultMaterial_);
  }
  inst.firstVertex = uint32_t(scene_.positions.size());
  inst.firstTriangle = uint32_t(scene_.triangles.size());

  // No POSITION: the primitive keeps its instance number and draws nothing.
  if (!attributes.contains("POSITION")) {
    scene_.instances.push_back(inst);
    return;
  }
  size_t components = 0;
  const int64_t posAccessor = attributes.at("POSITION").get<int64_t>();
  const std::vector<double> pos = readAccessor(posAccessor, e + " POSITION", {"VEC3"}, &components);
  const size_t vertexCount = pos.size() / 3;
  if (scene_.positions.size() + vertexCount >= size_t(kNoId))
    fail(e, "the scene has more than 2^32 vertices");

  std::vector<double> nrm, uv;
  if (attributes.contains("NORMAL")) {
    nrm = readAccessor(attributes.at("NORMAL").get<int64_t>(), e + " NORMAL", {"VEC3"}, &components);
    if (nrm.size() != pos.size())
      fail(e, "NORMAL has " + std::to_string(nrm.size() / 3) + " elements, POSITION " +
                  std::to_string(vertexCount));
    inst.normals = NormalSource::Authored;
  }
  // The texcoord set the base colour texture reads (TEXCOORD_0 unless it
  // says otherwise); without one, the emissive texture's set. loadMaterials
  // drops an emissive texture that names another set than the base colour.
  int64_t texCoordSet = 0;
  {
    const json& mats = array("materials");
    if (prim.contains("material")) {
      const json& m = mats[prim.at("material").get<size_t>()];
      if (m.contains("pbrMetallicRoughness") && m.at("pbrMetallicRoughness").contains("baseColorTexture"))
        texCoordSet = get<int64_t>(m.at("pbrMetallicRoughness").at("baseColorTexture"), "texCoord", 0);
      else if (m.contains("emissiveTexture"))
        texCoordSet = get<int64_t>(m.at("emissiveTexture"), "texCoord", 0);
    }
  }
  const std::string uvName = "TEXCOORD_" + std::to_string(texCoordSet);
  if (attributes.contains(uvName)) {
    uv = readAccessor(attributes.at(uvName).get<int64_t>(), e + " " + uvName, {"VEC2"}, &components);
    if (uv.size() / 2 != vertexCount)
      fail(e, uvName + " has " + std::to_string(uv.size() / 2) + " elements, POSITION " +
                  std::to_string(vertexCount));
    inst.hasTexcoords = true;
  }
  const std::vector<glm::vec4> colors = readColors(attributes, e, vertexCount);
  inst.hasColors = !colors.empty();
  // Scene::colors stays empty until an instance has COLOR_0; then it is
  // back-filled with white for the vertices before it.
  if (inst.hasColors && scene_.colors.empty()) scene_.colors.assign(scene_.positions.size(), glm::vec4(1.0f));

  // Normals transform by the cofactor matrix: the inverse transpose scaled
  // by the determinant, defined even for singular matrices; the sign keeps
  // normals on the same side for mirroring transforms.
  const glm::dmat3 m3(world);
  const glm::dmat3 cofactor(glm::cross(m3[1], m3[2]), glm::cross(m3[2], m3[0]), glm::cross(m3[0], m3[1]));
  const double sign = inst.mirrored ? -1.0 : 1.0;
  for (size_t v = 0; v < vertexCount; ++v) {
    const glm::dvec3 p = glm::dvec3(world * glm::dvec4(pos[3 * v], pos[3 * v + 1], pos[3 * v + 2], 1.0));
    // Test in double: converting a value beyond the float range is undefined.
    constexpr double kFloatMax = std::numeric_limits<float>::max();
    if (!(std::abs(p.x) <= kFloatMax && std::abs(p.y) <= kFloatMax && std::abs(p.z) <= kFloatMax))
      fail(e + " POSITION (accessor " + std::to_string(posAccessor) + ")",
           "vertex " + std::to_string(v) + " is not finite in world space as float");
    const glm::vec3 pf(p);
    scene_.worldPositions.push_back(p);
    scene_.positions.push_back(pf);
    scene_.bounds.extend(glm::dvec3(pf));
    glm::dvec3 n(0.0);
    if (!nrm.empty()) {
      n = sign * (cofactor * glm::dvec3(nrm[3 * v], nrm[3 * v + 1], nrm[3 * v + 2]));
      const double len = glm::length(n);
      n = len > 0.0 && std::isfinite(len) ? n / len : glm::dvec3(0.0);  // zero: use the face normal
    }
    scene_.normals.emplace_back(n);
    scene_.texcoords.emplace_back(uv.empty() ? glm::vec2(0.0f)
                                             : glm::vec2(float(uv[2 * v]), float(uv[2 * v + 1])));
    if (inst.hasColors || !scene_.colors.empty())
      scene_.colors.push_back(inst.hasColors ? colors[v] : glm::vec4(1.0f));
  }
  inst.vertexCount = uint32_t(vertexCount);

  // Triangulate (SPEC §1).
  std::vector<uint32_t> indices;
  if (prim.contains("indices")) {
    const int64_t ia = prim.at("indices").get<int64_t>();
    indices = readIndices(ia, e + " indices");
    for (uint32_t i : indices)
      if (i >= vertexCount)
        fail("accessor " + std::to_string(ia),
             "index " + std::to_string(i) + " out of range (" + std::to_string(vertexCount) + " vertices)");
  } else {
    indices.resize(vertexCount);
    for (size_t i = 0; i < vertexCount; ++i) indices[i] = uint32_t(i);
  }
  const size_t n = indices.size();
  std::vector<glm::uvec3> tris;
  if (inst.mode == 4) {
    if (n % 3 != 0)
      fail(e, std::to_string(n) + (prim.contains("indices") ? " indices" : " vertices") +
                  " for TRIANGLES is not a multiple of 3");
    for (size_t i = 0; i + 2 < n; i += 3) tris.emplace_back(indices[i], indices[i + 1], indices[i + 2]);
  } else if (inst.mode == 5) {
    for (size_t i = 0; i + 2 < n; ++i)
      tris.push_back(i % 2 == 0 ? glm::uvec3(indices[i], indices[i + 1], indices[i + 2])
                                : glm::uvec3(indices[i + 1], indices[i], indices[i + 2]));
  } else {
    for (size_t i = 0; i + 2 < n; ++i) tris.emplace_back(indices[0], indices[i + 1], indices[i + 2]);
  }
  if (scene_.triangles.size() + tris.size() >= size_t(kNoId))
    fail(e, "the scene has more than 2^32 triangles");
  for (glm::uvec3 t : tris) {
    if (inst.mirrored) std::swap(t.y, t.z);  // keep CCW = front in world space
    t += glm::uvec3(inst.firstVertex);
    scene_.triangles.push_back(t);
    if (isDegenerate(scene_, scene_.triangles.size() - 1)) ++inst.degenerateCount;
  }
  inst.triangleCount = uint32_t(tris.size());
  scene_.instances.push_back(inst);
}

void SceneBuilder::addCamera(size_t node, const glm::dmat4& world) {
  ++scene_.stats.cameraNodes;
  if (scene_.camera) return;  // the first camera node in walk order wins (SPEC §2)
  const size_t index = array("nodes")[node].at("camera").get<size_t>();
  const json& c = array("cameras")[index];
  const std::string e = "node " + std::to_string(node);
  if (glm::length(glm::cross(glm::dvec3(world[0]), glm::dvec3(world[1]))) == 0.0 ||
      glm::length(glm::dvec3(world[2])) == 0.0)
    fail(e, "the camera's world matrix is singular");
  CameraModel cam;
  cam.worldFromCamera = world;
  if (c.at("type") == "perspective") {
    const json& p = c.at("perspective");
    cam.projection = Projection::Perspective;
    cam.yfov = p.at("yfov").get<double>();
    cam.znear = p.at("znear").get<double>();
    cam.zfar = get(p, "zfar", std::numeric_limits<double>::infinity());
    cam.aspectRatio = get(p, "aspectRatio", 0.0);
  } else {
    const json& o = c.at("orthographic");
    cam.projection = Projection::Orthographic;
    cam.xmag = std::abs(o.at("xmag").get<double>());
    cam.ymag = std::abs(o.at("ymag").get<double>());
    cam.znear = o.at("znear").get<double>();
    cam.zfar = o.at("zfar").get<double>();
  }
  const std::string name = get<std::string>(array("nodes")[node], "name", "");
  cam.origin = "node " + std::to_string(node) + (name.empty() ? "" : " '" + name + "'") + " (camera " +
               std::to_string(index) + ")";
  scene_.camera = cam;
}

void SceneBuilder::addLight(size_t node, const glm::dmat4& world) {
  const size_t index =
      array("nodes")[node].at("extensions").at("KHR_lights_punctual").at("light").get<size_t>();
  const json& l = doc_.at("extensions").at("KHR_lights_punctual").at("lights")[index];
  Light light;
  light.name = get<std::string>(l, "name", "");
  const std::string type = l.at("type").get<std::string>();
  light.type = type == "point" ? LightType::Point : type == "spot" ? LightType::Spot : LightType::Directional;
  if (l.contains("color")) {
    const auto c = l.at("color").get<std::vector<double>>();
    if (c[0] < 0 || c[1] < 0 || c[2] < 0)
      fail("light " + std::to_string(index), "\"color\" must not be negative");
    light.color = glm::vec3(float(c[0]), float(c[1]), float(c[2]));
  }
  light.intensity = float(get(l, "intensity", 1.0));
  light.range = float(get(l, "range", 0.0));
  if (l.contains("spot")) {
    light.innerConeAngle = float(get(l.at("spot"), "innerConeAngle", 0.0));
    light.outerConeAngle = float(get(l.at("spot"), "outerConeAngle", kPi / 4));
  }
  light.position = glm::dvec3(world[3]);
  const glm::dvec3 d = glm::dvec3(world * glm::dvec4(0.0, 0.0, -1.0, 0.0));
  if (light.type != LightType::Point) {
    if (!(glm::length(d) > 0.0)) fail("node " + std::to_string(node), "the light's world matrix is singular");
    light.direction = glm::normalize(d);
  }
  light.node = uint32_t(node);
  scene_.lights.push_back(light);
}

void SceneBuilder::loadTextures() {
  // Images: tinygltf decoded them (stb); we keep RGBA8.
  for (size_t i = 0; i < model_.images.size(); ++i) {
    const tinygltf::Image& src = model_.images[i];
    TextureImage img;
    img.name = src.name;
    img.width = src.width;
    img.height = src.height;
    const int comps = src.component;
    const int bytes = src.bits / 8;
    const size_t pixels = size_t(std::max(src.width, 0)) * size_t(std::max(src.height, 0));
    if (src.width <= 0 || src.height <= 0 || comps < 1 || comps > 4 || (bytes != 1 && bytes != 2) ||
        src.image.size() < pixels * size_t(comps * bytes))
      fail("image " + std::to_string(i), src.image.empty() && !src.uri.empty()
                                             ? "\"" + shortened(src.uri) + "\" could not be read"
                                             : "could not be decoded to 8- or 16-bit pixels");
    img.rgba8.resize(pixels * 4);
    for (size_t p = 0; p < pixels; ++p) {
      uint8_t c[4] = {0, 0, 0, 255};
      for (int k = 0; k < comps; ++k) {
        const size_t at = (p * size_t(comps) + size_t(k)) * size_t(bytes);
        // 16-bit: keep the high byte, rounded (65535 → 255).
        c[k] = bytes == 1
                   ? src.image[at]
                   : uint8_t((uint32_t(src.image[at]) | uint32_t(src.image[at + 1]) << 8) * 255u / 65535u);
      }
      if (comps == 1) c[1] = c[2] = c[0];  // grey
      if (comps == 2) {
        c[3] = c[1];
        c[1] = c[2] = c[0];
      }  // grey + alpha
      std::memcpy(&img.rgba8[p * 4], c, 4);
    }
    scene_.images.push_back(std::move(img));
  }
  const json& textures = array("textures");
  for (size_t i = 0; i < textures.size(); ++i) {
    Texture t;
    t.image = int32_t(get<int64_t>(textures[i], "source", -1));
    if (textures[i].contains("sampler")) {
      const json& s = array("samplers")[textures[i].at("sampler").get<size_t>()];
      t.sampler.magFilter = int(get<int64_t>(s, "magFilter", -1));
      t.sampler.minFilter = int(get<int64_t>(s, "minFilter", -1));
      t.sampler.wrapS = int(get<int64_t>(s, "wrapS", 10497));
      t.sampler.wrapT = int(get<int64_t>(s, "wrapT", 10497));
    }
    scene_.textures.push_back(t);
  }
}

void SceneBuilder::loadMaterials() {
  const json& materials = array("materials");
  for (size_t i = 0; i < materials.size(); ++i) {
    const json& m = materials[i];
    const std::string e = "material " + std::to_string(i);
    Material mat;
    mat.name = get<std::string>(m, "name", "");
    auto unit = [&](double v, const char* what) {
      if (!(v >= 0.0 && v <= 1.0))
        fail(e, std::string(what) + " " + std::to_string(v) + " must lie in [0, 1]");
      return float(v);
    };
    if (m.contains("pbrMetallicRoughness")) {
      const json& pbr = m.at("pbrMetallicRoughness");
      if (pbr.contains("baseColorFactor")) {
        const auto f = pbr.at("baseColorFactor").get<std::vector<double>>();
        mat.baseColorFactor = glm::vec4(unit(f[0], "baseColorFactor"), unit(f[1], "baseColorFactor"),
                                        unit(f[2], "baseColorFactor"), unit(f[3], "baseColorFactor"));
      }
      // A texture without an image we can decode is ignored (and listed):
      // the factor alone applies.
      if (pbr.contains("baseColorTexture"))
        mat.baseColorTexture = decodableTexture(pbr.at("baseColorTexture"));
      mat.metallic = unit(get(pbr, "metallicFactor", 1.0), "metallicFactor");
      mat.roughness = unit(get(pbr, "roughnessFactor", 1.0), "roughnessFactor");
    }
    glm::dvec3 emissive(0.0);
    if (m.contains("emissiveFactor")) {
      const auto f = m.at("emissiveFactor").get<std::vector<double>>();
      emissive = glm::dvec3(unit(f[0], "emissiveFactor"), unit(f[1], "emissiveFactor"),
                            unit(f[2], "emissiveFactor"));
    }
    if (m.contains("emissiveTexture")) {
      // One uv set per vertex (Scene::texcoords): the emissive texture must
      // read the base colour texture's set, or it is listed as ignored.
      const json& info = m.at("emissiveTexture");
      const bool sameSet = !m.contains("pbrMetallicRoughness") ||
                           !m.at("pbrMetallicRoughness").contains("baseColorTexture") ||
                           get<int64_t>(m.at("pbrMetallicRoughness").at("baseColorTexture"), "texCoord", 0) ==
                               get<int64_t>(info, "texCoord", 0);
      if (sameSet)
        mat.emissiveTexture = decodableTexture(info);
      else
        noteIgnored("emissive texture on another texCoord set than the base colour texture", "material");
    }
    const std::string mode = get<std::string>(m, "alphaMode", "OPAQUE");
    mat.alphaMode = mode == "MASK" ? AlphaMode::Mask : mode == "BLEND" ? AlphaMode::Blend : AlphaMode::Opaque;
    mat.alphaCutoff = float(get(m, "alphaCutoff", 0.5));
    if (mat.alphaCutoff < 0.0f) fail(e, "\"alphaCutoff\" must be >= 0");
    mat.doubleSided = get(m, "doubleSided", false);
    if (m.contains("extensions")) {
      const json& ext = m.at("extensions");
      if (ext.contains("KHR_materials_transmission"))
        mat.transmission =
            unit(get(ext.at("KHR_materials_transmission"), "transmissionFactor", 0.0), "transmissionFactor");
      if (ext.contains("KHR_materials_ior")) {
        const double ior = get(ext.at("KHR_materials_ior"), "ior", 1.5);
        if (!(ior >= 1.0)) fail(e + " KHR_materials_ior", "\"ior\" " + std::to_string(ior) + " must be >= 1");
        mat.ior = float(ior);
      }
      if (ext.contains("KHR_materials_emissive_strength")) {
        const double s = get(ext.at("KHR_materials_emissive_strength"), "emissiveStrength", 1.0);
        if (!(s >= 0.0)) fail(e + " KHR_materials_emissive_strength", "\"emissiveStrength\" must be >= 0");
        emissive *= s;
      }
    }
    mat.emissive = glm::vec3(emissive);
    scene_.materials.push_back(mat);
  }
}

int32_t SceneBuilder::decodableTexture(const json& textureInfo) {
  const int32_t tex = textureInfo.at("index").get<int32_t>();
  if (scene_.textures[size_t(tex)].image >= 0) return tex;
  noteIgnored("texture without a decodable image", "textureInfo");
  return -1;
}

// COLOR_0 (glTF 2.0 §3.7.2.1): VEC3 or VEC4, float or normalized unsigned
// byte/short, linear. Empty when the primitive has none.
std::vector<glm::vec4> SceneBuilder::readColors(const json& attributes, const std::string& element,
                                                size_t vertexCount) const {
  if (!attributes.contains("COLOR_0")) return {};
  const int64_t index = attributes.at("COLOR_0").get<int64_t>();
  const json& a = array("accessors")[size_t(index)];
  const std::string e = element + " COLOR_0";
  const int64_t ct = a.at("componentType").get<int64_t>();
  if (!(ct == 5126 || ((ct == 5121 || ct == 5123) && get(a, "normalized", false))))
    fail(e + " (accessor " + std::to_string(index) + ")",
         "componentType " + std::to_string(ct) + " must be 5126, or 5121 or 5123 with \"normalized\": true");
  size_t components = 0;
  const std::vector<double> c = readAccessor(index, e, {"VEC3", "VEC4"}, &components);
  if (c.size() / components != vertexCount)
    fail(element, "COLOR_0 has " + std::to_string(c.size() / components) + " elements, POSITION " +
                      std::to_string(vertexCount));
  std::vector<glm::vec4> out(vertexCount, glm::vec4(1.0f));
  for (size_t v = 0; v < vertexCount; ++v)
    for (size_t k = 0; k < components; ++k)
      out[v][int(k)] = float(std::clamp(c[v * components + k], 0.0, 1.0));  // float colours may stray
  return out;
}

void SceneBuilder::noteIgnored(const std::string& feature, const std::string& unit) {
  for (IgnoredFeature& f : scene_.ignored)
    if (f.feature == feature && f.unit == unit) {
      ++f.count;
      return;
    }
  scene_.ignored.push_back({feature, unit, 1});
}

// What the checker accepted and nothing renders. Counted over the file's
// elements (every material, primitive, node), used or not.
void SceneBuilder::noteIgnoredFeatures() {
  for (const json& m : array("materials")) {
    if (m.contains("normalTexture")) noteIgnored("normal texture", "material");
    if (m.contains("occlusionTexture")) noteIgnored("occlusion texture", "material");
    if (m.contains("pbrMetallicRoughness") &&
        m.at("pbrMetallicRoughness").contains("metallicRoughnessTexture"))
      noteIgnored("metallicRoughness texture", "material");
    if (m.contains("extensions") && m.at("extensions").contains("KHR_materials_transmission") &&
        m.at("extensions").at("KHR_materials_transmission").contains("transmissionTexture"))
      noteIgnored("transmission texture", "material");
  }
  for (const json& mesh : array("meshes"))
    for (const json& prim : mesh.at("primitives")) {
      if (prim.contains("targets")) noteIgnored("morph targets", "primitive");
      for (auto it = prim.at("attributes").begin(); it != prim.at("attributes").end(); ++it)
        if (it.key().rfind("JOINTS_", 0) == 0) {
          noteIgnored("skinning attributes (JOINTS_n/WEIGHTS_n)", "primitive");
          break;
        }
    }
  for (const json& n : array("nodes"))
    if (n.contains("skin")) noteIgnored("skin", "node");
  for (size_t i = 0; i < array("animations").size(); ++i) noteIgnored("animation", "");
  std::vector<std::string> path;
  noteIgnoredExtensions(doc_, path);
}

// Every extension object in the document whose extension is not supported
// (KHR_texture_transform, KHR_materials_volume, ...), counted by the kind
// of element that holds it.
void SceneBuilder::noteIgnoredExtensions(const json& value, std::vector<std::string>& path) {
  if (value.is_array()) {
    for (size_t i = 0; i < value.size(); ++i) {
      path.push_back("#");  // an array entry: its index does not name the kind
      noteIgnoredExtensions(value[i], path);
      path.pop_back();
    }
    return;
  }
  if (!value.is_object()) return;
  if (value.contains("extensions") && value.at("extensions").is_object()) {
    std::string unit = "root object";
    const size_t n = path.size();
    if (n >= 1 && path[n - 1].size() > 7 && path[n - 1].compare(path[n - 1].size() - 7, 7, "Texture") == 0)
      unit = "textureInfo";
    else if (n == 4 && path[0] == "meshes" && path[2] == "primitives")
      unit = "primitive";
    else if (n == 2 && path[1] == "#" && !singular(path[0]).empty())
      unit = singular(path[0]);
    else if (n >= 1)
      unit = path[n - 1] == "#" && n >= 2 ? path[n - 2] + " entry" : "\"" + path[n - 1] + "\"";
    for (auto it = value.at("extensions").begin(); it != value.at("extensions").end(); ++it)
      if (!isSupportedExtension(it.key())) noteIgnored(it.key(), unit);
  }
  for (auto it = value.begin(); it != value.end(); ++it) {
    if (it.key() == "extras") continue;  // application data, not glTF
    path.push_back(it.key());
    noteIgnoredExtensions(it.value(), path);
    path.pop_back();
  }
}

Scene SceneBuilder::build() {
  scene_.path = path_;
  scene_.stats.nodes = uint32_t(array("nodes").size());
  scene_.stats.meshes = uint32_t(array("meshes").size());
  scene_.stats.cameras = uint32_t(array("cameras").size());
  loadTextures();
  loadMaterials();
  std::vector<int64_t> parent;
  checkNodeGraph(parent);
  walk(rootNodes(parent));
  noteIgnoredFeatures();
  return std::move(scene_);
}

std::vector<uint8_t> readFile(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw InputError(path, "", "no such file");
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path, "", "not a regular file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "", std::string("cannot open: ") + std::strerror(errno));
  std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw InputError(path, "", "read error");
  return bytes;
}

}  // namespace

Scene loadScene(const std::string& path) {
  const std::vector<uint8_t> bytes = readFile(path);

  // The container: a .glb is recognised by its magic, whatever its name.
  GltfCheckContext context{path, false, 0};
  std::string jsonText;
  if (bytes.size() >= 4 && readU32(bytes, 0) == kGlbMagic) {
    context.isGlb = true;
    if (bytes.size() < 20)
      throw InputError(path, "GLB header", "file is too short (" + std::to_string(bytes.size()) + " bytes)");
    const uint32_t version = readU32(bytes, 4), length = readU32(bytes, 8);
    if (version != 2)
      throw InputError(path, "GLB header", "version " + std::to_string(version) + " is not 2");
    if (length != bytes.size())
      throw InputError(
          path, "GLB header",
          "declares " + std::to_string(length) + " bytes, the file has " + std::to_string(bytes.size()));
    const uint32_t jsonLength = readU32(bytes, 12), jsonType = readU32(bytes, 16);
    if (jsonType != kChunkJson) throw InputError(path, "GLB chunk 0", "is not a JSON chunk");
    if (jsonLength > bytes.size() - 20)
      throw InputError(path, "GLB chunk 0",
                       "length " + std::to_string(jsonLength) + " runs past the end of the file");
    // Chunks end on 4-byte boundaries (glTF 2.0, GLB layout); tinygltf
    // looks for the BIN chunk right after the JSON bytes, so an unpadded
    // length would have it read another chunk than the one checked here.
    if (jsonLength % 4 != 0)
      throw InputError(path, "GLB chunk 0",
                       "length " + std::to_string(jsonLength) + " is not a multiple of 4");
    jsonText.assign(reinterpret_cast<const char*>(bytes.data() + 20), jsonLength);
    // Whatever follows must be a BIN chunk: tinygltf refuses anything else.
    const size_t binAt = 20 + size_t(jsonLength);
    if (binAt < bytes.size()) {
      if (bytes.size() - binAt < 8)
        throw InputError(
            path, "GLB chunk 1",
            "header is truncated (" + std::to_string(bytes.size() - binAt) + " bytes after the JSON chunk)");
      const uint32_t binLength = readU32(bytes, binAt), binType = readU32(bytes, binAt + 4);
      if (binType != kChunkBin) throw InputError(path, "GLB chunk 1", "is not a BIN chunk");
      if (binLength < 4 || binLength % 4 != 0)
        throw InputError(path, "GLB chunk 1",
                         "length " + std::to_string(binLength) + " is not a positive multiple of 4");
      if (binLength > bytes.size() - binAt - 8)
        throw InputError(path, "GLB chunk 1",
                         "length " + std::to_string(binLength) + " runs past the end of the file");
      context.glbBinSize = binLength;
    }
  } else {
    jsonText.assign(bytes.begin(), bytes.end());
  }

  json doc;
  TrackingJsonParser parser(doc, path, jsonText);
  json::sax_parse(jsonText, &parser);
  checkGltfDocument(doc, context);

  // Resources through tinygltf. The document is sound by now, so its
  // remaining failures are about resources: missing files, bad data URIs,
  // undecodable images.
  tinygltf::TinyGLTF loader;
  tinygltf::FsCallbacks fs{&isRegularFile, &expandNothing, &tinygltf::ReadWholeFile,
                           &tinygltf::WriteWholeFile, nullptr};
  loader.SetFsCallbacks(fs);
  tinygltf::Model model;
  std::string err, warn;
  const std::string baseDir = std::filesystem::path(path).parent_path().string();
  if (bytes.size() > UINT32_MAX) throw InputError(path, "", "file is larger than 4 GiB");
  const bool ok =
      context.isGlb ? loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(), unsigned(bytes.size()),
                                                  baseDir.empty() ? "." : baseDir)
                    : loader.LoadASCIIFromString(&model, &err, &warn, jsonText.data(),
                                                 unsigned(jsonText.size()), baseDir.empty() ? "." : baseDir);
  if (!ok) {
    // tinygltf loads the top-level arrays in this order and appends each
    // entry once it has loaded, so the first array that came up short
    // holds the entry it failed on.
    const std::pair<const char*, size_t> loaded[] = {
        {"buffers", model.buffers.size()},     {"bufferViews", model.bufferViews.size()},
        {"accessors", model.accessors.size()}, {"meshes", model.meshes.size()},
        {"nodes", model.nodes.size()},         {"scenes", model.scenes.size()},
        {"materials", model.materials.size()}, {"images", model.images.size()},
        {"textures", model.textures.size()},   {"animations", model.animations.size()},
        {"skins", model.skins.size()},         {"samplers", model.samplers.size()},
        {"cameras", model.cameras.size()}};
    for (const auto& [key, count] : loaded) {
      const auto it = doc.find(key);
      if (it == doc.end() || !it->is_array() || count >= it->size()) continue;
      const json& entry = (*it)[count];
      std::string message = shortened(firstLine(err));
      // tinygltf's message would quote the whole data URI.
      const bool dataUri = entry.value("uri", std::string()).rfind("data:", 0) == 0;
      if (std::string(key) == "buffers" && dataUri)
        message = "data URI is not base64 of exactly byteLength (" +
                  std::to_string(entry.at("byteLength").get<uint64_t>()) +
                  ") bytes with media type application/octet-stream or application/gltf-buffer";
      throw InputError(path, singular(key) + " " + std::to_string(count), message);
    }
    throw InputError(path, "", shortened(firstLine(err)));
  }
  if (model.buffers.size() != doc.value("buffers", json::array()).size() ||
      model.images.size() != doc.value("images", json::array()).size())
    throw InputError(path, "", "tinygltf loaded a different number of buffers or images than the file lists");
  for (size_t i = 0; i < model.buffers.size(); ++i)
    if (model.buffers[i].data.size() < doc.at("buffers")[i].at("byteLength").get<size_t>())
      throw InputError(path, "buffer " + std::to_string(i), "is shorter than its byteLength");

  return SceneBuilder(path, doc, model).build();
}

}  // namespace rastray
