#include "common/gltf/check.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <set>

#include "common/error.h"
#include "common/math_constants.h"

namespace rastray {

namespace {

using json = nlohmann::json;

// An accessor without a bufferView (zeros, or sparse over zeros) costs
// memory but no file bytes; this bound keeps a hostile "count" from
// allocating gigabytes while leaving far more than any real use.
constexpr int64_t kMaxZeroFilledElements = int64_t(1) << 24;

constexpr const char* kSupportedExtensions[] = {
    "KHR_lights_punctual",     "KHR_materials_transmission",
    "KHR_materials_ior",       "KHR_materials_emissive_strength",
    "KHR_mesh_quantization",   "KHR_draco_mesh_compression",
    "EXT_meshopt_compression", "KHR_meshopt_compression",
    "KHR_texture_transform",
};

// The two names of meshopt compression: the vendor extension and its
// Khronos successor share the bufferView and buffer schema.
constexpr const char* kMeshoptExtensions[] = {"EXT_meshopt_compression", "KHR_meshopt_compression"};

const char* typeName(const json& v) {
  switch (v.type()) {
    case json::value_t::null:
      return "null";
    case json::value_t::object:
      return "an object";
    case json::value_t::array:
      return "an array";
    case json::value_t::string:
      return "a string";
    case json::value_t::boolean:
      return "a boolean";
    case json::value_t::number_integer:
    case json::value_t::number_unsigned:
      return "an integer";
    case json::value_t::number_float:
      return "a number";
    default:
      return "an unknown value";
  }
}

// Checks one JSON object ("element", e.g. "accessor 3") field by field.
class Checker {
 public:
  Checker(const GltfCheckContext& context, const json& doc) : context_(context), doc_(doc) {}

  [[noreturn]] void fail(const std::string& element, const std::string& message) const {
    throw InputError(context_.file, element, message);
  }

  size_t countOf(const char* topLevel) const {
    auto it = doc_.find(topLevel);
    return (it != doc_.end() && it->is_array()) ? it->size() : 0;
  }

  const json* member(const json& obj, const char* key) const {
    auto it = obj.find(key);
    return it == obj.end() ? nullptr : &*it;
  }

  const json& object(const json& v, const std::string& element) const {
    if (!v.is_object()) fail(element, std::string("must be an object, got ") + typeName(v));
    return v;
  }

  // A top-level array of objects, possibly absent.
  const json* objectArray(const json& obj, const char* key, const std::string& element) const {
    const json* v = member(obj, key);
    if (!v) return nullptr;
    if (!v->is_array()) fail(element, std::string("\"") + key + "\" must be an array, got " + typeName(*v));
    return v;
  }

  // A non-negative integer; absent: `fallback`, or an error if required.
  int64_t integer(const json& obj, const char* key, const std::string& element, bool required,
                  int64_t fallback = -1) const {
    const json* v = member(obj, key);
    if (!v) {
      if (required) fail(element, std::string("\"") + key + "\" is missing");
      return fallback;
    }
    if (!v->is_number_integer())
      fail(element, std::string("\"") + key + "\" must be an integer, got " + typeName(*v));
    if (v->is_number_unsigned()) {
      const uint64_t u = v->get<uint64_t>();
      if (u > uint64_t(INT64_MAX)) fail(element, std::string("\"") + key + "\" is too large");
      return int64_t(u);
    }
    const int64_t i = v->get<int64_t>();
    if (i < 0) fail(element, std::string("\"") + key + "\" must not be negative, got " + std::to_string(i));
    return i;
  }

  // An index into the top-level array `target`.
  int64_t index(const json& obj, const char* key, const std::string& element, const char* target,
                bool required = false) const {
    const int64_t i = integer(obj, key, element, required);
    if (i >= 0 && size_t(i) >= countOf(target))
      fail(element, std::string("\"") + key + "\" refers to " + singular(target) + " " + std::to_string(i) +
                        ", which does not exist (" + std::to_string(countOf(target)) + " " + target + ")");
    return i;
  }

  double number(const json& obj, const char* key, const std::string& element, bool required,
                double fallback = 0.0) const {
    const json* v = member(obj, key);
    if (!v) {
      if (required) fail(element, std::string("\"") + key + "\" is missing");
      return fallback;
    }
    if (!v->is_number()) fail(element, std::string("\"") + key + "\" must be a number, got " + typeName(*v));
    const double d = v->get<double>();
    if (!std::isfinite(d)) fail(element, std::string("\"") + key + "\" is not finite");
    return d;
  }

  // A number the scene stores as a float (material factors, light values):
  // beyond float range it would turn into infinity unnoticed.
  double floatNumber(const json& obj, const char* key, const std::string& element, bool required,
                     double fallback = 0.0) const {
    const double d = number(obj, key, element, required, fallback);
    if (std::abs(d) > double(std::numeric_limits<float>::max())) {
      char value[32];
      std::snprintf(value, sizeof value, "%g", d);
      fail(element, std::string("\"") + key + "\" " + value + " is out of float range");
    }
    return d;
  }

  void numberArray(const json& obj, const char* key, const std::string& element, size_t minSize,
                   size_t maxSize) const {
    const json* v = member(obj, key);
    if (!v) return;
    if (!v->is_array()) fail(element, std::string("\"") + key + "\" must be an array, got " + typeName(*v));
    if (v->size() < minSize || v->size() > maxSize)
      fail(element, std::string("\"") + key + "\" has " + std::to_string(v->size()) + " entries, expected " +
                        (minSize == maxSize ? std::to_string(minSize)
                                            : std::to_string(minSize) + " to " + std::to_string(maxSize)));
    for (size_t i = 0; i < v->size(); ++i) {
      const json& e = (*v)[i];
      if (!e.is_number())
        fail(element,
             std::string("\"") + key + "\"[" + std::to_string(i) + "] must be a number, got " + typeName(e));
      if (!std::isfinite(e.get<double>()))
        fail(element, std::string("\"") + key + "\"[" + std::to_string(i) + "] is not finite");
    }
  }

