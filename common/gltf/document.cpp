#include "common/gltf/document.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <utility>

#include "common/error.h"

namespace rastray {

namespace {

using json = nlohmann::json;

constexpr uint32_t kGlbMagic = 0x46546C67;   // "glTF"
constexpr uint32_t kChunkJson = 0x4E4F534A;  // "JSON"
constexpr uint32_t kChunkBin = 0x004E4942;   // "BIN\0"

uint32_t readU32(const std::vector<uint8_t>& bytes, size_t offset) {
  uint32_t v;
  std::memcpy(&v, bytes.data() + offset, 4);
  return v;  // glTF is little-endian, as is every platform we build for
}

// The glTF top-level arrays whose entries messages name as elements.
constexpr const char* kElementArrays[] = {"accessors", "animations", "buffers", "bufferViews", "cameras",
                                          "images",    "materials",  "meshes",  "nodes",       "samplers",
                                          "scenes",    "skins",      "textures"};

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

// Checks a .glb's header and chunks (glTF 2.0, GLB file format) and keeps
// the JSON chunk's text and the BIN chunk's size.
void readGlbContainer(GltfDocument& d) {
  const std::string& path = d.context.file;
  const std::vector<uint8_t>& bytes = d.bytes;
  d.context.isGlb = true;
  if (bytes.size() < 20)
    throw InputError(path, "GLB header", "file is too short (" + std::to_string(bytes.size()) + " bytes)");
  const uint32_t version = readU32(bytes, 4), length = readU32(bytes, 8);
  if (version != 2) throw InputError(path, "GLB header", "version " + std::to_string(version) + " is not 2");
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
    throw InputError(path, "GLB chunk 0", "length " + std::to_string(jsonLength) + " is not a multiple of 4");
  d.jsonText.assign(reinterpret_cast<const char*>(bytes.data() + 20), jsonLength);
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
    d.context.glbBinSize = binLength;
  }
}

}  // namespace

// "nodes" -> "node"; empty for a key that is not one of kElementArrays.
std::string singular(const std::string& key) {
  for (const char* plural : kElementArrays)
    if (key == plural) return key == "meshes" ? "mesh" : key.substr(0, key.size() - 1);
  return "";
}

// Keeps a message from tinygltf readable on one line: data URIs can be
// megabytes long.
std::string shortened(std::string text) {
  constexpr size_t kMaxLength = 200;
  if (text.size() > kMaxLength) text = text.substr(0, kMaxLength) + "...";
  return text;
}

GltfDocument readGltfDocument(const std::string& path) { return parseGltfDocument(path, readFile(path)); }

GltfDocument parseGltfDocument(const std::string& path, std::vector<uint8_t> bytes) {
  GltfDocument d;
  d.bytes = std::move(bytes);
  d.context = GltfCheckContext{path, false, 0};
  if (d.bytes.size() >= 4 && readU32(d.bytes, 0) == kGlbMagic)
    readGlbContainer(d);
  else
    d.jsonText.assign(d.bytes.begin(), d.bytes.end());
  TrackingJsonParser parser(d.json, path, d.jsonText);
  json::sax_parse(d.jsonText, &parser);
  return d;
}

}  // namespace rastray
