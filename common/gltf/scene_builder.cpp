// Step 4 of loading (loader.cpp): the checked JSON and tinygltf's buffers
// and images → the flattened Scene. Walks the node trees from the scene's
// roots, flattens every triangle primitive into an instance with world-space
// vertices, and reads materials, textures, the cameras and the lights.
#include "common/gltf/scene_builder.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>

#include <tiny_gltf.h>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <nlohmann/json.hpp>

#include "common/error.h"
#include "common/gltf/animation.h"
#include "common/gltf/check.h"
#include "common/gltf/compression.h"
#include "common/gltf/document.h"
#include "common/gltf/tangents.h"
#include "common/math_constants.h"
#include "common/memory_budget.h"

namespace rastray {

namespace {

using json = nlohmann::json;

// The KHR_texture_transform object of a textureInfo, or nullptr.
const json* textureTransformOf(const json& textureInfo);
int64_t texCoordOf(const json& textureInfo);
int64_t materialTexCoordSet(const json& material);

class SceneBuilder {
 public:
  SceneBuilder(const std::string& path, const json& doc, const tinygltf::Model& model,
               const MemoryBudget& budget, const PoseRequest& pose)
      : path_(path), doc_(doc), model_(model), budget_(budget), pose_(pose) {}

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

  // The node's matrix at the requested pose (its own TRS where no played
  // channel sets it).
  glm::dmat4 localMatrix(size_t node) const;
  void checkNodeGraph(std::vector<int64_t>& parent) const;
  // Reads and checks every animation (animations_, Scene::animations) and
  // samples the requested pose (pose_, nodePose_).
  void loadAnimations();
  // The world matrix of any node at the pose, reached from the scene or
  // not (a skin's joints need not be); memoised in world_.
  const glm::dmat4& worldOf(size_t node);
  // skin's joint matrices globalJoint · inverseBind, in double; memoised.
  const std::vector<glm::dmat4>& jointMatrices(size_t skin);
  // The morph weights of (node, mesh) at the pose: an animated weights
  // channel, else the node's "weights", else the mesh's, else zeros;
  // `targets` per primitive.
  std::vector<double> morphWeights(size_t node, size_t mesh, size_t targets) const;
  std::vector<size_t> rootNodes(const std::vector<int64_t>& parent);
  void reserveFlattenedScene(const std::vector<size_t>& roots);
  void walk(const std::vector<size_t>& roots);
  void addPrimitive(size_t node, size_t mesh, size_t primitive, const glm::dmat4& world);
  // The steps of addPrimitive.
  struct VertexData {
    int64_t positionAccessor = -1;
    size_t count = 0;                                   // vertices
    std::vector<double> positions, normals, texcoords;  // object space; normals, texcoords may be empty
    std::vector<glm::vec4> colors;                      // empty without COLOR_0
    bool needsTangents = false;                         // the material has a normal map
    std::vector<double> tangents;   // TANGENT (4 per vertex), object space; empty: generate
    std::vector<glm::dmat3> skins;  // per vertex, the blended joint matrix (skinned, needsTangents)
  };
  // Adds the weighted POSITION and NORMAL deltas of the primitive's
  // morph targets to `v`; returns whether any weight was nonzero.
  bool applyMorphTargets(const json& prim, const std::string& e, const std::vector<double>& weights,
                         VertexData& v) const;
  // Moves `v`'s positions and normals into world space by the skin's
  // blended joint matrices (JOINTS_n, WEIGHTS_n); returns whether most
  // vertices' skin matrices mirror.
  bool applySkin(const json& prim, const std::string& e, size_t skin, VertexData& v);
  uint32_t materialOf(const json& prim);  // adds the default material when the primitive names none
  int64_t texCoordSetOf(const json& prim) const;
  VertexData readVertexData(const json& prim, const std::string& e, Instance& inst) const;
  void appendVertices(Instance& inst, const VertexData& v, const glm::dmat4& world, const std::string& e);
  // The primitive's triangles (SPEC §1), vertex indices local to it, in
  // the file's winding.
  std::vector<glm::uvec3> triangulate(const json& prim, const std::string& e, size_t vertexCount) const;
  void appendTriangles(Instance& inst, const std::vector<glm::uvec3>& triangles);
  // Per corner of `triangles`, object space: the file's TANGENT, else
  // generated (common/gltf/tangents.h).
  std::vector<glm::dvec4> objectTangents(const VertexData& v, const std::vector<glm::uvec3>& triangles) const;
  // Corner tangents into world space (by the world matrix, or by each
  // vertex's skin matrix) and into Scene::tangents, in stored order.
  void appendTangents(Instance& inst, const VertexData& v, const std::vector<glm::uvec3>& triangles,
                      const std::vector<glm::dvec4>& corners, const glm::dmat4& world);
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
  // `data`: a normal, occlusion or metallic-roughness map (Texture::data),
  // which gets a Texture of its own.
  int32_t decodableTexture(const json& textureInfo, bool data = false);
  std::vector<glm::vec4> readColors(const json& attributes, const std::string& element,
                                    size_t vertexCount) const;

  // Reads accessor `index` as doubles (components × count), applying
  // normalisation and sparse substitution. Ranges were checked before.
  std::vector<double> readAccessor(int64_t index, const std::string& element,
                                   std::initializer_list<const char*> types, size_t* components) const;
  std::vector<uint32_t> readIndices(int64_t index, const std::string& element) const;
  // The bytes of bufferView `view`: the decoded bytes of a meshopt-
  // compressed view, else its range of the buffer tinygltf loaded.
  const uint8_t* viewBytes(int64_t view) const;
  // Decodes every meshopt-compressed bufferView (decodedViews_), after
  // checking their total size against the budget.
  void decodeMeshoptViews();
  // Decodes a KHR_draco_mesh_compression primitive into dracoAccessors_:
  // the decoded values of its attribute and index accessors, which
  // readAccessor then reads instead of the (absent) bufferViews.
  void decodeDraco(const json& prim, const std::string& element);