  std::string string(const json& obj, const char* key, const std::string& element, bool required) const {
    const json* v = member(obj, key);
    if (!v) {
      if (required) fail(element, std::string("\"") + key + "\" is missing");
      return {};
    }
    if (!v->is_string()) fail(element, std::string("\"") + key + "\" must be a string, got " + typeName(*v));
    return v->get<std::string>();
  }

  void boolean(const json& obj, const char* key, const std::string& element) const {
    const json* v = member(obj, key);
    if (v && !v->is_boolean())
      fail(element, std::string("\"") + key + "\" must be a boolean, got " + typeName(*v));
  }

  // A glTF textureInfo: {"index": texture, "texCoord": n}.
  void textureInfo(const json& obj, const char* key, const std::string& element) const {
    const json* v = member(obj, key);
    if (!v) return;
    const std::string e = element + " " + key;
    object(*v, e);
    index(*v, "index", e, "textures", true);
    integer(*v, "texCoord", e, false);
    number(*v, "scale", e, false);
    number(*v, "strength", e, false);
    if (const json* ext = member(*v, "extensions")) {
      object(*ext, e + " extensions");
      if (const json* t = member(*ext, "KHR_texture_transform")) {
        const std::string te = e + " KHR_texture_transform";
        object(*t, te);
        numberArray(*t, "offset", te, 2, 2);
        numberArray(*t, "scale", te, 2, 2);
        floatNumber(*t, "rotation", te, false);
        integer(*t, "texCoord", te, false);
        for (const char* field : {"offset", "scale"})
          if (const json* a = member(*t, field))
            for (const json& x : *a)
              if (std::abs(x.get<double>()) > double(std::numeric_limits<float>::max()))
                fail(te, std::string("\"") + field + "\" is out of float range");
      }
    }
  }

  static std::string singular(const char* plural) {
    std::string s(plural);
    if (s == "meshes") return "mesh";
    if (!s.empty() && s.back() == 's') s.pop_back();
    return s;
  }

