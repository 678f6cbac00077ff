// Writes small glTF 2.0 files from code: the generated scenes of tests
// (regression cases, random scenes), of `rastray stability` and of the
// crossover study. Positions, optional normals and texcoords, and uint32
// indices in one buffer (a base64 data URI in .gltf, the BIN chunk in
// .glb); metallic-roughness materials with optional base colour, normal,
// occlusion and metallic-roughness textures (8-bit RGB, embedded as
// data-URI PNGs), optional tangents, an emissive factor and
// KHR_materials_transmission/ior; one optional perspective or orthographic
// camera (placed by eye/target/up) and KHR_lights_punctual lights.
#pragma once

#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <vector>

namespace rastray {

struct GltfMaterial {
  glm::vec4 baseColor{1.0f};
  float metallic = 0.0f, roughness = 1.0f;
  std::string alphaMode = "OPAQUE";  // OPAQUE, MASK, BLEND
  float alphaCutoff = 0.5f;
  bool doubleSided = false;
  float transmission = 0.0f;  // > 0 writes KHR_materials_transmission (and ior)
  float ior = 1.5f;
  int baseColorTexture = -1;  // index into GltfScene::textures, read through TEXCOORD_0; -1: none
  glm::vec3 emissive{0.0f};   // emissiveFactor, each in [0, 1]; written when not black
  // The data maps (indices into GltfScene::textures, TEXCOORD_0; -1: none).
  int normalTexture = -1;
  float normalScale = 1.0f;
  int occlusionTexture = -1;
  float occlusionStrength = 1.0f;
  int metallicRoughnessTexture = -1;
};

// An 8-bit RGB image (row 0 at the top, v = 0) with its glTF sampler.
struct GltfTexture {
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;    // width·height·3 bytes
  int magFilter = 9729;              // LINEAR
  int minFilter = 9987;              // LINEAR_MIPMAP_LINEAR
  int wrapS = 10497, wrapT = 10497;  // REPEAT
};

// One mesh with one TRIANGLES primitive, on its own node.
struct GltfMesh {
  std::vector<glm::vec3> positions;
  std::vector<uint32_t> indices;     // three per triangle
  std::vector<glm::vec3> normals;    // empty, or one per position (NORMAL)
  std::vector<glm::vec2> texcoords;  // empty, or one per position (TEXCOORD_0)
  int material = 0;
  glm::dvec3 translation{0.0};      // the node's translation (kept exact in the file)
  std::vector<glm::vec4> tangents;  // empty, or one per position (TANGENT)
};

struct GltfCamera {
  glm::dvec3 eye{0.0, 0.0, 3.0}, target{0.0}, up{0.0, 1.0, 0.0};
  double yfov = 0.8;  // radians (perspective)
  double znear = 0.1;
  std::optional<double> zfar;  // absent: infinite (perspective; orthographic requires it)
  // Last, so that aggregate initialisers written before it still compile.
  bool orthographic = false;
  double xmag = 1.0, ymag = 1.0;  // half extents (orthographic)
};

struct GltfLight {
  std::string type = "directional";      // directional, point, spot
  glm::dvec3 position{0.0};              // point, spot
  glm::dvec3 direction{0.0, -1.0, 0.0};  // directional, spot: the way light travels (not parallel to +-y)
  float intensity = 3.0f;
  float innerConeAngle = 0.0f, outerConeAngle = 0.7853981634f;  // spot, radians
};

struct GltfScene {
  std::vector<GltfMaterial> materials;
  std::vector<GltfTexture> textures;
  std::vector<GltfMesh> meshes;
  std::optional<GltfCamera> camera;
  std::vector<GltfLight> lights;

  std::string toJson() const;
  void write(const std::string& path) const;  // throws std::runtime_error when it cannot
  // The same scene as binary glTF: the JSON chunk, then buffer 0 as the BIN
  // chunk (no base64: large generated meshes write and load fast). Textures
  // stay data-URI PNGs. Throws std::runtime_error when it cannot write or the
  // file would pass the format's 4 GiB limit.
  void writeGlb(const std::string& path) const;
};

// A node transform that maps the node's −Z to `forward` (camera, light
// convention) from `eye`, with +Y as close to `up` as possible: a column-
// major 4×4 matrix as glTF's "matrix".
std::vector<double> lookAtNodeMatrix(const glm::dvec3& eye, const glm::dvec3& forward, glm::dvec3 up);

// A closed UV sphere (rings × segments, pole fans without degenerate
// triangles), counter-clockwise seen from outside, with flat normals (no
// NORMAL attribute).
GltfMesh uvSphereMesh(glm::vec3 centre, float radius, int rings, int segments, int material);

}  // namespace rastray
