// Found by fuzz/exr_reader_fuzzer (inputs in tests/data/fuzz-regressions/):
// - OpenEXR 3.1 allocates an attribute at its declared size before
//   reading it: a 31-byte file declaring a 1.8 GB string attribute had it
//   allocate and fill 1.8 GB before failing;
// - OpenEXR reads a channel list up to its terminating NUL and a value of
//   a fixed-size type (int, box2i, ...) at that type's size, whatever size
//   the attribute declares; where the two differ it reads the following
//   attributes from another offset than the declared sizes say, so a walk
//   by declared sizes alone would check other bytes than OpenEXR reads;
// - OpenImageIO 2.4 aborts the process (a failed assertion in
//   TypeDesc_from_ImfPixelType) on a channel whose pixel type is not one
//   of OpenEXR's three.
#include "common/exr_header.h"

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <utility>
#include <vector>

#include "common/error.h"

namespace rastray {

namespace {

int32_t readI32(const unsigned char* b) {
  return int32_t(uint32_t(b[0]) | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24);
}

// The size OpenEXR reads for a value of a fixed-size attribute type
// (OpenEXR 3.1, ImfStandardAttributes and ImfAttribute.cpp); 0 for the
// types whose values it reads by the declared size (string, stringvector,
// floatvector, idmanifest, unknown types) or parses (chlist, preview).
int32_t fixedSize(const std::string& type) {
  static const std::pair<const char*, int32_t> kSizes[] = {
      {"box2i", 16},      {"box2f", 16},   {"chromaticities", 32},
      {"compression", 1}, {"double", 8},   {"envmap", 1},
      {"float", 4},       {"int", 4},      {"keycode", 28},
      {"lineOrder", 1},   {"m33f", 36},    {"m33d", 72},
      {"m44f", 64},       {"m44d", 128},   {"rational", 8},
      {"timecode", 8},    {"v2i", 8},      {"v2f", 8},
      {"v2d", 16},        {"v3i", 12},     {"v3f", 12},
      {"v3d", 24},        {"tiledesc", 9}, {"deepImageState", 1}};
  for (const auto& [name, size] : kSizes)
    if (type == name) return size;
  return 0;
}

// A channel list: per channel its name and NUL, int32 pixel type, uint8
// pLinear, 3 reserved bytes, int32 x and y sampling; a NUL ends the list,
// and must be the value's last byte (OpenEXR reads up to it).
void checkChannelList(const std::string& path, const std::string& attribute, const std::vector<char>& value) {
  size_t at = 0;
  for (;;) {
    const auto end = std::find(value.begin() + at, value.end(), '\0');
    if (end == value.end())
      throw InputError(path, "header", "channel list \"" + attribute + "\" is not terminated");
    const std::string name(value.begin() + at, end);
    if (name.empty()) {
      if (size_t(end - value.begin()) + 1 != value.size())
        throw InputError(path, "header", "channel list \"" + attribute + "\" ends before its declared size");
      return;
    }
    at = size_t(end - value.begin()) + 1;
    if (value.size() - at < 16)
      throw InputError(path, "header", "channel \"" + name + "\" is truncated in \"" + attribute + "\"");
    const int32_t type = readI32(reinterpret_cast<const unsigned char*>(value.data()) + at);
    if (type < 0 || type > 2)  // UINT, HALF, FLOAT
      throw InputError(path, "header",
                       "channel \"" + name + "\" has pixel type " + std::to_string(type) +
                           " (OpenEXR has 0 uint, 1 half, 2 float)");
    at += 16;
  }
}

}  // namespace

ExrHeaderFacts checkExrHeaders(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw InputError(path, "", "no such file");
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path, "", "not a regular file");
  const uint64_t fileSize = std::filesystem::file_size(path, ec);
  std::ifstream in(path, std::ios::binary);
  if (ec || !in) throw InputError(path, "", std::string("cannot open: ") + std::strerror(errno));
  unsigned char start[8] = {};
  in.read(reinterpret_cast<char*>(start), 8);
  constexpr unsigned char kMagic[4] = {0x76, 0x2f, 0x31, 0x01};
  if (!in || std::memcmp(start, kMagic, 4) != 0)
    throw InputError(path, "", "not an OpenEXR file (no OpenEXR magic number)");
  const bool longNames = start[5] & 0x04, multiPart = start[5] & 0x10;  // flag bits 10 and 12
  const size_t maxName = longNames ? 255 : 31;
  uint64_t at = 8;
  const auto truncated = [&]() {
    return InputError(path, "header", "ends at byte " + std::to_string(fileSize) + " inside an attribute");
  };
  // A name or type: up to maxName characters and a NUL.
  const auto readName = [&](std::string& name) {
    name.clear();
    for (int c; (c = in.get()) != 0;) {
      if (c == EOF) throw truncated();
      if (name.size() == maxName)
        throw InputError(path, "header", "attribute name or type longer than " + std::to_string(maxName));
      name += char(c);
    }
    at += name.size() + 1;
  };
  std::string name, type;
  std::vector<char> value;
  ExrHeaderFacts facts;
  facts.fileSize = fileSize;
  facts.deep = start[5] & 0x08;  // flag bit 11: deep data
  for (int part = 0;; ++part) {
    readName(name);
    if (name.empty()) {
      // An empty header ends a multi-part file's list of headers.
      if (!multiPart || part == 0) throw InputError(path, "header", "is empty");
      return facts;
    }
    for (; !name.empty(); readName(name)) {
      readName(type);
      if (type.empty()) throw InputError(path, "header", "attribute \"" + name + "\" has no type");
      unsigned char bytes[4];
      if (!in.read(reinterpret_cast<char*>(bytes), 4)) throw truncated();
      at += 4;
      const int32_t size = readI32(bytes);
      const uint64_t left = fileSize - std::min(fileSize, at);
      if (size < 0 || uint64_t(size) > left)
        throw InputError(path, "header",
                         "attribute \"" + name + "\" declares " + std::to_string(size) + " bytes, " +
                             std::to_string(left) + " are left in the file");
      const int32_t fixed = fixedSize(type);
      if (fixed > 0 && size != fixed)
        throw InputError(path, "header",
                         "attribute \"" + name + "\" of type " + type + " declares " + std::to_string(size) +
                             " bytes; the type has " + std::to_string(fixed));
      if (part == 0 && name == "dataWindow" && type == "box2i") {
        unsigned char box[16];
        if (!in.read(reinterpret_cast<char*>(box), 16)) throw truncated();
        const int64_t w = int64_t(readI32(box + 8)) - readI32(box) + 1,
                      h = int64_t(readI32(box + 12)) - readI32(box + 4) + 1;
        facts.dataPixels = w > 0 && h > 0 ? uint64_t(w) * uint64_t(h) : 0;
      }
      if (part == 0 && name == "tiles" && type == "tiledesc") {
        unsigned char tiles[8];
        if (!in.read(reinterpret_cast<char*>(tiles), 8)) throw truncated();
        facts.tilePixels = uint64_t(uint32_t(readI32(tiles))) * uint32_t(readI32(tiles + 4));
      }
      if (part == 0 && name == "type" && type == "string" && size >= 4) {
        char kind[4];
        if (!in.read(kind, 4)) throw truncated();
        facts.deep = facts.deep || std::memcmp(kind, "deep", 4) == 0;
      }
      if (type == "chlist" || type == "preview") {
        value.resize(size_t(size));
        if (!in.read(value.data(), size)) throw truncated();
        if (type == "chlist") checkChannelList(path, name, value);
        // A preview image: uint32 width and height, then 4 bytes per pixel
        // (OpenEXR allocates them from width and height alone).
        const auto* v = reinterpret_cast<const unsigned char*>(value.data());
        if (type == "preview" &&
            (size < 8 || uint64_t(uint32_t(readI32(v))) * uint32_t(readI32(v + 4)) * 4 != uint64_t(size) - 8))
          throw InputError(path, "header", "preview \"" + name + "\" does not hold width x height pixels");
      }
      at += uint64_t(size);
      in.seekg(std::streamoff(at));
    }
    if (!multiPart) return facts;
  }
}

}  // namespace rastray
