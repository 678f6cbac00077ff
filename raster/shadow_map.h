// Shadows without rays: depth maps rendered from each light with the same
// clip/setup/bin/raster stages as the camera view (1 sample per texel,
// float-reversed depth), and a LightVisibility that looks them up.
//
// - Point lights: a cube map, six 90° perspective faces (±X, ±Y, ±Z).
// - Spot lights: one perspective map with the cone's full angle (2 × outer).
// - Directional lights: one orthographic map fitted to the scene's
//   bounding sphere.
// Bias is applied while rendering the maps, as glPolygonOffset does:
// constant (in units of the format's resolvable difference) plus slope
// scaled (× the occluder's max depth slope per texel). Too little bias
// shows acne, too much peter-panning; one texel per lookup (no filtering),
// so the maps' aliasing stays visible for comparison with traced shadows.
// OPAQUE and MASK surfaces (MASK alpha-tested) write depth. BLEND and
// refractive surfaces attenuate instead, as SPEC §5 asks (1 − α, and
// transmission × C): each map keeps, per texel, the transmissive fragments
// in front of its opaque depth (a small deep shadow map), and a lookup
// multiplies those nearer to the light than the point. Without a shader
// they block like opaque surfaces.
#pragma once

#include <cstdint>
#include <vector>

#include "common/analysis.h"
#include "common/camera.h"
#include "common/scene.h"
#include "common/shading.h"
#include "raster/coverage.h"
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

class ShadowMaps : public LightVisibility {
 public:
  // Renders the maps of every light (none without lights). `shader`
  // decides MASK coverage and transmittance (null: both cast as OPAQUE).
  ShadowMaps(const Scene& scene, const RasterOptions& options, const Shader* shader);

  glm::vec3 transmittance(const SurfacePoint& point, int lightIndex, const glm::dvec3& toLight,
                          double distance) const override;

  uint64_t trianglesRendered() const { return triangles_; }
  uint64_t mapCount() const { return maps_.size(); }

  uint64_t attenuatingFragments() const { return attenuating_; }

  struct Attenuation {
    uint32_t texel;
    uint32_t key;  // depth key from the light, bias applied
    glm::vec3 transmittance;
  };
  struct Map {
    Camera camera;
    ClipSpace space;
    DepthTarget depth;
    std::vector<Attenuation> attenuation;  // sorted by (texel, key)
  };

 private:
  glm::vec3 lit(const Map& map, const glm::dvec3& world) const;

  const Scene& scene_;
  std::vector<std::vector<Map>> perLight_;  // by light index; 6 faces for point lights
  std::vector<const Map*> maps_;
  uint64_t triangles_ = 0;
  uint64_t attenuating_ = 0;
};

}  // namespace rastray