  const std::string& path_;
  const json& doc_;
  const tinygltf::Model& model_;
  const MemoryBudget& budget_;
  const PoseRequest pose_;
  Scene scene_;
  std::vector<int64_t> parent_;  // per node, -1 for roots
  std::vector<Animation> animations_;
  std::vector<NodePose> nodePose_;                    // per node, at pose_
  std::vector<std::optional<glm::dmat4>> world_;      // per node, worldOf's memo
  std::map<size_t, std::vector<glm::dmat4>> joints_;  // per skin, jointMatrices' memo
  int64_t defaultMaterial_ = -1;
  std::map<int64_t, std::vector<uint8_t>> decodedViews_;  // by bufferView
  std::map<int64_t, DracoAttribute> dracoAccessors_;      // by accessor; the primitive being added
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
    const uint8_t* data = viewBytes(view) + byteOffset;
    for (size_t e = 0; e < elements; ++e)
      for (size_t c = 0; c < elementComponents; ++c)
        dst[e * elementComponents + c] =
            readComponent(data + e * stride + c * componentBytes(ctype), ctype, norm);
  };

  const auto draco = dracoAccessors_.find(index);
  if (draco != dracoAccessors_.end()) {
    // Decoded by libdraco: the same type, count and value checks as data
    // read from a bufferView.
    const DracoAttribute& d = draco->second;
    if (d.components != n)
      fail(ae, "the Draco stream has " + std::to_string(d.components) + " components per element, type " +
                   type + " has " + std::to_string(n));
    if (d.values.size() != out.size())
      fail(ae, "the Draco stream decodes " + std::to_string(d.values.size() / n) +
                   " elements, \"count\" is " + std::to_string(count));
    out = d.values;
  } else if (a.contains("bufferView")) {
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

const uint8_t* SceneBuilder::viewBytes(int64_t view) const {
  const auto decoded = decodedViews_.find(view);
  if (decoded != decodedViews_.end()) return decoded->second.data();
  const json& v = array("bufferViews")[size_t(view)];
  return model_.buffers[v.at("buffer").get<size_t>()].data.data() + get<size_t>(v, "byteOffset", 0);
}

// The meshopt extension of bufferView `v`, or nullptr.
const json* meshoptExtension(const json& v) {
  const auto ext = v.find("extensions");
  if (ext == v.end()) return nullptr;
  for (const char* name : {"EXT_meshopt_compression", "KHR_meshopt_compression"})
    if (ext->contains(name)) return &ext->at(name);
  return nullptr;
}

void SceneBuilder::decodeMeshoptViews() {
  const json& views = array("bufferViews");
  // check.cpp: count × byteStride is the view's byteLength, which a
  // fallback buffer only declares; a small file can declare gigabytes.
  uint64_t decodedBytes = 0;
  for (const json& v : views)
    if (meshoptExtension(v)) decodedBytes = addSat(decodedBytes, v.at("byteLength").get<uint64_t>());
  if (decodedBytes == 0) return;
  MemoryEstimate estimate;
  estimate.add("loaded file", currentRssBytes());
  estimate.add("decoded meshopt bufferViews", decodedBytes);
  checkMemory(estimate, budget_, path_, "bufferViews", "decoding meshopt-compressed bufferViews");
  for (size_t i = 0; i < views.size(); ++i) {
    const json* m = meshoptExtension(views[i]);
    if (!m) continue;
    MeshoptView view;
    const std::string mode = m->at("mode").get<std::string>();
    view.mode = mode == "ATTRIBUTES"  ? MeshoptView::Mode::Attributes
                : mode == "TRIANGLES" ? MeshoptView::Mode::Triangles
                                      : MeshoptView::Mode::Indices;
    const std::string filter = get<std::string>(*m, "filter", "NONE");
    view.filter = filter == "OCTAHEDRAL"    ? MeshoptView::Filter::Octahedral
                  : filter == "QUATERNION"  ? MeshoptView::Filter::Quaternion
                  : filter == "EXPONENTIAL" ? MeshoptView::Filter::Exponential
                                            : MeshoptView::Filter::None;
    view.count = m->at("count").get<size_t>();
    view.byteStride = m->at("byteStride").get<size_t>();
    const auto& source = model_.buffers[m->at("buffer").get<size_t>()].data;
    decodedViews_[int64_t(i)] =
        decodeMeshoptView(view, source.data() + get<size_t>(*m, "byteOffset", 0),
                          m->at("byteLength").get<size_t>(), path_, "bufferView " + std::to_string(i));
  }
}

void SceneBuilder::decodeDraco(const json& prim, const std::string& element) {
  dracoAccessors_.clear();
  const json& draco = prim.at("extensions").at("KHR_draco_mesh_compression");
  const json& attributes = prim.at("attributes");
  std::map<std::string, DracoAttributeRequest> requests;
  for (auto it = draco.at("attributes").begin(); it != draco.at("attributes").end(); ++it) {
    const json& a = array("accessors")[attributes.at(it.key()).get<size_t>()];
    requests[it.key()] = {it.value().get<int64_t>(), a.at("componentType").get<int64_t>(),
                          get(a, "normalized", false)};
  }
  const json& v = array("bufferViews")[draco.at("bufferView").get<size_t>()];
  DracoPrimitive decoded = decodeDracoPrimitive(viewBytes(draco.at("bufferView").get<int64_t>()),
                                                v.at("byteLength").get<size_t>(), requests, path_, element);
  for (auto& [name, values] : decoded.attributes) {
    const int64_t accessor = attributes.at(name).get<int64_t>();
    if (dracoAccessors_.count(accessor))
      fail(element + " KHR_draco_mesh_compression",
           "accessor " + std::to_string(accessor) + " is named by two Draco attributes");
    dracoAccessors_[accessor] = std::move(values);
  }
  const int64_t indices = prim.at("indices").get<int64_t>();
  if (dracoAccessors_.count(indices))
    fail(element + " KHR_draco_mesh_compression",
         "accessor " + std::to_string(indices) + " is both the indices and a Draco attribute");
  DracoAttribute& faces = dracoAccessors_[indices];
  faces.components = 1;
  faces.values.assign(decoded.indices.begin(), decoded.indices.end());
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
  if (n.contains("matrix")) {  // loadAnimations refuses channels on such nodes
    std::vector<double> m = n.at("matrix").get<std::vector<double>>();
    return glm::make_mat4(m.data());  // glTF matrices are column-major, as GLM's
  }
  const NodePose& pose = nodePose_[node];
  glm::dmat4 result(1.0);
  if (pose.translation) {
    result = glm::translate(result, *pose.translation);
  } else if (n.contains("translation")) {
    const auto t = n.at("translation").get<std::vector<double>>();
    result = glm::translate(result, glm::dvec3(t[0], t[1], t[2]));
  }
  if (pose.rotation) {
    result = result * glm::mat4_cast(*pose.rotation);  // sampleAt normalised it
  } else if (n.contains("rotation")) {
    const auto r = n.at("rotation").get<std::vector<double>>();
    glm::dquat q(r[3], r[0], r[1], r[2]);  // glTF stores (x, y, z, w)
    const double length = glm::length(q);
    if (!(length > 0.0)) fail("node " + std::to_string(node), "\"rotation\" is a zero quaternion");
    result = result * glm::mat4_cast(q / length);  // exporters round: renormalise
  }
  if (pose.scale) {
    result = glm::scale(result, *pose.scale);
  } else if (n.contains("scale")) {
    const auto s = n.at("scale").get<std::vector<double>>();
    result = glm::scale(result, glm::dvec3(s[0], s[1], s[2]));
  }
  return result;
}

void SceneBuilder::loadAnimations() {
  const json& animations = array("animations");
  const json& nodes = array("nodes");
  for (size_t a = 0; a < animations.size(); ++a) {
    const json& aj = animations[a];
    const std::string e = "animation " + std::to_string(a);
    Animation anim;
    anim.name = get<std::string>(aj, "name", "");
    const json& samplers = aj.at("samplers");
    std::vector<size_t> outputComponents(samplers.size());
    for (size_t k = 0; k < samplers.size(); ++k) {
      const json& sj = samplers[k];
      const std::string se = e + " sampler " + std::to_string(k);
      AnimationSampler sampler;
      sampler.interpolation = *parseInterpolation(get<std::string>(sj, "interpolation", "LINEAR"));
      size_t components = 0;
      sampler.input = readAccessor(sj.at("input").get<int64_t>(), se + " input", {"SCALAR"}, &components);
      sampler.output = readAccessor(sj.at("output").get<int64_t>(), se + " output",
                                    {"SCALAR", "VEC3", "VEC4"}, &outputComponents[k]);
      anim.samplers.push_back(std::move(sampler));
    }
    // Each channel fixes its sampler's value width: 3 (translation, scale),
    // 4 (rotation) or the target node's morph target count (weights).
    std::vector<size_t> width(samplers.size(), 0);
    const json& channels = aj.at("channels");
    for (size_t k = 0; k < channels.size(); ++k) {
      const json& cj = channels[k];
      const std::string ce = e + " channel " + std::to_string(k);
      const json& target = cj.at("target");
      if (!target.contains("node")) continue;  // an extension's target: nothing to play
      AnimationChannel channel;
      channel.sampler = cj.at("sampler").get<uint32_t>();
      channel.node = target.at("node").get<uint32_t>();
      channel.property = *parseAnimatedProperty(target.at("path").get<std::string>());
      const json& node = nodes[channel.node];
      if (node.contains("matrix"))
        fail(ce, "targets node " + std::to_string(channel.node) +
                     ", which has a \"matrix\" (glTF animates translation, rotation and scale only)");
      size_t w = 0, accessorComponents = 1;
      const char* type = "SCALAR";
      switch (channel.property) {
        case AnimatedProperty::Translation:
        case AnimatedProperty::Scale:
          w = accessorComponents = 3;
          type = "VEC3";
          break;
        case AnimatedProperty::Rotation:
          w = accessorComponents = 4;
          type = "VEC4";
          break;
        case AnimatedProperty::Weights: {
          size_t targets = 0;
          if (node.contains("mesh"))
            for (const json& prim : array("meshes")[node.at("mesh").get<size_t>()].at("primitives"))
              targets = std::max(targets, prim.contains("targets") ? prim.at("targets").size() : size_t(0));
          if (targets == 0)
            fail(ce, "animates the weights of node " + std::to_string(channel.node) +
                         ", whose mesh has no morph targets");
          w = targets;
          break;
        }
      }
      const std::string se = e + " sampler " + std::to_string(channel.sampler);
      if (outputComponents[channel.sampler] != accessorComponents)
        fail(ce, "path \"" + target.at("path").get<std::string>() + "\" needs a " + type + " output; " + se +
                     "'s has " + std::to_string(outputComponents[channel.sampler]) + " components");
      if (width[channel.sampler] != 0 && width[channel.sampler] != w)
        fail(ce, se + " is shared by channels whose values have different sizes");
      width[channel.sampler] = w;
      anim.channels.push_back(channel);
    }
    for (size_t k = 0; k < anim.samplers.size(); ++k) {
      AnimationSampler& sampler = anim.samplers[k];
      sampler.width = width[k] ? width[k] : outputComponents[k];
      const std::string se = e + " sampler " + std::to_string(k);
      checkAnimationSampler(sampler, path_, se);
    }
    for (const AnimationChannel& c : anim.channels) {
      if (c.property != AnimatedProperty::Rotation) continue;
      const AnimationSampler& sampler = anim.samplers[c.sampler];
      const bool cubic = sampler.interpolation == Interpolation::CubicSpline;
      for (size_t key = 0; key < sampler.input.size(); ++key) {
        const double* q = sampler.output.data() + (cubic ? 3 * key + 1 : key) * 4;
        if (q[0] == 0.0 && q[1] == 0.0 && q[2] == 0.0 && q[3] == 0.0)
          fail(e + " sampler " + std::to_string(c.sampler),
               "output key " + std::to_string(key) + " is a zero quaternion (no rotation)");
      }
    }
    AnimationSummary summary = anim.summary();
    summary.channels = uint32_t(channels.size());
    scene_.animations.push_back(summary);
    animations_.push_back(std::move(anim));
  }
  scene_.pose = pose_;
  if (pose_.animation >= 0 && size_t(pose_.animation) >= animations_.size())
    throw InputError("command line", "--animation",
                     "animation " + std::to_string(pose_.animation) + " does not exist: " + path_ + " has " +
                         std::to_string(animations_.size()) + " animation" +
                         (animations_.size() == 1 ? "" : "s"));
  nodePose_ = poseAt(animations_, pose_, nodes.size());
  world_.assign(nodes.size(), std::nullopt);
}

const glm::dmat4& SceneBuilder::worldOf(size_t node) {
  // Up the parent chain to the first node already known, then down.
  std::vector<size_t> chain;
  for (int64_t i = int64_t(node); i >= 0 && !world_[size_t(i)]; i = parent_[size_t(i)])
    chain.push_back(size_t(i));
  for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
    const int64_t p = parent_[*it];
    world_[*it] = (p >= 0 ? *world_[size_t(p)] : glm::dmat4(1.0)) * localMatrix(*it);
  }
  return *world_[node];
}

const std::vector<glm::dmat4>& SceneBuilder::jointMatrices(size_t skin) {
  const auto known = joints_.find(skin);
  if (known != joints_.end()) return known->second;
  const json& s = array("skins")[skin];
  const std::string e = "skin " + std::to_string(skin);
  const json& joints = s.at("joints");
  std::vector<double> inverseBind;
  if (s.contains("inverseBindMatrices")) {
    size_t components = 0;
    const int64_t accessor = s.at("inverseBindMatrices").get<int64_t>();
    inverseBind = readAccessor(accessor, e + " inverseBindMatrices", {"MAT4"}, &components);
    if (inverseBind.size() / 16 < joints.size())
      fail(e, "inverseBindMatrices (accessor " + std::to_string(accessor) + ") has " +
                  std::to_string(inverseBind.size() / 16) + " matrices for " + std::to_string(joints.size()) +
                  " joints");
  }
  std::vector<glm::dmat4> out;
  for (size_t j = 0; j < joints.size(); ++j) {
    const glm::dmat4 ibm =
        inverseBind.empty() ? glm::dmat4(1.0) : glm::make_mat4(inverseBind.data() + 16 * j);
    const glm::dmat4 m = worldOf(joints[j].get<size_t>()) * ibm;
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r)
        if (!std::isfinite(m[c][r])) fail(e, "the matrix of joint " + std::to_string(j) + " is not finite");
    out.push_back(m);
  }
  return joints_[skin] = std::move(out);
}

std::vector<double> SceneBuilder::morphWeights(size_t node, size_t mesh, size_t targets) const {
  const std::optional<std::vector<double>>& animated = nodePose_[node].weights;
  const json& n = array("nodes")[node];
  const json& m = array("meshes")[mesh];
  std::vector<double> w;
  std::string from;
  if (animated) {
    w = *animated;
    from = "the animated weights of node " + std::to_string(node);
  } else if (n.contains("weights")) {
    w = n.at("weights").get<std::vector<double>>();
    from = "node " + std::to_string(node) + " \"weights\"";
  } else if (m.contains("weights")) {
    w = m.at("weights").get<std::vector<double>>();
    from = "mesh " + std::to_string(mesh) + " \"weights\"";
  } else {
    return std::vector<double>(targets, 0.0);
  }
  if (w.size() != targets)
    fail("mesh " + std::to_string(mesh), from + " has " + std::to_string(w.size()) + " entries for " +
                                             std::to_string(targets) + " morph targets");
  return w;
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

// Before the walk allocates anything: the flattened totals, from accessor
// counts summed over every node that instances a mesh. A tiny file can
// name one large accessor from thousands of nodes or primitives; its
// scene is refused here, by count (2^32) or by the memory budget, instead
// of exhausting memory part way through the walk. With the totals known,
// the store is reserved once, so it never holds two copies while growing.
void SceneBuilder::reserveFlattenedScene(const std::vector<size_t>& roots) {
  const json& nodes = array("nodes");
  const json& accessors = array("accessors");
  struct MeshTotals {
    uint64_t vertices = 0, triangles = 0, primitives = 0, largestPrimitive = 0;
    uint64_t tangentCorners = 0;  // 3 per triangle of a primitive with a normal map
    bool colors = false, counted = false;
  };
  std::vector<MeshTotals> meshes(array("meshes").size());
  const auto totalsOf = [&](size_t mesh) -> const MeshTotals& {
    MeshTotals& t = meshes[mesh];
    if (t.counted) return t;
    t.counted = true;
    for (const json& prim : array("meshes")[mesh].at("primitives")) {
      const int64_t mode = get<int64_t>(prim, "mode", 4);
      const json& attributes = prim.at("attributes");
      if (mode < 4 || !attributes.contains("POSITION")) continue;
      const uint64_t v = accessors[attributes.at("POSITION").get<size_t>()].at("count").get<uint64_t>();
      const uint64_t n = prim.contains("indices")
                             ? accessors[prim.at("indices").get<size_t>()].at("count").get<uint64_t>()
                             : v;
      t.vertices += v;
      const uint64_t tris = mode == 4 ? n / 3 : (n >= 3 ? n - 2 : 0);
      t.triangles += tris;
      if (prim.contains("material") && scene_.materials[prim.at("material").get<size_t>()].normalTexture >= 0)
        t.tangentCorners += 3 * tris;
      t.primitives += 1;
      t.largestPrimitive = std::max(t.largestPrimitive, std::max(v, n));
      t.colors = t.colors || attributes.contains("COLOR_0");
    }
    return t;
  };
  uint64_t vertices = 0, triangles = 0, instances = 0, largestPrimitive = 0, tangentCorners = 0;
  bool colors = false;
  std::vector<size_t> stack(roots.rbegin(), roots.rend());
  while (!stack.empty()) {
    const json& n = nodes[stack.back()];
    stack.pop_back();
    if (n.contains("mesh")) {
      const MeshTotals& t = totalsOf(n.at("mesh").get<size_t>());
      vertices = addSat(vertices, t.vertices);
      triangles = addSat(triangles, t.triangles);
      tangentCorners = addSat(tangentCorners, t.tangentCorners);
      instances = addSat(instances, t.primitives);
      largestPrimitive = std::max(largestPrimitive, t.largestPrimitive);
      colors = colors || t.colors;
    }
    if (n.contains("children"))
      for (const json& c : n.at("children")) stack.push_back(c.get<size_t>());
  }
  if (vertices >= kNoId)
    fail("scene", "the node tree instances meshes into " + std::to_string(vertices) +
                      " vertices; the scene store holds fewer than 2^32");
  if (triangles >= kNoId)
    fail("scene", "the node tree instances meshes into " + std::to_string(triangles) +
                      " triangles; the scene store holds fewer than 2^32");

  // Bytes per vertex: worldPositions (double), positions, normals,
  // texcoords, colours when any primitive has them; per triangle its
  // indices; per instance the Instance; and the largest primitive's
  // accessors read as doubles while it is flattened (8 components).
  const uint64_t perVertex =
      sizeof(glm::dvec3) + sizeof(glm::vec3) * 2 + sizeof(glm::vec2) + (colors ? sizeof(glm::vec4) : 0);
  MemoryEstimate estimate;
  estimate.add("loaded file", currentRssBytes());
  estimate.add("vertices", mulSat(vertices, perVertex));
  estimate.add("triangles", mulSat(triangles, sizeof(glm::uvec3)));
  // Only primitives with a normal map carry tangents (SPEC §8).
  if (tangentCorners > 0) estimate.add("tangents", mulSat(tangentCorners, sizeof(glm::vec4)));
  estimate.add("instances", mulSat(instances, sizeof(Instance)));
  estimate.add("largest primitive", mulSat(largestPrimitive, 8 * sizeof(double) + sizeof(uint32_t)));
  checkMemory(estimate, budget_, path_, "scene",
              "flattening " + std::to_string(instances) + " instances into " + std::to_string(vertices) +
                  " vertices and " + std::to_string(triangles) + " triangles");

  scene_.worldPositions.reserve(vertices);
  scene_.positions.reserve(vertices);
  scene_.normals.reserve(vertices);
  scene_.texcoords.reserve(vertices);
  if (colors) scene_.colors.reserve(vertices);
  scene_.triangles.reserve(triangles);
  scene_.tangents.reserve(tangentCorners);
  scene_.instances.reserve(instances);
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
  inst.material = materialOf(prim);
  inst.firstVertex = uint32_t(scene_.positions.size());
  inst.firstTriangle = uint32_t(scene_.triangles.size());

  // No POSITION: the primitive keeps its instance number and draws nothing.
  if (!attributes.contains("POSITION")) {
    scene_.instances.push_back(inst);
    return;
  }
  // Draco streams decode per instance: a mesh instanced by several nodes
  // decodes once for each, so only one primitive's data is held at a time
  // (the flattened scene's memory estimate counts one).
  const bool draco =
      prim.contains("extensions") && prim.at("extensions").contains("KHR_draco_mesh_compression");
  if (draco) decodeDraco(prim, e);
  VertexData vertices = readVertexData(prim, e, inst);
  if (prim.contains("targets"))
    inst.morphed = applyMorphTargets(prim, e, morphWeights(node, mesh, prim.at("targets").size()), vertices);
  const std::vector<glm::uvec3> triangles = triangulate(prim, e, vertices.count);
  // Tangents on the (morphed) object-space mesh, before the skin or the
  // world matrix moves it: the space normal maps are baked in.
  std::vector<glm::dvec4> tangents;
  if (vertices.needsTangents) {
    inst.generatedTangents = vertices.tangents.empty();
    tangents = objectTangents(vertices, triangles);
  }
  const json& n = array("nodes")[node];
  glm::dmat4 placement = world;
  if (n.contains("skin") && attributes.contains("JOINTS_0") && attributes.contains("WEIGHTS_0")) {
    // The skin places the vertices in world space; the node's own
    // transform is ignored (glTF 2.0 §3.7.3.3).
    inst.skinned = true;
    inst.worldFromObject = glm::dmat4(1.0);
    placement = glm::dmat4(1.0);
    inst.mirrored = applySkin(prim, e, n.at("skin").get<size_t>(), vertices);
  }
  appendVertices(inst, vertices, placement, e);
  appendTriangles(inst, triangles);
  if (!tangents.empty()) appendTangents(inst, vertices, triangles, tangents, placement);
  dracoAccessors_.clear();
  scene_.instances.push_back(inst);
}

uint32_t SceneBuilder::materialOf(const json& prim) {
  if (prim.contains("material")) return prim.at("material").get<uint32_t>();
  if (defaultMaterial_ < 0) {
    Material m;
    m.name = "default";
    m.isDefault = true;
    defaultMaterial_ = int64_t(scene_.materials.size());
    scene_.materials.push_back(m);
  }
  return uint32_t(defaultMaterial_);
}

// The texcoord set the base colour texture reads (TEXCOORD_0 unless it
// says otherwise); without one, the emissive texture's set. loadMaterials
// drops an emissive texture that names another set than the base colour.
int64_t SceneBuilder::texCoordSetOf(const json& prim) const {
  if (!prim.contains("material")) return 0;
  return materialTexCoordSet(array("materials")[prim.at("material").get<size_t>()]);
}

// The one uv set a material's textures are read through (Scene::texcoords):
// the first of its textureInfos, in the order base colour, emissive,
// metallic-roughness, normal, occlusion; 0 without any.
int64_t materialTexCoordSet(const json& m) {
  const json* pbr = m.contains("pbrMetallicRoughness") ? &m.at("pbrMetallicRoughness") : nullptr;
  if (pbr && pbr->contains("baseColorTexture")) return texCoordOf(pbr->at("baseColorTexture"));
  if (m.contains("emissiveTexture")) return texCoordOf(m.at("emissiveTexture"));
  if (pbr && pbr->contains("metallicRoughnessTexture"))
    return texCoordOf(pbr->at("metallicRoughnessTexture"));
  if (m.contains("normalTexture")) return texCoordOf(m.at("normalTexture"));
  if (m.contains("occlusionTexture")) return texCoordOf(m.at("occlusionTexture"));
  return 0;
}

const json* textureTransformOf(const json& textureInfo) {
  const auto ext = textureInfo.find("extensions");
  if (ext == textureInfo.end() || !ext->contains("KHR_texture_transform")) return nullptr;
  return &ext->at("KHR_texture_transform");
}

// A textureInfo's texcoord set: KHR_texture_transform's "texCoord"
// overrides the textureInfo's own.
int64_t texCoordOf(const json& textureInfo) {
  const json* transform = textureTransformOf(textureInfo);
  if (transform && transform->contains("texCoord")) return transform->at("texCoord").get<int64_t>();
  return textureInfo.value("texCoord", int64_t(0));
}

SceneBuilder::VertexData SceneBuilder::readVertexData(const json& prim, const std::string& e,
                                                      Instance& inst) const {
  const json& attributes = prim.at("attributes");
  VertexData v;
  size_t components = 0;
  v.positionAccessor = attributes.at("POSITION").get<int64_t>();
  v.positions = readAccessor(v.positionAccessor, e + " POSITION", {"VEC3"}, &components);
  v.count = v.positions.size() / 3;
  if (scene_.positions.size() + v.count >= size_t(kNoId)) fail(e, "the scene has more than 2^32 vertices");

  if (attributes.contains("NORMAL")) {
    v.normals = readAccessor(attributes.at("NORMAL").get<int64_t>(), e + " NORMAL", {"VEC3"}, &components);
    if (v.normals.size() != v.positions.size())
      fail(e, "NORMAL has " + std::to_string(v.normals.size() / 3) + " elements, POSITION " +
                  std::to_string(v.count));
    inst.normals = NormalSource::Authored;
  }
  const std::string uvName = "TEXCOORD_" + std::to_string(texCoordSetOf(prim));
  if (attributes.contains(uvName)) {
    v.texcoords = readAccessor(attributes.at(uvName).get<int64_t>(), e + " " + uvName, {"VEC2"}, &components);
    if (v.texcoords.size() / 2 != v.count)
      fail(e, uvName + " has " + std::to_string(v.texcoords.size() / 2) + " elements, POSITION " +
                  std::to_string(v.count));
    inst.hasTexcoords = true;
  }
  v.colors = readColors(attributes, e, v.count);
  inst.hasColors = !v.colors.empty();
  v.needsTangents = scene_.materials[inst.material].normalTexture >= 0;
  if (v.needsTangents && attributes.contains("TANGENT")) {
    // glTF 2.0 §3.7.2.1: VEC4 float, or normalized signed byte/short; xyz
    // unit, w = ±1 (its sign is read).
    const int64_t ta = attributes.at("TANGENT").get<int64_t>();
    const json& a = array("accessors")[size_t(ta)];
    const std::string te = e + " TANGENT (accessor " + std::to_string(ta) + ")";
    const int64_t ct = a.at("componentType").get<int64_t>();
    if (!(ct == 5126 || ((ct == 5120 || ct == 5122) && get(a, "normalized", false))))
      fail(te, "componentType " + std::to_string(ct) +
                   " must be 5126, or 5120 or 5122 with \"normalized\": true");
    v.tangents = readAccessor(ta, e + " TANGENT", {"VEC4"}, &components);
    if (v.tangents.size() / 4 != v.count)
      fail(te,
           "has " + std::to_string(v.tangents.size() / 4) + " elements, POSITION " + std::to_string(v.count));
  }
  return v;
}

void SceneBuilder::appendVertices(Instance& inst, const VertexData& v, const glm::dmat4& world,
                                  const std::string& e) {
  // Scene::colors stays empty until an instance has COLOR_0; then it is
  // back-filled with white for the vertices before it.
  if (inst.hasColors && scene_.colors.empty()) scene_.colors.assign(scene_.positions.size(), glm::vec4(1.0f));

  // Normals transform by the cofactor matrix: the inverse transpose scaled
  // by the determinant, defined even for singular matrices; the sign keeps
  // normals on the same side for mirroring transforms.
  const glm::dmat3 m3(world);
  const glm::dmat3 cofactor(glm::cross(m3[1], m3[2]), glm::cross(m3[2], m3[0]), glm::cross(m3[0], m3[1]));
  const double sign = glm::determinant(m3) < 0.0 ? -1.0 : 1.0;
  const std::vector<double>& pos = v.positions;
  const std::vector<double>& nrm = v.normals;
  const std::vector<double>& uv = v.texcoords;
  for (size_t i = 0; i < v.count; ++i) {
    const glm::dvec3 p = glm::dvec3(world * glm::dvec4(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2], 1.0));
    // Test in double: converting a value beyond the float range is undefined.
    constexpr double kFloatMax = std::numeric_limits<float>::max();
    if (!(std::abs(p.x) <= kFloatMax && std::abs(p.y) <= kFloatMax && std::abs(p.z) <= kFloatMax))
      fail(e + " POSITION (accessor " + std::to_string(v.positionAccessor) + ")",
           "vertex " + std::to_string(i) + " is not finite in world space as float");
    const glm::vec3 pf(p);
    scene_.worldPositions.push_back(p);
    scene_.positions.push_back(pf);
    scene_.bounds.extend(glm::dvec3(pf));
    glm::dvec3 n(0.0);
    if (!nrm.empty()) {
      n = sign * (cofactor * glm::dvec3(nrm[3 * i], nrm[3 * i + 1], nrm[3 * i + 2]));
      const double len = glm::length(n);
      n = len > 0.0 && std::isfinite(len) ? n / len : glm::dvec3(0.0);  // zero: use the face normal
    }
    scene_.normals.emplace_back(n);
    scene_.texcoords.emplace_back(uv.empty() ? glm::vec2(0.0f)
                                             : glm::vec2(float(uv[2 * i]), float(uv[2 * i + 1])));
    if (inst.hasColors || !scene_.colors.empty())
      scene_.colors.push_back(inst.hasColors ? v.colors[i] : glm::vec4(1.0f));
  }
  inst.vertexCount = uint32_t(v.count);
}

bool SceneBuilder::applyMorphTargets(const json& prim, const std::string& e,
                                     const std::vector<double>& weights, VertexData& v) const {
  const json& targets = prim.at("targets");
  bool any = false;
  for (size_t t = 0; t < targets.size(); ++t) {
    if (weights[t] == 0.0) continue;
    any = true;
    const std::string te = e + " target " + std::to_string(t);
    for (const char* attribute : {"POSITION", "NORMAL", "TANGENT"}) {
      const char kind = attribute[0];
      std::vector<double>& base = kind == 'P' ? v.positions : kind == 'N' ? v.normals : v.tangents;
      // No NORMAL to move: face normals; no TANGENT read: none needed, or generated from the morphed mesh.
      if (!targets[t].contains(attribute) || base.empty()) continue;
      size_t components = 0;
      const std::vector<double> delta =
          readAccessor(targets[t].at(attribute).get<int64_t>(), te + " " + attribute, {"VEC3"}, &components);
      const size_t width = kind == 'T' ? 4 : 3;  // a TANGENT delta moves xyz, not w
      if (delta.size() / 3 != base.size() / width)
        fail(te, std::string(attribute) + " has " + std::to_string(delta.size() / 3) +
                     " elements, the primitive " + std::to_string(v.count) + " vertices");
      for (size_t i = 0; i < delta.size(); ++i) base[i / 3 * width + i % 3] += weights[t] * delta[i];
    }
  }
  return any;
}

bool SceneBuilder::applySkin(const json& prim, const std::string& e, size_t skin, VertexData& v) {
  const std::vector<glm::dmat4>& joints = jointMatrices(skin);
  const json& attributes = prim.at("attributes");
  // JOINTS_0/WEIGHTS_0, JOINTS_1/WEIGHTS_1, ...: four influences per set,
  // read and checked first; then one blended matrix per vertex at a time.
  struct Influences {
    std::vector<double> joint, weight;
    std::string weightElement;
  };
  std::vector<Influences> sets;
  for (int set = 0;; ++set) {
    const std::string jn = "JOINTS_" + std::to_string(set), wn = "WEIGHTS_" + std::to_string(set);
    if (!attributes.contains(jn) || !attributes.contains(wn)) break;
    const int64_t ja = attributes.at(jn).get<int64_t>(), wa = attributes.at(wn).get<int64_t>();
    const std::string je = e + " " + jn + " (accessor " + std::to_string(ja) + ")";
    const std::string we = e + " " + wn + " (accessor " + std::to_string(wa) + ")";
    const int64_t jct = array("accessors")[size_t(ja)].at("componentType").get<int64_t>();
    if (jct != 5121 && jct != 5123)
      fail(je, "componentType " + std::to_string(jct) + " must be 5121 or 5123");
    size_t components = 0;
    Influences in{readAccessor(ja, e + " " + jn, {"VEC4"}, &components),
                  readAccessor(wa, e + " " + wn, {"VEC4"}, &components), we};
    if (in.joint.size() != 4 * v.count)
      fail(je,
           "has " + std::to_string(in.joint.size() / 4) + " elements, POSITION " + std::to_string(v.count));
    if (in.weight.size() != 4 * v.count)
      fail(we,
           "has " + std::to_string(in.weight.size() / 4) + " elements, POSITION " + std::to_string(v.count));
    for (size_t i = 0; i < 4 * v.count; ++i) {
      if (in.joint[i] >= double(joints.size()))
        fail(je, "vertex " + std::to_string(i / 4) + " names joint " + std::to_string(uint64_t(in.joint[i])) +
                     "; skin " + std::to_string(skin) + " has " + std::to_string(joints.size()) + " joints");
      if (in.weight[i] < 0.0) fail(we, "vertex " + std::to_string(i / 4) + " has a negative weight");
    }
    sets.push_back(std::move(in));
  }
  size_t mirroring = 0;
  for (size_t i = 0; i < v.count; ++i) {
    glm::dmat4 m(0.0);
    double weightSum = 0.0;
    for (const Influences& in : sets)
      for (size_t k = 4 * i; k < 4 * i + 4; ++k)
        if (in.weight[k] != 0.0) {
          m += in.weight[k] * joints[size_t(in.joint[k])];
          weightSum += in.weight[k];
        }
    // Weights should sum to 1; exporters round (and 8-bit weights cannot
    // say 1/3): normalise.
    if (!(weightSum > 0.0))
      fail(sets.front().weightElement, "vertex " + std::to_string(i) + " has weights summing to 0");
    m /= weightSum;
    const glm::dvec3 p =
        glm::dvec3(m * glm::dvec4(v.positions[3 * i], v.positions[3 * i + 1], v.positions[3 * i + 2], 1.0));
    std::copy_n(&p.x, 3, &v.positions[3 * i]);
    const glm::dmat3 m3(m);
    const double det = glm::determinant(m3);
    mirroring += det < 0.0;
    // Tangents are directions on the surface: they move by m3 itself.
    if (v.needsTangents) v.skins.push_back(m3);
    if (!v.normals.empty()) {
      // The inverse transpose, as the cofactor matrix (defined when m3 is
      // singular; its sign kept by det), renormalised.
      const glm::dmat3 cofactor(glm::cross(m3[1], m3[2]), glm::cross(m3[2], m3[0]), glm::cross(m3[0], m3[1]));
      glm::dvec3 n = (det < 0.0 ? -1.0 : 1.0) *
                     (cofactor * glm::dvec3(v.normals[3 * i], v.normals[3 * i + 1], v.normals[3 * i + 2]));
      const double len = glm::length(n);
      if (len > 0.0 && std::isfinite(len)) n /= len;
      std::copy_n(&n.x, 3, &v.normals[3 * i]);
    }
  }
  return 2 * mirroring > v.count;
}

// Triangulates (SPEC §1) the primitive's indices, or its vertices in order
// when it has none, into Scene::triangles.
std::vector<glm::uvec3> SceneBuilder::triangulate(const json& prim, const std::string& e,
                                                  size_t vertexCount) const {
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
  const int64_t mode = get<int64_t>(prim, "mode", 4);
  if (mode == 4) {
    if (n % 3 != 0)
      fail(e, std::to_string(n) + (prim.contains("indices") ? " indices" : " vertices") +
                  " for TRIANGLES is not a multiple of 3");
    for (size_t i = 0; i + 2 < n; i += 3) tris.emplace_back(indices[i], indices[i + 1], indices[i + 2]);
  } else if (mode == 5) {
    for (size_t i = 0; i + 2 < n; ++i)
      tris.push_back(i % 2 == 0 ? glm::uvec3(indices[i], indices[i + 1], indices[i + 2])
                                : glm::uvec3(indices[i + 1], indices[i], indices[i + 2]));
  } else {
    for (size_t i = 0; i + 2 < n; ++i) tris.emplace_back(indices[0], indices[i + 1], indices[i + 2]);
  }
  if (scene_.triangles.size() + tris.size() >= size_t(kNoId))
    fail(e, "the scene has more than 2^32 triangles");
  return tris;
}

void SceneBuilder::appendTriangles(Instance& inst, const std::vector<glm::uvec3>& tris) {
  for (glm::uvec3 t : tris) {
    if (inst.mirrored) std::swap(t.y, t.z);  // keep CCW = front in world space
    t += glm::uvec3(inst.firstVertex);
    scene_.triangles.push_back(t);
    if (isDegenerate(scene_, scene_.triangles.size() - 1)) ++inst.degenerateCount;
  }
  inst.triangleCount = uint32_t(tris.size());
}

std::vector<glm::dvec4> SceneBuilder::objectTangents(const VertexData& v,
                                                     const std::vector<glm::uvec3>& triangles) const {
  if (!v.tangents.empty()) {
    std::vector<glm::dvec4> out;
    out.reserve(3 * triangles.size());
    for (const glm::uvec3& t : triangles)
      for (int k = 0; k < 3; ++k) {
        const double* x = &v.tangents[4 * size_t(t[k])];
        out.emplace_back(x[0], x[1], x[2], x[3] < 0.0 ? -1.0 : 1.0);
      }
    return out;
  }
  std::vector<glm::dvec3> positions(v.count), normals(v.normals.empty() ? 0 : v.count);
  std::vector<glm::dvec2> uvs(v.texcoords.empty() ? 0 : v.count);
  for (size_t i = 0; i < v.count; ++i) {
    positions[i] = glm::dvec3(v.positions[3 * i], v.positions[3 * i + 1], v.positions[3 * i + 2]);
    if (!normals.empty())
      normals[i] = glm::dvec3(v.normals[3 * i], v.normals[3 * i + 1], v.normals[3 * i + 2]);
    if (!uvs.empty()) uvs[i] = glm::dvec2(v.texcoords[2 * i], v.texcoords[2 * i + 1]);
  }
  return generateTangents(positions, normals, uvs, triangles);
}

void SceneBuilder::appendTangents(Instance& inst, const VertexData& v,
                                  const std::vector<glm::uvec3>& triangles,
                                  const std::vector<glm::dvec4>& corners, const glm::dmat4& world) {
  inst.firstTangent = uint32_t(scene_.tangents.size());
  const glm::dmat3 m3(world);
  for (size_t f = 0; f < triangles.size(); ++f) {
    glm::vec4 stored[3];
    for (int k = 0; k < 3; ++k) {
      const glm::dvec4 t = corners[3 * f + size_t(k)];
      const glm::dmat3& m = v.skins.empty() ? m3 : v.skins[triangles[f][k]];
      glm::dvec3 xyz = m * glm::dvec3(t);
      const double length = glm::length(xyz);
      xyz =
          length > 0.0 && std::isfinite(length) ? xyz / length : glm::dvec3(0.0);  // zero: no normal map here
      // A mirroring matrix turns the frame's handedness (the normal follows
      // the cofactor, appendVertices): the bitangent keeps its side.
      const double w = glm::determinant(m) < 0.0 ? -t.w : t.w;
      stored[k] = glm::vec4(glm::vec3(xyz), float(w));
    }
    if (inst.mirrored) std::swap(stored[1], stored[2]);  // as appendTriangles swapped the corners
    scene_.tangents.insert(scene_.tangents.end(), stored, stored + 3);
  }
}

void SceneBuilder::addCamera(size_t node, const glm::dmat4& world) {
  ++scene_.stats.cameraNodes;
  const size_t index = array("nodes")[node].at("camera").get<size_t>();
  const json& c = array("cameras")[index];
  const std::string e = "node " + std::to_string(node);
  // The first camera node in walk order is the scene's camera (SPEC §2) and
  // must be usable; later ones are kept for --camera N, which checks its own.
  const bool first = !scene_.camera;
  if (first && (glm::length(glm::cross(glm::dvec3(world[0]), glm::dvec3(world[1]))) == 0.0 ||
                glm::length(glm::dvec3(world[2])) == 0.0))
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
  if (first) scene_.camera = cam;
  scene_.cameras.push_back(cam);
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
    // The data maps, each through the material's one uv set (Scene::texcoords).
    const int64_t set = materialTexCoordSet(m);
    auto dataMap = [&](const json& owner, const char* key, const std::string& feature) {
      if (!owner.contains(key)) return int32_t(-1);
      if (texCoordOf(owner.at(key)) != set) {
        noteIgnored(feature + " texture on another texCoord set than the base colour texture", "material");
        return int32_t(-1);
      }
      return decodableTexture(owner.at(key), true);
    };
    if (m.contains("pbrMetallicRoughness"))
      mat.metallicRoughnessTexture =
          dataMap(m.at("pbrMetallicRoughness"), "metallicRoughnessTexture", "metallicRoughness");
    mat.normalTexture = dataMap(m, "normalTexture", "normal");
    if (mat.normalTexture >= 0) mat.normalScale = float(get(m.at("normalTexture"), "scale", 1.0));
    mat.occlusionTexture = dataMap(m, "occlusionTexture", "occlusion");
    if (mat.occlusionTexture >= 0)
      mat.occlusionStrength =
          unit(get(m.at("occlusionTexture"), "strength", 1.0), "occlusionTexture strength");
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
      const bool sameSet =
          !m.contains("pbrMetallicRoughness") || !m.at("pbrMetallicRoughness").contains("baseColorTexture") ||
          texCoordOf(m.at("pbrMetallicRoughness").at("baseColorTexture")) == texCoordOf(info);
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

int32_t SceneBuilder::decodableTexture(const json& textureInfo, bool data) {
  const int32_t tex = textureInfo.at("index").get<int32_t>();
  if (scene_.textures[size_t(tex)].image < 0) {
    noteIgnored("texture without a decodable image", "textureInfo");
    return -1;
  }
  // KHR_texture_transform and data maps (read linearly) get a texture of
  // this textureInfo's own, sharing the image (its chain of that kind,
  // TextureSet) and the sampler.
  Texture t = scene_.textures[size_t(tex)];
  t.data = data;
  if (const json* transform = textureTransformOf(textureInfo)) {
    const auto pair = [&](const char* key, double fallback) {
      const auto v = get<std::vector<double>>(*transform, key, {fallback, fallback});
      return glm::dvec2(v[0], v[1]);
    };
    t.transform = TextureTransform(pair("offset", 0.0), get(*transform, "rotation", 0.0), pair("scale", 1.0));
  }
  if (!data && t.transform.identity) return tex;
  scene_.textures.push_back(t);
  return int32_t(scene_.textures.size() - 1);
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
    if (m.contains("extensions") && m.at("extensions").contains("KHR_materials_transmission") &&
        m.at("extensions").at("KHR_materials_transmission").contains("transmissionTexture"))
      noteIgnored("transmission texture", "material");
  }
  for (const json& mesh : array("meshes"))
    for (const json& prim : mesh.at("primitives")) {
      // Morph targets move POSITION, NORMAL and TANGENT.
      if (!prim.contains("targets")) continue;
      bool other = false;
      for (const json& target : prim.at("targets"))
        for (auto it = target.begin(); it != target.end(); ++it)
          other = other || it.key().rfind("TEXCOORD_", 0) == 0 || it.key().rfind("COLOR_", 0) == 0;
      if (other) noteIgnored("morph target TEXCOORD_n/COLOR_n deltas", "primitive");
    }
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
  decodeMeshoptViews();
  loadTextures();
  loadMaterials();
  checkNodeGraph(parent_);
  loadAnimations();
  const std::vector<size_t> roots = rootNodes(parent_);
  reserveFlattenedScene(roots);
  walk(roots);
  noteIgnoredFeatures();
  return std::move(scene_);
}

}  // namespace

Scene buildScene(const std::string& path, const nlohmann::json& doc, const tinygltf::Model& model,
                 const MemoryBudget& budget, const PoseRequest& pose) {
  return SceneBuilder(path, doc, model, budget, pose).build();
}

}  // namespace rastray