 private:
  const GltfCheckContext& context_;
  const json& doc_;
};

// Checks that [offset, offset + size) lies inside [0, limit).
bool fits(int64_t offset, int64_t size, int64_t limit) {
  return offset >= 0 && size >= 0 && offset <= limit && size <= limit - offset;
}

}  // namespace

int64_t componentSize(int64_t componentType) {
  switch (componentType) {
    case 5120:
    case 5121:
      return 1;
    case 5122:
    case 5123:
      return 2;
    case 5125:
    case 5126:
      return 4;
    default:
      return 0;
  }
}

int64_t componentCount(const std::string& type) {
  if (type == "SCALAR") return 1;
  if (type == "VEC2") return 2;
  if (type == "VEC3") return 3;
  if (type == "VEC4") return 4;
  if (type == "MAT2") return 4;
  if (type == "MAT3") return 9;
  if (type == "MAT4") return 16;
  return 0;
}

bool isSupportedExtension(const std::string& name) {
  for (const char* s : kSupportedExtensions)
    if (name == s) return true;
  return false;
}

bool isMeshoptFallbackBuffer(const nlohmann::json& buffer) {
  const auto ext = buffer.find("extensions");
  if (ext == buffer.end() || !ext->is_object()) return false;
  for (const char* name : kMeshoptExtensions) {
    const auto m = ext->find(name);
    if (m != ext->end() && m->is_object() && m->value("fallback", json(false)) == json(true)) return true;
  }
  return false;
}

std::string supportedExtensionList() {
  std::string s;
  for (const char* e : kSupportedExtensions) s += (s.empty() ? "" : ", ") + std::string(e);
  return s;
}

namespace {

// The steps of checkGltfDocument, in the order it runs them: each checks
// one kind of element and throws on its first problem.

void checkAsset(const Checker& c, const json& doc) {
  // asset.version: only 2.x.
  const json* asset = c.member(doc, "asset");
  if (!asset) c.fail("asset", "is missing");
  c.object(*asset, "asset");
  const std::string version = c.string(*asset, "version", "asset", true);
  if (version.empty() || version[0] != '2' || (version.size() > 1 && version[1] != '.'))
    c.fail("asset", "version \"" + version + "\": only glTF 2.x is supported");
}

void checkExtensionLists(const Checker& c, const json& doc) {
  for (const char* key : {"extensionsUsed", "extensionsRequired"}) {
    const json* list = c.member(doc, key);
    if (!list) continue;
    if (!list->is_array()) c.fail(key, std::string("must be an array, got ") + typeName(*list));
    for (const json& name : *list) {
      if (!name.is_string()) c.fail(key, std::string("entries must be strings, got ") + typeName(name));
      if (std::string(key) == "extensionsRequired" && !isSupportedExtension(name.get<std::string>()))
        c.fail(key, name.get<std::string>() +
                        " is required but not supported (supported: " + supportedExtensionList() + ")");
    }
  }
}

// Buffers and views come first: accessors and images check their ranges
// against the declared byte lengths, which tinygltf enforces on load.
struct BufferRanges {
  std::vector<int64_t> length;
  std::vector<bool> fallback;  // a meshopt fallback buffer: never read
};

BufferRanges checkBuffers(const Checker& c, const json& doc, const GltfCheckContext& context) {
  BufferRanges r;
  if (const json* buffers = c.objectArray(doc, "buffers", "buffers")) {
    for (size_t i = 0; i < buffers->size(); ++i) {
      const std::string e = "buffer " + std::to_string(i);
      const json& b = c.object((*buffers)[i], e);
      const int64_t length = c.integer(b, "byteLength", e, true);
      if (length < 1) c.fail(e, "\"byteLength\" must be at least 1");
      const std::string uri = c.string(b, "uri", e, false);
      if (const json* ext = c.member(b, "extensions")) {
        c.object(*ext, e + " extensions");
        for (const char* name : kMeshoptExtensions)
          if (const json* m = c.member(*ext, name)) {
            c.object(*m, e + " " + name);
            c.boolean(*m, "fallback", e + " " + name);
          }
      }
      const bool fallback = isMeshoptFallbackBuffer(b);
      // A fallback buffer's bytes are never read (only compressed views
      // name it), so it may have no data anywhere.
      if (!c.member(b, "uri") && !fallback) {
        if (!(context.isGlb && i == 0))
          c.fail(e, "has no \"uri\" (only buffer 0 of a .glb file may use the BIN chunk)");
        if (uint64_t(length) > context.glbBinSize)
          c.fail(e, "byteLength " + std::to_string(length) + " exceeds the GLB BIN chunk (" +
                        std::to_string(context.glbBinSize) + " bytes)");
      }
      r.length.push_back(length);
      r.fallback.push_back(fallback);
    }
  }
  return r;
}

// Byte length and stride (0: tightly packed) of every bufferView, and
// whether its bytes come from a meshopt decoder.
struct ViewRanges {
  std::vector<int64_t> length, stride;
  std::vector<bool> compressed;
};

// An EXT_/KHR_meshopt_compression bufferView extension: the compressed
// range lies in a buffer with data, and the decoded elements (count ×
// byteStride, in a mode and filter libmeshoptimizer decodes) fill the
// bufferView exactly, so accessors checked against the view stay inside
// the decoded bytes.
void checkMeshoptView(const Checker& c, const json& ext, const std::string& e, const BufferRanges& buffers,
                      int64_t viewLength, int64_t viewStride) {
  c.object(ext, e);
  const int64_t buffer = c.index(ext, "buffer", e, "buffers", true);
  if (buffers.fallback[size_t(buffer)])
    c.fail(e, "\"buffer\" refers to fallback buffer " + std::to_string(buffer) + ", which holds no data");
  const int64_t offset = c.integer(ext, "byteOffset", e, false, 0);
  const int64_t length = c.integer(ext, "byteLength", e, true);
  const int64_t stride = c.integer(ext, "byteStride", e, true);
  const int64_t count = c.integer(ext, "count", e, true);
  const std::string mode = c.string(ext, "mode", e, true);
  const std::string filter = c.member(ext, "filter") ? c.string(ext, "filter", e, false) : "NONE";
  if (!fits(offset, length, buffers.length[size_t(buffer)]))
    c.fail(e, "compressed bytes [" + std::to_string(offset) + ", " + std::to_string(offset + length) +
                  ") lie outside buffer " + std::to_string(buffer) + " (" +
                  std::to_string(buffers.length[size_t(buffer)]) + " bytes)");
  if (mode == "ATTRIBUTES") {
    if (stride < 4 || stride > 256 || stride % 4 != 0)
      c.fail(e, "\"byteStride\" " + std::to_string(stride) +
                    " must be a multiple of 4 in [4, 256] for ATTRIBUTES");
  } else if (mode == "TRIANGLES" || mode == "INDICES") {
    if (stride != 2 && stride != 4)
      c.fail(e, "\"byteStride\" " + std::to_string(stride) + " must be 2 or 4 for " + mode);
    if (mode == "TRIANGLES" && count % 3 != 0)
      c.fail(e, "\"count\" " + std::to_string(count) + " must be a multiple of 3 for TRIANGLES");
  } else {
    c.fail(e, "\"mode\" \"" + mode + "\" is not ATTRIBUTES, TRIANGLES or INDICES");
  }
  if (filter != "NONE") {
    const bool ok =
        mode == "ATTRIBUTES" && ((filter == "OCTAHEDRAL" && (stride == 4 || stride == 8)) ||
                                 (filter == "QUATERNION" && stride == 8) || filter == "EXPONENTIAL");
    if (filter != "OCTAHEDRAL" && filter != "QUATERNION" && filter != "EXPONENTIAL")
      c.fail(
          e,
          "\"filter\" \"" + filter +
              "\" is not NONE, OCTAHEDRAL, QUATERNION or EXPONENTIAL (the filters libmeshoptimizer decodes)");
    if (!ok)
      c.fail(e, "\"filter\" " + filter + " cannot apply to mode " + mode + " with byteStride " +
                    std::to_string(stride));
  }
  if (count < 1 || count > (int64_t(1) << 32) || stride * count != viewLength)
    c.fail(e, std::to_string(count) + " elements of " + std::to_string(stride) +
                  " bytes do not fill the bufferView's byteLength " + std::to_string(viewLength));
  if (viewStride != 0 && viewStride != stride)
    c.fail(e, "\"byteStride\" " + std::to_string(stride) + " differs from the bufferView's " +
                  std::to_string(viewStride));
}

ViewRanges checkBufferViews(const Checker& c, const json& doc, const BufferRanges& buffers) {
  const std::vector<int64_t>& bufferLength = buffers.length;
  ViewRanges r;
  if (const json* views = c.objectArray(doc, "bufferViews", "bufferViews")) {
    for (size_t i = 0; i < views->size(); ++i) {
      const std::string e = "bufferView " + std::to_string(i);
      const json& v = c.object((*views)[i], e);
      const int64_t buffer = c.index(v, "buffer", e, "buffers", true);
      const int64_t offset = c.integer(v, "byteOffset", e, false, 0);
      const int64_t length = c.integer(v, "byteLength", e, true);
      if (length < 1) c.fail(e, "\"byteLength\" must be at least 1");
      const int64_t stride = c.integer(v, "byteStride", e, false, 0);
      if (c.member(v, "byteStride") && (stride < 4 || stride > 252 || stride % 4 != 0))
        c.fail(e, "\"byteStride\" " + std::to_string(stride) + " must be a multiple of 4 in [4, 252]");
      c.integer(v, "target", e, false);
      if (!fits(offset, length, bufferLength[size_t(buffer)]))
        c.fail(e, "bytes [" + std::to_string(offset) + ", " + std::to_string(offset + length) +
                      ") lie outside buffer " + std::to_string(buffer) + " (" +
                      std::to_string(bufferLength[size_t(buffer)]) + " bytes)");
      const json* meshopt = nullptr;
      if (const json* ext = c.member(v, "extensions")) {
        c.object(*ext, e + " extensions");
        for (const char* name : kMeshoptExtensions)
          if (const json* m = c.member(*ext, name)) {
            if (meshopt) c.fail(e, "has both EXT_meshopt_compression and KHR_meshopt_compression");
            meshopt = m;
            checkMeshoptView(c, *m, e + " " + name, buffers, length, stride);
          }
      }
      if (buffers.fallback[size_t(buffer)] && !meshopt)
        c.fail(e, "refers to fallback buffer " + std::to_string(buffer) +
                      " without a meshopt compression extension (a fallback buffer holds no data)");
      r.length.push_back(length);
      r.stride.push_back(stride);
      r.compressed.push_back(meshopt != nullptr);
    }
  }
  return r;
}

// The accessors whose data a KHR_draco_mesh_compression stream holds: the
// attributes it lists and the indices of its primitive. Their counts come
// from the JSON as for any accessor; the decoder must produce exactly
// them (scene_builder.cpp).
std::vector<bool> dracoAccessors(const json& doc) {
  std::vector<bool> draco(doc.contains("accessors") && doc["accessors"].is_array() ? doc["accessors"].size()
                                                                                   : 0);
  const auto mark = [&](const json& index) {
    if (index.is_number_unsigned() && index.get<uint64_t>() < draco.size()) draco[index.get<size_t>()] = true;
  };
  const auto meshes = doc.find("meshes");
  if (meshes == doc.end() || !meshes->is_array()) return draco;
  for (const json& m : *meshes) {
    if (!m.is_object() || !m.contains("primitives") || !m["primitives"].is_array()) continue;
    for (const json& p : m["primitives"]) {
      if (!p.is_object() || !p.contains("extensions") || !p["extensions"].is_object() ||
          !p["extensions"].contains("KHR_draco_mesh_compression"))
        continue;
      const json& ext = p["extensions"]["KHR_draco_mesh_compression"];
      if (p.contains("indices")) mark(p["indices"]);
      if (!ext.is_object() || !ext.contains("attributes") || !ext["attributes"].is_object() ||
          !p.contains("attributes") || !p["attributes"].is_object())
        continue;
      for (auto it = ext["attributes"].begin(); it != ext["attributes"].end(); ++it)
        if (p["attributes"].contains(it.key())) mark(p["attributes"][it.key()]);
    }
  }
  return draco;
}

void checkAccessors(const Checker& c, const json& doc, const ViewRanges& views) {
  const std::vector<bool> draco = dracoAccessors(doc);
  if (const json* accessors = c.objectArray(doc, "accessors", "accessors")) {
    for (size_t i = 0; i < accessors->size(); ++i) {
      const std::string e = "accessor " + std::to_string(i);
      const json& a = c.object((*accessors)[i], e);
      const int64_t view = c.index(a, "bufferView", e, "bufferViews");
      const int64_t offset = c.integer(a, "byteOffset", e, false, 0);
      const int64_t componentType = c.integer(a, "componentType", e, true);
      const int64_t size = componentSize(componentType);
      if (size == 0)
        c.fail(e, "\"componentType\" " + std::to_string(componentType) + " is not a glTF component type");
      c.boolean(a, "normalized", e);
      const int64_t count = c.integer(a, "count", e, true);
      if (count < 1) c.fail(e, "\"count\" must be at least 1");
      if (count > (int64_t(1) << 32)) c.fail(e, "\"count\" " + std::to_string(count) + " is too large");
      // A Draco accessor's elements are decoded, not zero-filled: the
      // flattened scene's memory estimate bounds them instead.
      if (view < 0 && !draco[i] && count > kMaxZeroFilledElements)
        c.fail(e, "\"count\" " + std::to_string(count) +
                      " is too large for an accessor without a bufferView (at most " +
                      std::to_string(kMaxZeroFilledElements) + ")");
      const std::string type = c.string(a, "type", e, true);
      const int64_t components = componentCount(type);
      if (components == 0) c.fail(e, "\"type\" \"" + type + "\" is not a glTF accessor type");
      c.numberArray(a, "min", e, size_t(components), size_t(components));
      c.numberArray(a, "max", e, size_t(components), size_t(components));
      const int64_t elementSize = size * components;
      if (view >= 0) {
        const int64_t stride = views.stride[size_t(view)] ? views.stride[size_t(view)] : elementSize;
        if (stride < elementSize)
          c.fail(e, "bufferView " + std::to_string(view) + " byteStride " + std::to_string(stride) +
                        " is smaller than the element size " + std::to_string(elementSize));
        const int64_t needed = stride * (count - 1) + elementSize;
        if (!fits(offset, needed, views.length[size_t(view)]))
          c.fail(e, std::to_string(count) + " elements from byte " + std::to_string(offset) + " need " +
                        std::to_string(offset + needed) + " bytes, bufferView " + std::to_string(view) +
                        " has " + std::to_string(views.length[size_t(view)]));
      }
      if (const json* sparse = c.member(a, "sparse")) {
        const std::string se = e + " sparse";
        c.object(*sparse, se);
        const int64_t sparseCount = c.integer(*sparse, "count", se, true);
        if (sparseCount < 1 || sparseCount > count)
          c.fail(se, "\"count\" " + std::to_string(sparseCount) + " must lie in [1, " +
                         std::to_string(count) + "]");
        const json* indices = c.member(*sparse, "indices");
        const json* values = c.member(*sparse, "values");
        if (!indices) c.fail(se, "\"indices\" is missing");
        if (!values) c.fail(se, "\"values\" is missing");
        c.object(*indices, se + " indices");
        c.object(*values, se + " values");
        const int64_t iv = c.index(*indices, "bufferView", se + " indices", "bufferViews", true);
        const int64_t io = c.integer(*indices, "byteOffset", se + " indices", false, 0);
        const int64_t ict = c.integer(*indices, "componentType", se + " indices", true);
        if (ict != 5121 && ict != 5123 && ict != 5125)
          c.fail(se + " indices", "\"componentType\" " + std::to_string(ict) + " must be 5121, 5123 or 5125");
        if (!fits(io, componentSize(ict) * sparseCount, views.length[size_t(iv)]))
          c.fail(se + " indices", "lie outside bufferView " + std::to_string(iv));
        const int64_t vv = c.index(*values, "bufferView", se + " values", "bufferViews", true);
        const int64_t vo = c.integer(*values, "byteOffset", se + " values", false, 0);
        if (!fits(vo, elementSize * sparseCount, views.length[size_t(vv)]))
          c.fail(se + " values", "lie outside bufferView " + std::to_string(vv));
      }
    }
  }
}

void checkImagesAndTextures(const Checker& c, const json& doc, const ViewRanges& views) {
  if (const json* images = c.objectArray(doc, "images", "images")) {
    for (size_t i = 0; i < images->size(); ++i) {
      const std::string e = "image " + std::to_string(i);
      const json& im = c.object((*images)[i], e);
      c.string(im, "uri", e, false);
      c.string(im, "mimeType", e, false);
      const int64_t view = c.index(im, "bufferView", e, "bufferViews");
      if (view < 0 && !c.member(im, "uri")) c.fail(e, "has neither \"uri\" nor \"bufferView\"");
      // tinygltf decodes images from the buffer's bytes as stored.
      if (view >= 0 && views.compressed[size_t(view)])
        c.fail(e, "bufferView " + std::to_string(view) + " is meshopt-compressed; images cannot be");
    }
  }
  if (const json* samplers = c.objectArray(doc, "samplers", "samplers")) {
    for (size_t i = 0; i < samplers->size(); ++i) {
      const std::string e = "sampler " + std::to_string(i);
      const json& s = c.object((*samplers)[i], e);
      const int64_t mag = c.integer(s, "magFilter", e, false);
      if (mag >= 0 && mag != 9728 && mag != 9729)
        c.fail(e, "\"magFilter\" " + std::to_string(mag) + " is not 9728 or 9729");
      const int64_t min = c.integer(s, "minFilter", e, false);
      if (min >= 0 && !(min == 9728 || min == 9729 || (min >= 9984 && min <= 9987)))
        c.fail(e, "\"minFilter\" " + std::to_string(min) + " is not a glTF filter");
      for (const char* key : {"wrapS", "wrapT"}) {
        const int64_t w = c.integer(s, key, e, false);
        if (w >= 0 && w != 33071 && w != 33648 && w != 10497)
          c.fail(e, std::string("\"") + key + "\" " + std::to_string(w) + " is not a glTF wrap mode");
      }
    }
  }
  if (const json* textures = c.objectArray(doc, "textures", "textures")) {
    for (size_t i = 0; i < textures->size(); ++i) {
      const std::string e = "texture " + std::to_string(i);
      const json& t = c.object((*textures)[i], e);
      c.index(t, "sampler", e, "samplers");
      c.index(t, "source", e, "images");
    }
  }
}

void checkMaterials(const Checker& c, const json& doc) {
  if (const json* materials = c.objectArray(doc, "materials", "materials")) {
    for (size_t i = 0; i < materials->size(); ++i) {
      const std::string e = "material " + std::to_string(i);
      const json& m = c.object((*materials)[i], e);
      c.string(m, "name", e, false);
      if (const json* pbr = c.member(m, "pbrMetallicRoughness")) {
        const std::string pe = e + " pbrMetallicRoughness";
        c.object(*pbr, pe);
        c.numberArray(*pbr, "baseColorFactor", pe, 4, 4);
        c.textureInfo(*pbr, "baseColorTexture", pe);
        c.textureInfo(*pbr, "metallicRoughnessTexture", pe);
        c.floatNumber(*pbr, "metallicFactor", pe, false);
        c.floatNumber(*pbr, "roughnessFactor", pe, false);
      }
      c.textureInfo(m, "normalTexture", e);
      c.textureInfo(m, "occlusionTexture", e);
      c.textureInfo(m, "emissiveTexture", e);
      c.numberArray(m, "emissiveFactor", e, 3, 3);
      const std::string mode = c.string(m, "alphaMode", e, false);
      if (c.member(m, "alphaMode") && mode != "OPAQUE" && mode != "MASK" && mode != "BLEND")
        c.fail(e, "\"alphaMode\" \"" + mode + "\" is not OPAQUE, MASK or BLEND");
      c.floatNumber(m, "alphaCutoff", e, false);
      c.boolean(m, "doubleSided", e);
      if (const json* ext = c.member(m, "extensions")) {
        c.object(*ext, e + " extensions");
        if (const json* t = c.member(*ext, "KHR_materials_transmission")) {
          const std::string te = e + " KHR_materials_transmission";
          c.object(*t, te);
          c.floatNumber(*t, "transmissionFactor", te, false);
          c.textureInfo(*t, "transmissionTexture", te);
        }
        if (const json* t = c.member(*ext, "KHR_materials_ior")) {
          c.object(*t, e + " KHR_materials_ior");
          c.floatNumber(*t, "ior", e + " KHR_materials_ior", false);
        }
        if (const json* t = c.member(*ext, "KHR_materials_emissive_strength")) {
          c.object(*t, e + " KHR_materials_emissive_strength");
          c.floatNumber(*t, "emissiveStrength", e + " KHR_materials_emissive_strength", false);
        }
      }
    }
  }
}

// KHR_draco_mesh_compression on a primitive: the stream lies in a plain
// bufferView, and every attribute it lists is one of the primitive's.
// Draco decodes triangle lists, with indices.
void checkDraco(const Checker& c, const json& draco, const std::string& e, const json& attributes,
                int64_t indices, int64_t mode, const ViewRanges& views) {
  c.object(draco, e);
  const int64_t view = c.index(draco, "bufferView", e, "bufferViews", true);
  if (views.compressed[size_t(view)])
    c.fail(e, "bufferView " + std::to_string(view) + " is meshopt-compressed; a Draco stream cannot be");
  const json* list = c.member(draco, "attributes");
  if (!list) c.fail(e, "\"attributes\" is missing");
  c.object(*list, e + " attributes");
  for (auto it = list->begin(); it != list->end(); ++it) {
    c.integer(*list, it.key().c_str(), e + " attributes", true);
    if (!attributes.contains(it.key()))
      c.fail(e + " attributes", "\"" + it.key() + "\" is not an attribute of the primitive");
  }
  if (mode > 4) c.fail(e, "\"mode\" " + std::to_string(mode) + ": Draco decodes TRIANGLES (4) only");
  if (mode == 4 && indices < 0) c.fail(e, "the primitive has no \"indices\" for the decoded faces");
}

void checkMeshes(const Checker& c, const json& doc, const ViewRanges& views) {
  if (const json* meshes = c.objectArray(doc, "meshes", "meshes")) {
    for (size_t i = 0; i < meshes->size(); ++i) {
      const std::string e = "mesh " + std::to_string(i);
      const json& m = c.object((*meshes)[i], e);
      c.numberArray(m, "weights", e, 1, SIZE_MAX);
      const json* primitives = c.member(m, "primitives");
      if (!primitives) c.fail(e, "\"primitives\" is missing");
      if (!primitives->is_array())
        c.fail(e, std::string("\"primitives\" must be an array, got ") + typeName(*primitives));
      for (size_t p = 0; p < primitives->size(); ++p) {
        const std::string pe = e + " primitive " + std::to_string(p);
        const json& prim = c.object((*primitives)[p], pe);
        const json* attributes = c.member(prim, "attributes");
        if (!attributes) c.fail(pe, "\"attributes\" is missing");
        c.object(*attributes, pe + " attributes");
        for (auto it = attributes->begin(); it != attributes->end(); ++it)
          c.index(*attributes, it.key().c_str(), pe + " attributes", "accessors");
        if (const json* targets = c.member(prim, "targets")) {
          if (!targets->is_array() || targets->empty())
            c.fail(pe, "\"targets\" must be a non-empty array of morph targets");
          for (size_t t = 0; t < targets->size(); ++t) {
            const std::string te = pe + " target " + std::to_string(t);
            c.object((*targets)[t], te);
            for (auto it = (*targets)[t].begin(); it != (*targets)[t].end(); ++it)
              c.index((*targets)[t], it.key().c_str(), te, "accessors");
          }
        }
        const int64_t indices = c.index(prim, "indices", pe, "accessors");
        c.index(prim, "material", pe, "materials");
        const int64_t mode = c.integer(prim, "mode", pe, false, 4);
        if (mode > 6) c.fail(pe, "\"mode\" " + std::to_string(mode) + " is not a glTF primitive mode");
        if (const json* ext = c.member(prim, "extensions")) {
          c.object(*ext, pe + " extensions");
          if (const json* draco = c.member(*ext, "KHR_draco_mesh_compression"))
            checkDraco(c, *draco, pe + " KHR_draco_mesh_compression", *attributes, indices, mode, views);
        }
      }
    }
  }
}

void checkCameras(const Checker& c, const json& doc) {
  if (const json* cameras = c.objectArray(doc, "cameras", "cameras")) {
    for (size_t i = 0; i < cameras->size(); ++i) {
      const std::string e = "camera " + std::to_string(i);
      const json& cam = c.object((*cameras)[i], e);
      const std::string type = c.string(cam, "type", e, true);
      if (type == "perspective") {
        const json* p = c.member(cam, "perspective");
        if (!p) c.fail(e, "\"perspective\" is missing");
        c.object(*p, e + " perspective");
        const double yfov = c.number(*p, "yfov", e + " perspective", true);
        const double znear = c.number(*p, "znear", e + " perspective", true);
        const double zfar = c.number(*p, "zfar", e + " perspective", false, INFINITY);
        const double aspect = c.number(*p, "aspectRatio", e + " perspective", false, 1.0);
        if (!(yfov > 0.0 && yfov < kPi)) c.fail(e + " perspective", "\"yfov\" must lie in (0, pi)");
        if (!(znear > 0.0)) c.fail(e + " perspective", "\"znear\" must be > 0");
        if (!(zfar > znear)) c.fail(e + " perspective", "\"zfar\" must be > znear");
        if (!(aspect > 0.0)) c.fail(e + " perspective", "\"aspectRatio\" must be > 0");
      } else if (type == "orthographic") {
        const json* o = c.member(cam, "orthographic");
        if (!o) c.fail(e, "\"orthographic\" is missing");
        const std::string oe = e + " orthographic";
        c.object(*o, oe);
        const double xmag = c.number(*o, "xmag", oe, true);
        const double ymag = c.number(*o, "ymag", oe, true);
        const double znear = c.number(*o, "znear", oe, true);
        const double zfar = c.number(*o, "zfar", oe, true);
        if (xmag == 0.0 || ymag == 0.0) c.fail(oe, "\"xmag\" and \"ymag\" must not be zero");
        if (!(znear >= 0.0)) c.fail(oe, "\"znear\" must be >= 0");
        if (!(zfar > znear)) c.fail(oe, "\"zfar\" must be > znear");
      } else {
        c.fail(e, "\"type\" \"" + type + "\" is not perspective or orthographic");
      }
    }
  }
}

// Returns the number of KHR_lights_punctual lights, which nodes refer to.
size_t checkLights(const Checker& c, const json& doc) {
  size_t lightCount = 0;
  if (const json* ext = c.member(doc, "extensions")) {
    c.object(*ext, "extensions");
    if (const json* lp = c.member(*ext, "KHR_lights_punctual")) {
      c.object(*lp, "KHR_lights_punctual");
      if (const json* lights = c.objectArray(*lp, "lights", "KHR_lights_punctual")) {
        lightCount = lights->size();
        for (size_t i = 0; i < lights->size(); ++i) {
          const std::string e = "light " + std::to_string(i);
          const json& l = c.object((*lights)[i], e);
          c.string(l, "name", e, false);
          const std::string type = c.string(l, "type", e, true);
          if (type != "point" && type != "spot" && type != "directional")
            c.fail(e, "\"type\" \"" + type + "\" is not point, spot or directional");
          c.numberArray(l, "color", e, 3, 3);
          if (c.floatNumber(l, "intensity", e, false, 1.0) < 0.0) c.fail(e, "\"intensity\" must be >= 0");
          if (c.member(l, "range") && !(c.floatNumber(l, "range", e, false) > 0.0))
            c.fail(e, "\"range\" must be > 0");
          if (type == "spot") {
            const json* spot = c.member(l, "spot");
            if (!spot) c.fail(e, "\"spot\" is missing");
            c.object(*spot, e + " spot");
            const double inner = c.floatNumber(*spot, "innerConeAngle", e + " spot", false, 0.0);
            const double outer = c.floatNumber(*spot, "outerConeAngle", e + " spot", false, kPi / 4);
            if (!(inner >= 0.0 && inner < outer && outer <= kPi / 2))
              c.fail(e + " spot", "cone angles must satisfy 0 <= inner < outer <= pi/2");
          }
        }
      }
    }
  }
  return lightCount;
}

void checkNodes(const Checker& c, const json& doc, size_t lightCount) {
  if (const json* nodes = c.objectArray(doc, "nodes", "nodes")) {
    for (size_t i = 0; i < nodes->size(); ++i) {
      const std::string e = "node " + std::to_string(i);
      const json& n = c.object((*nodes)[i], e);
      c.string(n, "name", e, false);
      c.index(n, "camera", e, "cameras");
      c.index(n, "mesh", e, "meshes");
      c.index(n, "skin", e, "skins");
      if (const json* children = c.member(n, "children")) {
        if (!children->is_array())
          c.fail(e, std::string("\"children\" must be an array, got ") + typeName(*children));
        for (size_t k = 0; k < children->size(); ++k) {
          const json& child = (*children)[k];
          if (!child.is_number_integer() || child.get<int64_t>() < 0 ||
              child.get<uint64_t>() >= nodes->size())
            c.fail(e, "\"children\"[" + std::to_string(k) + "] is not a node index (" +
                          std::to_string(nodes->size()) + " nodes)");
        }
      }
      c.numberArray(n, "matrix", e, 16, 16);
      c.numberArray(n, "translation", e, 3, 3);
      c.numberArray(n, "rotation", e, 4, 4);
      c.numberArray(n, "scale", e, 3, 3);
      c.numberArray(n, "weights", e, 1, SIZE_MAX);
      if (c.member(n, "matrix") &&
          (c.member(n, "translation") || c.member(n, "rotation") || c.member(n, "scale")))
        c.fail(e, "has both \"matrix\" and translation/rotation/scale");
      if (const json* ext = c.member(n, "extensions")) {
        c.object(*ext, e + " extensions");
        if (const json* lp = c.member(*ext, "KHR_lights_punctual")) {
          c.object(*lp, e + " KHR_lights_punctual");
          const int64_t light = c.integer(*lp, "light", e + " KHR_lights_punctual", true);
          if (size_t(light) >= lightCount)
            c.fail(e + " KHR_lights_punctual", "\"light\" refers to light " + std::to_string(light) +
                                                   ", which does not exist (" + std::to_string(lightCount) +
                                                   " lights)");
        }
      }
    }
  }
}

void checkScenes(const Checker& c, const json& doc) {
  if (const json* scenes = c.objectArray(doc, "scenes", "scenes")) {
    for (size_t i = 0; i < scenes->size(); ++i) {
      const std::string e = "scene " + std::to_string(i);
      const json& s = c.object((*scenes)[i], e);
      if (const json* list = c.member(s, "nodes")) {
        if (!list->is_array()) c.fail(e, std::string("\"nodes\" must be an array, got ") + typeName(*list));
        for (size_t k = 0; k < list->size(); ++k) {
          const json& n = (*list)[k];
          if (!n.is_number_integer() || n.get<int64_t>() < 0 || n.get<uint64_t>() >= c.countOf("nodes"))
            c.fail(e, "\"nodes\"[" + std::to_string(k) + "] is not a node index (" +
                          std::to_string(c.countOf("nodes")) + " nodes)");
        }
      }
    }
  }
  if (c.member(doc, "scene")) {
    const int64_t scene = c.integer(doc, "scene", "scene", true);
    if (size_t(scene) >= c.countOf("scenes"))
      c.fail("scene", "scene " + std::to_string(scene) + " does not exist (" +
                          std::to_string(c.countOf("scenes")) + " scenes)");
  }
}

// Skins: joints are node indices, at least one; inverseBindMatrices an
// accessor (its type and count are checked when it is read).
void checkSkins(const Checker& c, const json& doc) {
  if (const json* skins = c.objectArray(doc, "skins", "skins")) {
    for (size_t i = 0; i < skins->size(); ++i) {
      const std::string e = "skin " + std::to_string(i);
      const json& s = c.object((*skins)[i], e);
      c.string(s, "name", e, false);
      c.index(s, "inverseBindMatrices", e, "accessors");
      c.index(s, "skeleton", e, "nodes");
      const json* joints = c.member(s, "joints");
      if (!joints) c.fail(e, "\"joints\" is missing");
      if (!joints->is_array())
        c.fail(e, std::string("\"joints\" must be an array, got ") + typeName(*joints));
      if (joints->empty()) c.fail(e, "has no joints");
      for (size_t k = 0; k < joints->size(); ++k) {
        const json& j = (*joints)[k];
        if (!j.is_number_integer() || j.get<int64_t>() < 0 || j.get<uint64_t>() >= c.countOf("nodes"))
          c.fail(e, "\"joints\"[" + std::to_string(k) + "] is not a node index (" +
                        std::to_string(c.countOf("nodes")) + " nodes)");
      }
    }
  }
}

// Animations: samplers name input and output accessors and a known
// interpolation; channels name a sampler of their animation and a node
// and path. What the data must satisfy (increasing times, output
// counts, finite values) is checked when it is read (animation.h).
void checkAnimations(const Checker& c, const json& doc) {
  if (const json* animations = c.objectArray(doc, "animations", "animations")) {
    for (size_t i = 0; i < animations->size(); ++i) {
      const std::string e = "animation " + std::to_string(i);
      const json& a = c.object((*animations)[i], e);
      c.string(a, "name", e, false);
      const json* samplers = c.objectArray(a, "samplers", e);
      const json* channels = c.objectArray(a, "channels", e);
      if (!samplers) c.fail(e, "\"samplers\" is missing");
      if (!channels) c.fail(e, "\"channels\" is missing");
      for (size_t k = 0; k < samplers->size(); ++k) {
        const std::string se = e + " sampler " + std::to_string(k);
        const json& s = c.object((*samplers)[k], se);
        c.index(s, "input", se, "accessors", true);
        c.index(s, "output", se, "accessors", true);
        const std::string interpolation = c.string(s, "interpolation", se, false);
        if (c.member(s, "interpolation") && interpolation != "STEP" && interpolation != "LINEAR" &&
            interpolation != "CUBICSPLINE")
          c.fail(se, "\"interpolation\" \"" + interpolation + "\" is not STEP, LINEAR or CUBICSPLINE");
      }
      for (size_t k = 0; k < channels->size(); ++k) {
        const std::string ce = e + " channel " + std::to_string(k);
        const json& ch = c.object((*channels)[k], ce);
        const int64_t sampler = c.integer(ch, "sampler", ce, true);
        if (size_t(sampler) >= samplers->size())
          c.fail(ce, "\"sampler\" refers to sampler " + std::to_string(sampler) + ", which does not exist (" +
                         std::to_string(samplers->size()) + " samplers in " + e + ")");
        const json* target = c.member(ch, "target");
        if (!target) c.fail(ce, "\"target\" is missing");
        c.object(*target, ce + " target");
        // Without "node" a channel targets something an extension defines
        // (KHR_animation_pointer): nothing rastray plays.
        c.index(*target, "node", ce + " target", "nodes");
        const std::string path = c.string(*target, "path", ce + " target", true);
        if (path != "translation" && path != "rotation" && path != "scale" && path != "weights")
          c.fail(ce + " target", "\"path\" \"" + path + "\" is not translation, rotation, scale or weights");
      }
    }
  }
}

}  // namespace

void checkGltfDocument(const json& doc, const GltfCheckContext& context) {
  Checker c(context, doc);
  if (!doc.is_object()) c.fail("", std::string("the document must be a JSON object, got ") + typeName(doc));

  checkAsset(c, doc);
  checkExtensionLists(c, doc);
  const BufferRanges buffers = checkBuffers(c, doc, context);
  const ViewRanges views = checkBufferViews(c, doc, buffers);
  checkAccessors(c, doc, views);
  checkImagesAndTextures(c, doc, views);
  checkMaterials(c, doc);
  checkMeshes(c, doc, views);
  checkCameras(c, doc);
  const size_t lightCount = checkLights(c, doc);
  checkNodes(c, doc, lightCount);
  checkScenes(c, doc);
  checkSkins(c, doc);
  checkAnimations(c, doc);
}

}  // namespace rastray
