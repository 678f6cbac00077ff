// Shadows without rays: depth maps rendered from each light with the same
// clip/setup/bin/raster stages as the camera view (1 sample per texel,
// float-reversed depth), and a LightVisibility that looks them up.
//
// - Point lights: a cube map, six 90° perspective faces (±X, ±Y, ±Z).
// - Spot lights: one perspective map with the cone's full angle (2 × outer).
// - Directional lights: one orthographic map fitted to the scene's bounds
//   as the light sees them, its x and y extents apart.
// Bias is applied while rendering the maps, as glPolygonOffset does:
// constant (in units of the format's resolvable difference) plus slope
// scaled (× the occluder's max depth slope per texel); a lookup compares
// the texel with the receiver's own plane at the texel's sample
// (receiver-plane depth, taking min with the point's depth), so the bias
// covers only the maps' rounding and snap, not the receiver's slope
// across half a texel (docs/SHADOWS.md "Shadow maps": 0 leaks and 0 acne
// on the stability study's shadow-map cases). One texel per lookup (no
// filtering), so the maps' aliasing stays visible for comparison with
// traced shadows.
// OPAQUE and MASK surfaces (MASK alpha-tested) write depth. BLEND and
// refractive surfaces attenuate instead, as SPEC §5 asks (1 − α, and
// transmission × C): each map keeps, per texel, the transmissive fragments
// in front of its opaque depth (a small deep shadow map), and a lookup
// multiplies those nearer to the light than the point. Without a shader
// they block like opaque surfaces.
//
// Speed. The opaque depth runs the depth-only pass (depth_only_pass.h:
// the camera pass's block coverage and hierarchical depth, SIMD keys, a
// tile-local buffer, 8×8 blocks kept as a triangle's plane where one
// covers them whole), with the same keys as the camera pass's keys-only
// rasterDepthPass. A map is stored by blocks (BlockDepthMap): a lookup
// costs a few double operations (the reference's, inlined: same bits),
// one load from the blocks' table (256 KB a 2048² face) and either the
// block's plane evaluated at the texel or one load of its keys; the
// transmissive fragments are indexed by texel within their tile: two
// loads find a texel's (none, or its layers in order), no search.
#pragma once

#include <cstdint>
#include <vector>

#include "common/analysis.h"
#include "common/camera.h"
#include "common/scene.h"
#include "common/shading.h"
#include "raster/bin.h"
#include "raster/coverage.h"
#include "raster/depth_only_pass.h"
#include "raster/options.h"

namespace rastray {

// A point light's cube map: six faces, ±X, ±Y, ±Z in this order.
constexpr int kCubeFaces = 6;
std::vector<Camera> cubeFaceCameras(const glm::dvec3& eye, int size, double znear);

// Which faces of the cube map at `eye` each stored triangle can reach: bit f
// of byte i for face f of triangle i, from the faces' NDC scale `t`
// (ClipSpace::scale) and size in texels. Conservative: a face whose bit is
// clear would set up nothing of the triangle, so each face sets up only its
// candidates and the maps stay identical.
std::vector<uint8_t> cubeFaceCandidates(const Scene& scene, const glm::dvec3& eye, double t, int size);

// One texel of light `lightIndex`'s map (maps of `size` texels a side, as
// ShadowMaps renders them) near `point`: its two sides as world vectors
// across the light (a directional map's are uniform; a cube face's or
// spot map's at the point's depth along the face's axis). A one-texel
// lookup cannot place a shadow edge closer than this; the stability study
// uses it to tell the maps' resolution from their bias.
struct ShadowTexel {
  glm::dvec3 side[2];
};
ShadowTexel shadowMapTexel(const Scene& scene, int lightIndex, int size, const glm::dvec3& point);

class ShadowMaps : public LightVisibility {
 public:
  // Renders the maps of every light (none without lights). `shader`
  // decides MASK coverage and transmittance (null: both cast as OPAQUE).
  // `path` picks the depth-only pass's walk (identical maps; Reference
  // for the tests that prove it).
  ShadowMaps(const Scene& scene, const RasterOptions& options, const Shader* shader,
             CoveragePath path = CoveragePath::Fast);

  glm::vec3 transmittance(const SurfacePoint& point, int lightIndex, const glm::dvec3& toLight,
                          double distance) const override;

