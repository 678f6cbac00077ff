// The shared scene model: one flattened, world-space triangle store that
// both renderers read (SPEC §1, §2, §5). Nothing in here is specific to a
// renderer.
//
// Conventions
// - IDs: an instance is one (node with a mesh, triangle primitive) pair in
//   depth-first scene order; a triangle ID is the triangle's index within
//   its primitive after strip/fan triangulation. Instance i owns
//   triangles[firstTriangle, firstTriangle + triangleCount) and
//   vertices [firstVertex, firstVertex + vertexCount).
// - Space: positions and normals are in world space, translated by
//   −Scene::origin (the render origin, rebaseScene). Flattening is done in
//   double; positions are rounded to float (what Embree consumes) only
//   after the render origin is subtracted, so their spacing is fine where
//   the image is made however far the scene lies from the file's origin.
//   Lights, the camera model and the bounds are in the same rebased frame.
// - Winding: counter-clockwise seen from the front. When an instance's
//   world matrix mirrors (negative determinant) the loader swaps the
//   second and third vertex of every triangle, as glTF requires, so
//   "CCW = front" holds in world space for every triangle in the store.
//   Barycentrics (b1, b2) always refer to the stored vertex order.
// - Colours: factors are linear; textures keep their sRGB-encoded bytes
//   and are decoded by the shading module.
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace rastray {

// "Nothing hit" for both instance and triangle (SPEC §1).
constexpr uint32_t kNoId = 0xFFFFFFFFu;

enum class AlphaMode { Opaque, Mask, Blend };

// glTF sampler, with the GL enum values the file uses (-1: unset, which
// glTF leaves to the implementation; we treat it as linear/trilinear).
struct TextureSampler {
  int magFilter = -1;
  int minFilter = -1;
  int wrapS = 10497;  // REPEAT
  int wrapT = 10497;
};

// A decoded image: RGBA8, sRGB-encoded colour, straight (not premultiplied)
// alpha, row 0 at the top, which is where glTF's uv (0, 0) lies.
struct TextureImage {
  std::string name;
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgba8;
};

// KHR_texture_transform of one textureInfo: the uv a texture is sampled at
// is offset + R(rotation) · (scale ⊙ uv) (the extension's T·R·S), with R
// as the glTF Sample Viewer and three.js apply it: u' = cos·u + sin·v,
// v' = −sin·u + cos·v (rotation counter-clockwise in the image, whose
// v axis points down). Kept in double: applied to the float uv in double,
// rounded to float once (the texture wraps in double anyway).
struct TextureTransform {
  glm::dmat2 linear{1.0};  // rotation × scale; columns are GLM's
  glm::dvec2 offset{0.0};
  bool identity = true;

  TextureTransform() = default;
  TextureTransform(glm::dvec2 offset, double rotation, glm::dvec2 scale);
  glm::vec2 apply(glm::vec2 uv) const { return identity ? uv : glm::vec2(linear * glm::dvec2(uv) + offset); }
  // A uv difference (a footprint derivative): the linear part only.
  glm::vec2 applyLinear(glm::vec2 d) const { return identity ? d : glm::vec2(linear * glm::dvec2(d)); }
};

// A texture as one textureInfo reads it: the loader gives every textureInfo
// with a KHR_texture_transform a Texture of its own (same image and
// sampler, its transform); TextureSet shares the image's mip chain.
struct Texture {
  int32_t image = -1;  // index into Scene::images; -1: no decodable source
  TextureSampler sampler;
  TextureTransform transform;
  // Data, not colour (normal, metallic-roughness and occlusion maps): the
  // bytes are read linearly (v / 255), not sRGB-decoded, and alpha is
  // ignored. The loader gives such textureInfos textures of their own, so
  // an image used both ways gets one chain of each kind (TextureSet).
  bool data = false;
};

struct Material {
  std::string name;
  glm::vec4 baseColorFactor{1.0f};  // linear RGBA, straight alpha
  int32_t baseColorTexture = -1;    // index into Scene::textures, -1: none
  float metallic = 1.0f;
  float roughness = 1.0f;
  glm::vec3 emissive{0.0f};  // emissiveFactor × KHR_materials_emissive_strength
  // Multiplies `emissive` (sRGB-decoded RGB); read through the same uv set
  // as the base colour texture (Scene::texcoords). -1: none.
  int32_t emissiveTexture = -1;
  AlphaMode alphaMode = AlphaMode::Opaque;
  float alphaCutoff = 0.5f;
  bool doubleSided = false;
  float transmission = 0.0f;  // KHR_materials_transmission
  float ior = 1.5f;           // KHR_materials_ior
  bool isDefault = false;     // made by the loader for primitives without a material

  // The maps of docs/MATERIALS.md, indices into Scene::textures (data
  // textures, Texture::data), -1: none. All read through the base colour
  // texture's uv set (Scene::texcoords); the loader drops (and lists) a
  // map on another set.
  // normalTexture: tangent-space normal, scaled in x and y by normalScale;
  // the instance carries tangents (Instance::firstTangent).
  int32_t normalTexture = -1;
  float normalScale = 1.0f;
  // occlusionTexture: R scales indirect light (Shader, SPEC §5) as
  // 1 + occlusionStrength · (R − 1).
  int32_t occlusionTexture = -1;
  float occlusionStrength = 1.0f;
  // metallicRoughnessTexture: B multiplies `metallic`, G `roughness`, per hit.
  int32_t metallicRoughnessTexture = -1;

  // SPEC §5: mirror reflection weight metallic × (1 − roughness), from the
  // factors; with a metallicRoughnessTexture the weight at a hit is
  // mirrorWeight(metallic · B, roughness · G) (Shader::surfaceAt).
  static float mirrorWeight(float metallic, float roughness) { return metallic * (1.0f - roughness); }
  float mirrorWeight() const { return mirrorWeight(metallic, roughness); }
  // Whether some hit may reflect: the factor weight, or with a texture a
  // G below 1 (B at most 1 scales metallic down, never up).
  bool isReflective() const {
    return mirrorWeight() > 0.0f || (metallicRoughnessTexture >= 0 && metallic > 0.0f);
  }
  // A normal, occlusion or metallic-roughness map.
  bool hasSurfaceMaps() const {
    return normalTexture >= 0 || occlusionTexture >= 0 || metallicRoughnessTexture >= 0;
  }
  // Any texture shading samples.
  bool isTextured() const { return baseColorTexture >= 0 || emissiveTexture >= 0 || hasSurfaceMaps(); }
  bool isRefractive() const { return transmission > 0.0f; }
  bool isEmissive() const { return emissive != glm::vec3(0.0f); }
};

enum class LightType { Point, Spot, Directional };

// KHR_lights_punctual, placed in the world by its node.
struct Light {
  std::string name;
  LightType type = LightType::Point;
  glm::vec3 color{1.0f};
  float intensity = 1.0f;  // candela (point, spot) or lux (directional)
  float range = 0.0f;      // 0: infinite
  float innerConeAngle = 0.0f;
  float outerConeAngle = 0.7853981634f;  // π/4, the glTF default
  glm::dvec3 position{0.0};              // world space (point, spot)
  glm::dvec3 direction{0.0, 0.0, -1.0};  // world, unit: the way light travels (node's −Z)
  uint32_t node = 0;
};

enum class Projection { Perspective, Orthographic };

// A camera as the file (or the SPEC §2 default) describes it. The image
// size and command-line overrides are applied later (common/camera.h).
struct CameraModel {
  Projection projection = Projection::Perspective;
  double yfov = 0.7853981633974483;  // radians (perspective)
  double aspectRatio = 0.0;          // 0: use image width / height
  double xmag = 1.0, ymag = 1.0;     // half extents (orthographic)
  double znear = 0.1;
  double zfar = std::numeric_limits<double>::infinity();
  glm::dmat4 worldFromCamera{1.0};  // camera looks down −Z, +Y up
  std::string origin;               // e.g. "node 3 'Camera' (camera 0)" or "default"
};

struct Bounds {
  glm::dvec3 lo{std::numeric_limits<double>::infinity()};
  glm::dvec3 hi{-std::numeric_limits<double>::infinity()};
  bool empty() const { return !(lo.x <= hi.x); }
  void extend(const glm::dvec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
};

enum class NormalSource {
  Authored,  // the primitive's NORMAL attribute, transformed to world space
  Flat,      // none in the file: the geometric (face) normal, as glTF requires
};

struct Instance {
  uint32_t node = 0;
  uint32_t mesh = 0;
  uint32_t primitive = 0;  // index within the mesh
  uint32_t material = 0;   // index into Scene::materials (always valid)
  int mode = 4;            // glTF primitive mode: 4 TRIANGLES, 5 STRIP, 6 FAN
  // The node's world matrix; identity for a skinned instance, whose
  // vertices the skin places in world space (the node's own transform is
  // ignored, as glTF requires).
  glm::dmat4 worldFromObject{1.0};
  // det(worldFromObject) < 0 (skinned: the skin matrix of most vertices
  // mirrors): winding was swapped.
  bool mirrored = false;
  bool skinned = false;  // placed by a skin (joint matrices), not by worldFromObject
  bool morphed = false;  // morph-target deltas with a nonzero weight were added
  NormalSource normals = NormalSource::Flat;
  bool hasTexcoords = false;  // false: texcoords are all (0, 0)
  bool hasColors = false;     // COLOR_0 read into Scene::colors; false: white
  uint32_t firstVertex = 0, vertexCount = 0;
  uint32_t firstTriangle = 0, triangleCount = 0;
  uint32_t degenerateCount = 0;  // zero-area triangles (kept, cover nothing)
  // Tangents (only for instances whose material has a normal map, SPEC §8):
  // corner k of triangle t (stored order) has Scene::tangents[firstTangent
  // + 3t + k]. kNoId: none.
  uint32_t firstTangent = kNoId;
  bool generatedTangents = false;  // no TANGENT in the file: generated (common/gltf/tangents.h)
};

// A feature the file uses that the loader checks but nothing renders, with
// how often it occurs: "occlusion texture on 3 materials".
struct IgnoredFeature {
  std::string feature;  // e.g. "occlusion texture", "KHR_texture_transform"
  std::string unit;     // singular: "material", "textureInfo", "primitive", ...
  uint32_t count = 0;
  std::string describe() const;  // "<feature> on <count> <unit>(s)"
};

// Which pose of the file the scene is flattened at (--time, --animation;
// common/gltf/animation.h samples it).
struct PoseRequest {
  // Seconds; nullopt: no animation plays (the nodes' own transforms and
  // morph weights, skins applied).
  std::optional<double> time;
  int animation = -1;  // -1: every animation plays; else only this one
  bool operator==(const PoseRequest& o) const { return time == o.time && animation == o.animation; }
  bool operator!=(const PoseRequest& o) const { return !(*this == o); }
};

// One animation of the file, as `info` lists it. Times in seconds.
struct AnimationSummary {
  std::string name;
  uint32_t channels = 0;
  uint32_t samplers = 0;
  double start = 0.0;  // the smallest key time of its samplers
  double end = 0.0;    // the largest: the animation's duration, glTF time starting at 0
};

// Counts of what the file holds, for `rastray info`.
struct SceneFileStats {
  uint32_t nodes = 0;         // nodes in the file
  uint32_t visitedNodes = 0;  // nodes reached from the scene's roots
  uint32_t meshes = 0;
  uint32_t cameras = 0;            // camera definitions in the file
  uint32_t cameraNodes = 0;        // visited nodes that carry a camera
  uint32_t skippedPrimitives = 0;  // points and lines: no instance number
  int sceneIndex = -1;             // -1: no scenes, all root nodes used
};

struct Scene {
  std::string path;  // as given by the user, used in messages

  // The world point the store's (0, 0, 0) stands for: positions, lights,
  // camera and bounds are relative to it (rebaseScene). (0, 0, 0) after
  // loading.
  glm::dvec3 origin{0.0};
  // Flattened world positions in double, parallel to `positions`: what
  // rebasing rounds from.
  std::vector<glm::dvec3> worldPositions;

  // The triangle store (see the conventions above). positions[i] =
  // float(worldPositions[i] − origin), rounded to nearest.
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;    // unit; (0,0,0) where NormalSource::Flat
  std::vector<glm::vec2> texcoords;  // the set the base colour texture reads
  // COLOR_0 as linear straight RGBA (vec3 colours get alpha 1); empty when
  // no instance has COLOR_0, else parallel to positions and white where an
  // instance has none.
  std::vector<glm::vec4> colors;
  // Per triangle corner of the instances with a normal map
  // (Instance::firstTangent): world-space unit tangent xyz and handedness
  // w = ±1 (glTF: bitangent = cross(normal, xyz) · w). Float, rounded from
  // the double computation at load.
  std::vector<glm::vec4> tangents;
  std::vector<glm::uvec3> triangles;  // absolute indices into the vertex arrays
  std::vector<Instance> instances;

  std::vector<Material> materials;
  std::vector<Texture> textures;
  std::vector<TextureImage> images;
  std::vector<Light> lights;
  std::optional<CameraModel> camera;  // first camera node in walk order
  // Every camera node in walk order (cameras[0] is `camera`), for --camera N.
  // Only the first is checked at load; makeCamera refuses a chosen later one
  // whose world matrix is singular.
  std::vector<CameraModel> cameras;

  Bounds bounds;  // world bounds of all instance vertices
  SceneFileStats stats;
  // What the file uses and no renderer draws, in the order first met;
  // empty when nothing is ignored.
  std::vector<IgnoredFeature> ignored;
  // The file's animations (all of them, played or not) and the pose the
  // store was flattened at.
  std::vector<AnimationSummary> animations;
  PoseRequest pose;

  const Instance& instanceOf(uint32_t instance) const { return instances[instance]; }
  // Stored vertex indices of (instance, triangle).
  const glm::uvec3& triangle(uint32_t instance, uint32_t tri) const {
    return triangles[instances[instance].firstTriangle + tri];
  }
  const Material& materialOf(uint32_t instance) const { return materials[instances[instance].material]; }
  size_t triangleCount() const { return triangles.size(); }
};

// Scenes come from common/gltf/loader.h (loadScene) and are written by
// common/gltf/writer.h; this header is the model only.

// Moves the scene's frame so that world point `origin` is at (0, 0, 0):
// positions are rounded again from worldPositions, and lights, the camera
// model, the bounds and the degenerate-triangle counts follow. Throws
// InputError (file: the scene) when a position does not fit a float
// relative to that origin.
void rebaseScene(Scene& scene, const glm::dvec3& origin);

// World-space geometric normal of a stored triangle (unnormalised: its
// length is twice the area); CCW seen from the front.
glm::dvec3 faceNormal(const Scene& scene, uint32_t instance, uint32_t tri);

// SPEC §1: a stored triangle (index into Scene::triangles) whose float
// corners span zero area covers nothing. Exact: the cross product of the
// float edge vectors in double is zero (every product of floats is exact
// in double). The one definition the loader, the rasterizer's setup and
// the Embree scene share.
bool isDegenerate(const Scene& scene, size_t storedTriangle);

const char* toString(AlphaMode mode);
const char* toString(LightType type);
const char* toString(Projection projection);

}  // namespace rastray
