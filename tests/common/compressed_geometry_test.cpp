// Compressed glTF geometry (issue 22 item 1): KHR_draco_mesh_compression,
// EXT_meshopt_compression (and its filters), KHR_mesh_quantization as
// gltfpack writes it. The compressed files are made here from a scene the
// glTF writer writes, with the encoders of Debian's draco and gltfpack
// packages (scripts/setup.sh) and libmeshoptimizer's encoder API; each
// decodes back to the uncompressed geometry within its quantisation step,
// renders the same coverage and cross-validates. Corrupt streams are
// refused with one InputError naming the element, never a crash.
#include <gtest/gtest.h>
#include <meshoptimizer.h>
#include <stb/stb_image.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "common/error.h"
#include "common/gltf/compression.h"
#include "common/gltf/loader.h"
#include "common/gltf/writer.h"
#include "common/math_constants.h"
#include "common/scene.h"
#include "tests/app/run_command.h"
#include "tests/test_files.h"

namespace rastray {
namespace {

using json = nlohmann::json;

// A UV sphere with smooth normals (the writer's has none).
GltfMesh smoothSphere(glm::vec3 centre, float radius, int rings, int segments, int material) {
  GltfMesh m = uvSphereMesh(centre, radius, rings, segments, material);
  for (const glm::vec3& p : m.positions) m.normals.push_back(glm::normalize(p - centre));
  return m;
}

// Two spheres in front of a textured-coordinate quad, under a camera: the
// attributes the loader reads (POSITION, NORMAL, TEXCOORD_0), three
// instances, coverage with silhouettes and background.
GltfScene testScene() {
  GltfScene s;
  GltfMaterial red, green;
  red.baseColor = {0.8f, 0.2f, 0.2f, 1.0f};
  green.baseColor = {0.2f, 0.7f, 0.3f, 1.0f};
  s.materials = {red, green};
  s.meshes.push_back(smoothSphere({-0.6f, 0.0f, 0.0f}, 0.5f, 12, 16, 0));
  s.meshes.push_back(smoothSphere({0.6f, 0.1f, -0.3f}, 0.45f, 10, 20, 1));
  GltfMesh quad;
  quad.positions = {{-1.5f, -1.0f, -1.0f}, {1.5f, -1.0f, -1.0f}, {1.5f, 1.0f, -1.0f}, {-1.5f, 1.0f, -1.0f}};
  quad.indices = {0, 1, 2, 0, 2, 3};
  quad.normals.assign(4, {0.0f, 0.0f, 1.0f});
  quad.texcoords = {{0.0f, 1.0f}, {1.0f, 1.0f}, {1.0f, 0.0f}, {0.0f, 0.0f}};
  quad.material = 1;
  s.meshes.push_back(quad);
  GltfCamera camera;
  camera.eye = {0.0, 0.4, 3.5};
  s.camera = camera;
  return s;
}

// Runs an encoder of the Debian packages; its output goes to a log in the
// test's folder, shown when it fails.
void runTool(const std::string& command) {
  const std::string log = test::scratchPath("tool.log");
  const int status = std::system((command + " >" + log + " 2>&1").c_str());
  ASSERT_EQ(status, 0) << command << "\n" << test::slurp(log);
}

// The test scene as plain.glb and, made from it, the compressed files.
struct Files {
  std::string plain, draco, meshopt, meshoptFilters;
};

Files writeFiles() {
  Files f{test::scratchPath("plain.glb"), test::scratchPath("draco.glb"), test::scratchPath("meshopt.glb"),
          test::scratchPath("meshopt-cc.glb")};
  testScene().writeGlb(f.plain);
  runTool("draco_transcoder -i " + f.plain + " -o " + f.draco);
  // -c: meshopt streams over KHR_mesh_quantization attributes (unsigned
  // short positions with the dequantisation in the node transform, byte
  // normals); -cc adds the OCTAHEDRAL filter on normals.
  runTool("gltfpack -c -i " + f.plain + " -o " + f.meshopt);
  runTool("gltfpack -cc -i " + f.plain + " -o " + f.meshoptFilters);
  return f;
}

// A .glb split into its JSON and BIN chunk, and put back together.
struct Glb {
  json doc;
  std::vector<uint8_t> bin;
};

Glb readGlb(const std::string& path) {
  const std::string bytes = test::slurp(path);
  uint32_t jsonLength = 0, binLength = 0;
  std::memcpy(&jsonLength, bytes.data() + 12, 4);
  Glb g;
  g.doc = json::parse(bytes.substr(20, jsonLength));
  if (bytes.size() > 20 + size_t(jsonLength) + 8) {
    std::memcpy(&binLength, bytes.data() + 20 + jsonLength, 4);
    const char* bin = bytes.data() + 28 + jsonLength;
    g.bin.assign(bin, bin + binLength);
  }
  return g;
}

void writeGlb(const std::string& path, const Glb& g) {
  std::string text = g.doc.dump();
  text.append((4 - text.size() % 4) % 4, ' ');
  std::vector<uint8_t> bin = g.bin;
  bin.resize((bin.size() + 3) / 4 * 4, 0);
  const auto u32 = [](std::string& out, uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
  std::string out = "glTF";
  u32(out, 2);
  u32(out, uint32_t(12 + 8 + text.size() + (bin.empty() ? 0 : 8 + bin.size())));
  u32(out, uint32_t(text.size()));
  out += "JSON" + text;
  if (!bin.empty()) {
    u32(out, uint32_t(bin.size()));
    out.append("BIN\0", 4);
    out.append(bin.begin(), bin.end());
  }
  std::ofstream(path, std::ios::binary) << out;
}

// The loader's InputError for `path`, or a failure when it loads.
InputError loadError(const std::string& path) {
  try {
    loadScene(path);
  } catch (const InputError& e) {
    return e;
  }
  ADD_FAILURE() << path << " loaded";
  return InputError(path, "", "loaded");
}

double maxExtent(const Scene& s) {
  const glm::dvec3 e = s.bounds.hi - s.bounds.lo;
  return std::max({e.x, e.y, e.z});
}

// How far decoding moved the vertices: for every vertex of `b`, the
// distance to the nearest vertex of `a` (world space), over instances
// paired by number or over the whole scene. Also checks the normal and
// texcoord of that nearest vertex against the decoded ones.
struct Displacement {
  double position = 0.0;   // largest distance
  double normalDot = 1.0;  // smallest cosine between paired normals
  double texcoord = 0.0;   // largest texcoord difference (either axis)
};

Displacement displacement(const Scene& a, const Scene& b, bool perInstance) {
  Displacement d;
  const auto range = [&](const Scene& s, size_t i) {
    return perInstance ? std::pair<size_t, size_t>(s.instances[i].firstVertex, s.instances[i].vertexCount)
                       : std::pair<size_t, size_t>(0, s.positions.size());
  };
  const size_t groups = perInstance ? b.instances.size() : 1;
  for (size_t i = 0; i < groups; ++i) {
    const auto [aFirst, aCount] = range(a, i);
    const auto [bFirst, bCount] = range(b, i);
    for (size_t v = bFirst; v < bFirst + bCount; ++v) {
      size_t best = aFirst;
      double bestDistance = INFINITY;
      for (size_t u = aFirst; u < aFirst + aCount; ++u) {
        const double distance = glm::length(b.worldPositions[v] - a.worldPositions[u]);
        if (distance < bestDistance) bestDistance = distance, best = u;
      }
      d.position = std::max(d.position, bestDistance);
      d.normalDot = std::min(d.normalDot, double(glm::dot(a.normals[best], b.normals[v])));
      const glm::vec2 t = glm::abs(a.texcoords[best] - b.texcoords[v]);
      d.texcoord = std::max(d.texcoord, double(std::max(t.x, t.y)));
    }
  }
  return d;
}

size_t nonDegenerateTriangles(const Scene& s) {
  size_t n = 0;
  for (const Instance& in : s.instances) n += in.triangleCount - in.degenerateCount;
  return n;
}

TEST(CompressedGeometry, DracoDecodesToTheUncompressedGeometry) {
  const Files f = writeFiles();
  ASSERT_NE(readGlb(f.draco).doc.at("extensionsRequired").dump().find("KHR_draco_mesh_compression"),
            std::string::npos);
  const Scene plain = loadScene(f.plain);
  const Scene draco = loadScene(f.draco);
  ASSERT_EQ(draco.instances.size(), plain.instances.size());
  for (size_t i = 0; i < plain.instances.size(); ++i) {
    EXPECT_EQ(draco.instances[i].triangleCount, plain.instances[i].triangleCount) << "instance " << i;
    EXPECT_EQ(draco.instances[i].normals, NormalSource::Authored) << "instance " << i;
  }
  // draco_transcoder's defaults: 11-bit positions over each mesh's box
  // (at most half a step, sqrt(3)/2 steps in 3D), 8-bit octahedral
  // normals, 10-bit texcoords. Moved vertices in both directions bound
  // dropped or added ones as well.
  const double step = maxExtent(plain) / 2047.0;
  const Displacement d = displacement(plain, draco, true);
  EXPECT_LE(d.position, step) << "step " << step;
  EXPECT_GE(d.normalDot, 0.995);
  EXPECT_LE(d.texcoord, 1.0 / 1023.0);
  EXPECT_LE(displacement(draco, plain, true).position, step);
  std::printf("Draco: vertices moved up to %.3g (%.3g of the scene's extent), normals within %.2f deg\n",
              d.position, d.position / maxExtent(plain), std::acos(std::min(d.normalDot, 1.0)) * 180.0 / kPi);
}

TEST(CompressedGeometry, MeshoptDecodesToTheUncompressedGeometry) {
  const Files f = writeFiles();
  const Scene plain = loadScene(f.plain);
  for (const std::string& path : {f.meshopt, f.meshoptFilters}) {
    const Glb glb = readGlb(path);
    const std::string required = glb.doc.at("extensionsRequired").dump();
    ASSERT_NE(required.find("EXT_meshopt_compression"), std::string::npos) << path;
    ASSERT_NE(required.find("KHR_mesh_quantization"), std::string::npos) << path;
    const Scene meshopt = loadScene(path);
    // gltfpack merges and reorders meshes: compare the whole scene.
    EXPECT_EQ(nonDegenerateTriangles(meshopt), nonDegenerateTriangles(plain)) << path;
    // 14-bit positions over the scene, 8-bit normals.
    const double step = maxExtent(plain) / 8191.0;
    const Displacement d = displacement(plain, meshopt, false);
    EXPECT_LE(d.position, step) << path;
    EXPECT_GE(d.normalDot, 0.99) << path;
    EXPECT_LE(displacement(meshopt, plain, false).position, step) << path;
  }
  // -cc filters the normals' view; -c does not.
  const json views = readGlb(f.meshoptFilters).doc.at("bufferViews");
  EXPECT_TRUE(std::any_of(views.begin(), views.end(), [](const json& v) {
    return v.at("extensions").at("EXT_meshopt_compression").value("filter", "") == "OCTAHEDRAL";
  }));
}

// Decodes `encoded` as one meshopt view with the given mode and filter.
std::vector<uint8_t> decodeView(const std::vector<uint8_t>& encoded, MeshoptView::Mode mode,
                                MeshoptView::Filter filter, size_t count, size_t stride) {
  MeshoptView view;
  view.mode = mode;
  view.filter = filter;
  view.count = count;
  view.byteStride = stride;
  return decodeMeshoptView(view, encoded.data(), encoded.size(), "test.glb", "bufferView 0");
}

std::vector<uint8_t> encodeVertices(const void* data, size_t count, size_t stride) {
  std::vector<uint8_t> out(meshopt_encodeVertexBufferBound(count, stride));
  out.resize(meshopt_encodeVertexBuffer(out.data(), out.size(), data, count, stride));
  return out;
}

// The filters gltfpack 0.18 writes only for animations (QUATERNION) or
// not at all (EXPONENTIAL), with libmeshoptimizer's encoders, and the
// TRIANGLES and INDICES index codecs.
TEST(CompressedGeometry, MeshoptFiltersAndIndexCodecsDecode) {
  const size_t n = 64;
  std::vector<float> unit(n * 4), quats(n * 4), floats(n * 3);
  for (size_t i = 0; i < n; ++i) {
    const glm::vec3 v =
        glm::normalize(glm::vec3(std::sin(i * 0.7f), std::cos(i * 1.3f), 0.3f + std::sin(i * 0.2f)));
    unit[4 * i] = v.x, unit[4 * i + 1] = v.y, unit[4 * i + 2] = v.z, unit[4 * i + 3] = 1.0f;
    const glm::vec4 q = glm::normalize(glm::vec4(v, std::cos(i * 0.4f)));
    quats[4 * i] = q.x, quats[4 * i + 1] = q.y, quats[4 * i + 2] = q.z, quats[4 * i + 3] = q.w;
    floats[3 * i] = 1000.0f * std::sin(float(i)), floats[3 * i + 1] = 0.001f * float(i),
               floats[3 * i + 2] = -3.5f;
  }
  {  // OCTAHEDRAL, 8-bit components (stride 4)
    std::vector<int8_t> encoded(n * 4);
    meshopt_encodeFilterOct(encoded.data(), n, 4, 8, unit.data());
    const std::vector<uint8_t> d =
        decodeView(encodeVertices(encoded.data(), n, 4), MeshoptView::Mode::Attributes,
                   MeshoptView::Filter::Octahedral, n, 4);
    for (size_t i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(int8_t(d[4 * i + k]) / 127.0, unit[4 * i + k], 0.02) << i;
  }
  {  // QUATERNION, 12 bits (stride 8)
    std::vector<int16_t> encoded(n * 4);
    meshopt_encodeFilterQuat(encoded.data(), n, 8, 12, quats.data());
    const std::vector<uint8_t> d =
        decodeView(encodeVertices(encoded.data(), n, 8), MeshoptView::Mode::Attributes,
                   MeshoptView::Filter::Quaternion, n, 8);
    for (size_t i = 0; i < n; ++i) {
      int16_t c[4];
      std::memcpy(c, d.data() + 8 * i, 8);
      const glm::vec4 q(c[0] / 32767.0f, c[1] / 32767.0f, c[2] / 32767.0f, c[3] / 32767.0f);
      const glm::vec4 r(quats[4 * i], quats[4 * i + 1], quats[4 * i + 2], quats[4 * i + 3]);
      EXPECT_GE(std::abs(glm::dot(q, r)), 0.999f) << i;  // q and -q are one rotation
    }
  }
  {  // EXPONENTIAL, 15-bit mantissas (stride 12)
    std::vector<uint32_t> encoded(n * 3);
    meshopt_encodeFilterExp(encoded.data(), n, 12, 15, floats.data());
    const std::vector<uint8_t> d =
        decodeView(encodeVertices(encoded.data(), n, 12), MeshoptView::Mode::Attributes,
                   MeshoptView::Filter::Exponential, n, 12);
    // One exponent per vector (meshoptimizer 0.18): the precision is
    // relative to the vector's largest component.
    for (size_t i = 0; i < 3 * n; ++i) {
      float v;
      std::memcpy(&v, d.data() + 4 * i, 4);
      const float* vector = &floats[i / 3 * 3];
      const float largest = std::max({std::abs(vector[0]), std::abs(vector[1]), std::abs(vector[2])});
      EXPECT_NEAR(v, floats[i], largest * 1e-4f) << i;
    }
  }
  const std::vector<uint32_t> triangles = {0, 1, 2, 2, 1, 3, 3, 4, 2, 5, 4, 3, 7, 6, 5};
  {  // TRIANGLES: the index codec, 16-bit output; it may rotate a
     // triangle's corners (winding kept), not reorder triangles
    std::vector<uint8_t> encoded(meshopt_encodeIndexBufferBound(triangles.size(), 8));
    encoded.resize(
        meshopt_encodeIndexBuffer(encoded.data(), encoded.size(), triangles.data(), triangles.size()));
    const std::vector<uint8_t> d =
        decodeView(encoded, MeshoptView::Mode::Triangles, MeshoptView::Filter::None, triangles.size(), 2);
    const auto index = [&](size_t i) { return uint32_t(d[2 * i] | d[2 * i + 1] << 8); };
    for (size_t t = 0; t < triangles.size(); t += 3) {
      bool rotation = false;
      for (size_t r = 0; r < 3; ++r)
        rotation |= index(t) == triangles[t + r] && index(t + 1) == triangles[t + (r + 1) % 3] &&
                    index(t + 2) == triangles[t + (r + 2) % 3];
      EXPECT_TRUE(rotation) << "triangle " << t / 3;
    }
  }
  {  // INDICES: the sequence codec, 32-bit output
    std::vector<uint8_t> encoded(meshopt_encodeIndexSequenceBound(triangles.size(), 8));
    encoded.resize(
        meshopt_encodeIndexSequence(encoded.data(), encoded.size(), triangles.data(), triangles.size()));
    const std::vector<uint8_t> d =
        decodeView(encoded, MeshoptView::Mode::Indices, MeshoptView::Filter::None, triangles.size(), 4);
    EXPECT_EQ(std::memcmp(d.data(), triangles.data(), d.size()), 0);
  }
}

// The first bufferView carrying the meshopt extension, and its extension.
size_t firstMeshoptView(const Glb& g) {
  const json& views = g.doc.at("bufferViews");
  for (size_t i = 0; i < views.size(); ++i)
    if (views[i].contains("extensions")) return i;
  ADD_FAILURE() << "no compressed bufferView";
  return 0;
}

TEST(CompressedGeometryErrors, CorruptMeshoptStreamsAreRefusedNamingTheBufferView) {
  const Files f = writeFiles();
  const Glb good = readGlb(f.meshopt);
  const size_t view = firstMeshoptView(good);
  const std::string element = "bufferView " + std::to_string(view);
  const json& ext = good.doc.at("bufferViews")[view].at("extensions").at("EXT_meshopt_compression");
  const size_t offset = ext.value("byteOffset", 0), length = ext.at("byteLength");
  const std::string bad = test::scratchPath("bad.glb");
  {  // an unknown header: the codec version byte
    Glb g = good;
    g.bin[offset] = 0xff;
    writeGlb(bad, g);
    const InputError e = loadError(bad);
    EXPECT_EQ(e.element(), element) << e.what();
    EXPECT_NE(e.message().find("unsupported version or bad header"), std::string::npos) << e.what();
  }
  {  // the stream cut short
    Glb g = good;
    g.doc["bufferViews"][view]["extensions"]["EXT_meshopt_compression"]["byteLength"] = length / 2;
    writeGlb(bad, g);
    const InputError e = loadError(bad);
    EXPECT_EQ(e.element(), element) << e.what();
    EXPECT_NE(e.message().find("corrupt or truncated"), std::string::npos) << e.what();
  }
  // Any byte of any stream overwritten: decodes to data that passes the
  // accessor checks, or is refused; never a crash.
  for (size_t at = 0; at < good.bin.size(); at += 7) {
    Glb g = good;
    g.bin[at] ^= 0x5a;
    writeGlb(bad, g);
    try {
      loadScene(bad);
    } catch (const InputError&) {
    }
  }
}

TEST(CompressedGeometryErrors, CorruptDracoStreamsAreRefusedNamingThePrimitive) {
  const Files f = writeFiles();
  const Glb good = readGlb(f.draco);
  const json& prim = good.doc.at("meshes")[0].at("primitives")[0];
  const size_t view = prim.at("extensions").at("KHR_draco_mesh_compression").at("bufferView");
  const size_t offset = good.doc.at("bufferViews")[view].value("byteOffset", 0);
  const size_t length = good.doc.at("bufferViews")[view].at("byteLength");
  const std::string element = "mesh 0 primitive 0 KHR_draco_mesh_compression";
  const std::string bad = test::scratchPath("bad.glb");
  {  // not a Draco stream
    Glb g = good;
    std::memcpy(g.bin.data() + offset, "NOTDR", 5);
    writeGlb(bad, g);
    const InputError e = loadError(bad);
    EXPECT_EQ(e.element(), element) << e.what();
    EXPECT_EQ(e.message().rfind("Draco stream does not decode", 0), 0u) << e.what();
  }
  {  // cut short
    Glb g = good;
    g.doc["bufferViews"][view]["byteLength"] = length / 2;
    writeGlb(bad, g);
    EXPECT_EQ(loadError(bad).element(), element);
  }
  {  // an accessor count the stream does not decode to: the plain checks
    Glb g = good;
    const size_t position = prim.at("attributes").at("POSITION");
    g.doc["accessors"][position]["count"] = g.doc["accessors"][position]["count"].get<size_t>() + 1;
    writeGlb(bad, g);
    const InputError e = loadError(bad);
    EXPECT_EQ(e.element(), "mesh 0 primitive 0 POSITION (accessor " + std::to_string(position) + ")")
        << e.what();
    EXPECT_NE(e.message().find("the Draco stream decodes"), std::string::npos) << e.what();
  }
  {  // an attribute id the stream does not hold
    Glb g = good;
    g.doc["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]["attributes"]
         ["POSITION"] = 9;
    writeGlb(bad, g);
    const InputError e = loadError(bad);
    EXPECT_EQ(e.element(), element) << e.what();
    EXPECT_NE(e.message().find("no attribute 9"), std::string::npos) << e.what();
  }
  // Any byte of the stream overwritten: loads or is refused, never a crash.
  for (size_t at = offset; at < offset + length; ++at) {
    Glb g = good;
    g.bin[at] ^= 0xa5;
    writeGlb(bad, g);
    try {
      loadScene(bad);
    } catch (const InputError&) {
    }
  }
}

// What check.cpp refuses before anything decodes.
TEST(CompressedGeometryErrors, MalformedExtensionsAreRefusedBeforeDecoding) {
  const Files f = writeFiles();
  const std::string bad = test::scratchPath("bad.glb");
  const auto expectRefused = [&](const Glb& g, const std::string& element, const std::string& message) {
    writeGlb(bad, g);
    const InputError e = loadError(bad);
    EXPECT_EQ(e.element(), element) << e.what();
    EXPECT_NE(e.message().find(message), std::string::npos) << e.what();
  };
  const Glb meshopt = readGlb(f.meshopt);
  const size_t view = firstMeshoptView(meshopt);
  const std::string ve = "bufferView " + std::to_string(view) + " EXT_meshopt_compression";
  const auto withExt = [&](const char* key, const json& value) {
    Glb g = meshopt;
    g.doc["bufferViews"][view]["extensions"]["EXT_meshopt_compression"][key] = value;
    return g;
  };
  expectRefused(withExt("mode", "STRIPS"), ve, "is not ATTRIBUTES, TRIANGLES or INDICES");
  expectRefused(withExt("filter", "COLOR"), ve, "is not NONE, OCTAHEDRAL, QUATERNION or EXPONENTIAL");
  expectRefused(withExt("count", 1), ve, "do not fill the bufferView's byteLength");
  expectRefused(withExt("byteLength", 1 << 30), ve, "lie outside buffer");
  const size_t stride =
      meshopt.doc["bufferViews"][view]["extensions"]["EXT_meshopt_compression"]["byteStride"];
  expectRefused(withExt("filter", stride == 8 ? "OCTAHEDRAL" : "QUATERNION"), ve, "cannot apply");
  {  // a plain bufferView over the fallback buffer
    Glb g = meshopt;
    g.doc["bufferViews"][view].erase("extensions");
    expectRefused(g, "bufferView " + std::to_string(view), "without a meshopt compression extension");
  }
  const Glb draco = readGlb(f.draco);
  const std::string pe = "mesh 0 primitive 0 KHR_draco_mesh_compression";
  {
    Glb g = draco;
    g.doc["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]["attributes"]
         ["TEXCOORD_3"] = 2;
    expectRefused(g, pe + " attributes", "\"TEXCOORD_3\" is not an attribute of the primitive");
  }
  {
    Glb g = draco;
    g.doc["meshes"][0]["primitives"][0]["mode"] = 5;
    expectRefused(g, pe, "Draco decodes TRIANGLES (4) only");
  }
}

// Item 4: `info` lists what is still ignored; the compression extensions
// are handled now and are not in the list.
TEST(CompressedGeometry, InfoListsStillIgnoredExtensionsButNotCompression) {
  const Files f = writeFiles();
  Glb g = readGlb(f.draco);
  g.doc["materials"][0]["extensions"]["KHR_materials_clearcoat"] = {{"clearcoatFactor", 1.0}};
  g.doc["extensionsUsed"].push_back("KHR_materials_clearcoat");
  const std::string path = test::scratchPath("clearcoat-draco.glb");
  writeGlb(path, g);
  for (const std::string& file : {path, f.meshopt}) {
    const Scene s = loadScene(file);
    for (const IgnoredFeature& i : s.ignored) {
      EXPECT_EQ(i.feature.find("draco"), std::string::npos) << file << ": " << i.describe();
      EXPECT_EQ(i.feature.find("meshopt"), std::string::npos) << file << ": " << i.describe();
      EXPECT_EQ(i.feature.find("quantization"), std::string::npos) << file << ": " << i.describe();
    }
  }
  const Scene s = loadScene(path);
  ASSERT_EQ(s.ignored.size(), 1u);
  EXPECT_EQ(s.ignored[0].describe(), "KHR_materials_clearcoat on 1 material");
  const test::CommandResult info = test::runRastray({"info", path});
  EXPECT_EQ(info.status, 0) << info.err;
  EXPECT_NE(info.out.find("ignored    KHR_materials_clearcoat on 1 material"), std::string::npos) << info.out;
}

// The alpha channel of a rendered PNG: 0 where no sample hit.
std::vector<uint8_t> coverage(const std::string& png, int* width, int* height) {
  int components = 0;
  unsigned char* pixels = stbi_load(png.c_str(), width, height, &components, 4);
  if (!pixels) return {};
  std::vector<uint8_t> alpha(size_t(*width) * size_t(*height));
  for (size_t i = 0; i < alpha.size(); ++i) alpha[i] = pixels[4 * i + 3] > 0;
  stbi_image_free(pixels);
  return alpha;
}

// The done-when, on the generated scene: at 640×480 the Draco and
// meshopt files cover the pixels the uncompressed one covers (≥ 99 %),
// and cross-validate with no genuine mismatch.
TEST(CompressedGeometry, CompressedFilesRenderTheSameCoverageAndCrossValidate) {
  const Files f = writeFiles();
  std::vector<uint8_t> reference;
  for (const std::string& file : {f.plain, f.draco, f.meshopt}) {
    const std::string png = file + ".png";
    // draco_transcoder drops the camera node: the same view for all, given.
    const test::CommandResult r =
        test::runRastray({"render", file, "-o", png, "--size", "640", "480", "--threads", "2", "--eye", "0",
                          "0.4", "3.5", "--target", "0", "0", "0", "--yfov", "45"});
    ASSERT_EQ(r.status, 0) << r.err;
    int w = 0, h = 0;
    const std::vector<uint8_t> c = coverage(png, &w, &h);
    ASSERT_EQ(c.size(), 640u * 480u) << png;
    if (reference.empty()) {
      reference = c;
      const size_t covered = size_t(std::count(c.begin(), c.end(), 1));
      EXPECT_GT(covered, c.size() / 4);  // the scene fills a good part of the image
      EXPECT_LT(covered, c.size());      // and leaves background
      continue;
    }
    size_t agree = 0;
    for (size_t i = 0; i < c.size(); ++i) agree += c[i] == reference[i];
    EXPECT_GE(double(agree) / double(c.size()), 0.99) << file;
  }
  const test::CommandResult cv =
      test::runRastray({"crossval", f.draco, f.meshopt, "--json", "--size", "320", "240", "--threads", "2",
                        "--eye", "0", "0.4", "3.5", "--target", "0", "0", "0", "--yfov", "45"});
  ASSERT_EQ(cv.status, 0) << cv.err;
  const json report = json::parse(cv.out);
  ASSERT_EQ(report.at("scenes").size(), 2u);
  for (const json& scene : report.at("scenes")) {
    EXPECT_EQ(scene.at("rasterVsRaytrace").at("visibility").at("mismatches").at("genuine"), 0)
        << scene.dump();
    EXPECT_EQ(scene.at("hybridVsRaytrace").at("visibility").at("mismatches").at("genuine"), 0)
        << scene.dump();
  }
}

}  // namespace
}  // namespace rastray