  // The transmittance of light `lightIndex` at `world` on a surface of
  // unit geometric normal `normal` (either side; zero: compare the point's
  // own depth, no receiver plane), `toLight` the direction from the point
  // towards the light (it picks the cube face): what transmittance()
  // returns for that surface point. Plain members, not virtual, for
  // callers that shade many points at once: the batch form looks up n
  // points of one light.
  glm::vec3 lightTransmittance(int lightIndex, const glm::dvec3& world, const glm::dvec3& normal,
                               const glm::dvec3& toLight) const;
  void lightTransmittances(int lightIndex, size_t n, const glm::dvec3* world, const glm::dvec3* normal,
                           const glm::dvec3* toLight, glm::vec3* out) const;
  // The same from the scalar reference lookup: the general matrix and
  // window-depth functions, and a binary search of the map tile's
  // attenuating fragments. The tests demand the same bits.
  glm::vec3 lightTransmittanceReference(int lightIndex, const glm::dvec3& world, const glm::dvec3& normal,
                                        const glm::dvec3& toLight) const;

  uint64_t trianglesRendered() const { return triangles_; }
  uint64_t mapCount() const { return maps_.size(); }

  uint64_t attenuatingFragments() const { return attenuating_; }

  struct Attenuation {
    uint32_t texel;
    uint32_t key;  // depth key from the light, bias applied
    glm::vec3 transmittance;
    Attenuation() = default;
    // For emplace_back: the fields stored in place. A braced temporary
    // pushed back was assembled on the stack by narrow stores and copied
    // with a 16-byte load, which stalled on store forwarding (a third of
    // the tile's fragment loop at 2048²).
    Attenuation(uint32_t atTexel, uint32_t keyFromLight, const glm::vec3& passed)
        : texel(atTexel), key(keyFromLight), transmittance(passed) {}
  };
  // What a lookup needs of a map, precomputed: the view matrix's x, y and
  // z rows (glm's column order of operations kept, so the view position
  // has the bits of viewFromWorld · (world, 1)), the clip scale and the
  // window-depth constants.
  struct Lookup {
    glm::dvec3 column[4];  // (x, y, z) rows of viewFromWorld's columns
    glm::dvec2 scale;
    double width = 0.0, height = 0.0;
    bool perspective = true;
    double znear = 0.0, zfar = 0.0;
    glm::dvec2 sample{0.5};  // a texel's sample position within it
  };
  struct Map {
    Camera camera;
    ClipSpace space;
    Lookup lookup;
    BlockDepthMap depth;  // by 8×8 blocks: clear, a plane or keys
    TileGrid tiles{0, 0};
    // The transmissive fragments in front of the opaque depth, per tile
    // (each tile's own vector, as its task sorted it: no copy into one),
    // by (texel, key); equal keys at a texel in the order the pass met
    // them (bin order, then texel order).
    std::vector<std::vector<Attenuation>> attenuation;
    // Per tile, the first fragment of each of its texels in its vector:
    // kTileSize² + 1 entries, texel (x, y) of the tile at (y mod
    // kTileSize) · kTileSize + x mod kTileSize, the last the size; empty
    // for a tile without fragments. A lookup finds its texel's fragments
    // without a search (the binary search of the texel's row, a third of
    // the lookup's samples under the Cornell box's glass sphere).
    std::vector<std::vector<uint32_t>> attenuationTexels;
  };

  // Map i, lights in order (a point light's six faces in face order).
  const Map& mapAt(size_t i) const;

 private:
  glm::vec3 lit(const Map& map, const glm::dvec3& world, const glm::dvec3& normal) const;
  glm::vec3 litReference(const Map& map, const glm::dvec3& world, const glm::dvec3& normal) const;
  const Map& mapFor(int lightIndex, const glm::dvec3& toLight) const;

  const Scene& scene_;
  std::vector<std::vector<Map>> perLight_;  // by light index; 6 faces for point lights
  std::vector<const Map*> maps_;
  uint64_t triangles_ = 0;
  uint64_t attenuating_ = 0;
};

// Sorts one map tile's transmissive fragments (texels of `rect`, in a map
// `width` texels wide) by (texel, key), equal pairs in the order given:
// std::stable_sort's result, counted into texel order in one linear pass
// (a glass sphere over the tile: thousands, a few per texel) and each
// texel's few then sorted by key. `texelStarts` gets the tile's texel
// index (Map::attenuationTexels): empty without fragments.
void sortTileFragments(const TileRect& rect, size_t width, std::vector<ShadowMaps::Attenuation>* fragments,
                       std::vector<uint32_t>* texelStarts);

}  // namespace rastray
